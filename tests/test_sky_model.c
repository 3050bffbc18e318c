/* The Preetham sky against values worked out by hand from the paper's
 * equations, the xyY -> Rec. 709 conversion, and NOAA's solar position
 * against an independent implementation, Meeus' worked example and
 * geometric facts. */
#include "test_support.h"

#include <math.h>

#include "light/sky_model.h"

static const double pi = 3.14159265358979323846;

static double rad(double deg) { return deg * (pi / 180.0); }

static double rel_err(double got, double want) { return fabs(got - want) / fabs(want); }

/* Unit direction at zenith angle theta and azimuth phi (degrees), phi
 * measured from +x toward +z, +y up. */
static vec3 dir(double theta_deg, double phi_deg)
{
    double t = rad(theta_deg), p = rad(phi_deg);
    return v3(sin(t) * cos(p), cos(t), sin(t) * sin(p));
}

/* Reference values for T = 3, computed once by a separate python3 script
 * (not kept) straight from Preetham, Shirley and Smits 1999, Appendix A.2:
 * the zenith luminance Y_z = (4.0453 T - 4.9710) tan(chi) - 0.2155 T
 * + 2.4192, chi = (4/9 - T/120)(pi - 2 theta_s) (times 1000 for cd/m^2);
 * x_z, y_z = [T^2 T 1] M [theta_s^3 theta_s^2 theta_s 1]^T with the
 * paper's matrices; Perez A..E linear in T from the appendix; the sky
 * value = zenith * F(theta, gamma) / F(0, theta_s) with Perez et al.'s
 * F = (1 + A e^(B / cos theta))(1 + C e^(D gamma) + E cos^2 gamma) (the
 * paper's eq. 3 and 4), gamma from the spherical law of cosines.  rgb is
 * Y / 179 through X = x Y / y, Z = (1 - x - y) Y / y and the D65 Rec. 709
 * matrix.  The sun is at azimuth 0 (toward +x). */
typedef struct sky_ref {
    double theta, phi;     /* view direction, degrees */
    double x, y, Y;        /* Y in cd/m^2 */
    double r, g, b;        /* radiance, W/m^2/sr */
} sky_ref;

typedef struct sun_ref {
    double theta_s;        /* degrees */
    double zenith_Y, zenith_x, zenith_y;
    sky_ref views[4];
} sun_ref;

static const sun_ref preetham_refs[2] = {
    {30.0, 10413.08691, 0.2534341841, 0.259792522,
     {{0.0, 0.0, 0.2534341841, 0.259792522, 10413.08691, 40.13171449, 58.660704, 106.5065564},
      /* toward the sun's azimuth, gamma = 30 deg */
      {60.0, 0.0, 0.2694768017, 0.2791315525, 15123.89326, 66.3264701, 85.1267064, 131.7281352},
      /* opposite, gamma = 90 deg */
      {60.0, 180.0, 0.2441363941, 0.2593635732, 6332.696866, 19.76489298, 36.90750265, 66.22254543},
      /* a quarter turn round, gamma = 52.238756 deg */
      {45.0, 90.0, 0.2480923469, 0.2575565532, 8080.101983, 28.3170723, 46.14044957, 84.79353551}}},
    {70.0, 3932.878979, 0.2507018058, 0.2612870173,
     {{0.0, 0.0, 0.2507018058, 0.2612870173, 3932.878979, 14.08084612, 22.49128477, 40.06756235},
      /* gamma = 10 deg */
      {60.0, 0.0, 0.30406216, 0.3171505864, 19732.28366, 107.3881397, 109.8449568, 122.5632894},
      /* gamma = 130 deg */
      {60.0, 180.0, 0.2596586785, 0.277496263, 4602.165279, 17.0578765, 26.69771432, 41.4226838},
      /* gamma = 76.004555 deg */
      {45.0, 90.0, 0.2556942137, 0.2687392981, 4519.213992, 16.75802495, 25.93805068, 43.41184139}}},
};

/* The rounding of the printed references (10 significant digits) is far
 * inside this. */
#define PREETHAM_REL_TOL 1e-6

static void test_preetham_zenith_and_coefficients(void **state)
{
    (void)state;
    /* A..E at T = 3 from the appendix's linear forms (Y, x, y rows). */
    const double want_perez[3][5] = {
        {-0.9269, -0.6387, 5.2570, -2.2153, 0.1693},
        {-0.3171, -0.1987, 0.2113, -1.0912, 0.0353},
        {-0.3109, -0.2758, 0.1865, -1.7860, 0.0202},
    };
    for (int k = 0; k < 2; k++) {
        const sun_ref *r = &preetham_refs[k];
        preetham_sky s;
        preetham_init(&s, 3.0, dir(r->theta_s, 0.0));
        print_message("theta_s %g: Y_z %.6f cd/m^2, x_z %.8f, y_z %.8f\n", r->theta_s, s.zenith_Y,
                      s.zenith_x, s.zenith_y);
        assert_true(fabs(s.theta_s - rad(r->theta_s)) < 1e-12);
        assert_true(rel_err(s.zenith_Y, r->zenith_Y) < PREETHAM_REL_TOL);
        assert_true(rel_err(s.zenith_x, r->zenith_x) < PREETHAM_REL_TOL);
        assert_true(rel_err(s.zenith_y, r->zenith_y) < PREETHAM_REL_TOL);
        for (int i = 0; i < 5; i++) {
            assert_true(fabs(s.perez_Y[i] - want_perez[0][i]) < 1e-12);
            assert_true(fabs(s.perez_x[i] - want_perez[1][i]) < 1e-12);
            assert_true(fabs(s.perez_y[i] - want_perez[2][i]) < 1e-12);
        }
    }
}

static void test_preetham_views(void **state)
{
    (void)state;
    for (int k = 0; k < 2; k++) {
        const sun_ref *r = &preetham_refs[k];
        preetham_sky s;
        preetham_init(&s, 3.0, dir(r->theta_s, 0.0));
        for (int i = 0; i < 4; i++) {
            const sky_ref *v = &r->views[i];
            double x, y, Y;
            preetham_xyY(&s, dir(v->theta, v->phi), &x, &y, &Y);
            vec3 rgb = preetham_radiance(&s, dir(v->theta, v->phi));
            print_message("theta_s %g view (%g, %g): Y %.4f (want %.4f) rgb %.5f %.5f %.5f\n",
                          r->theta_s, v->theta, v->phi, Y, v->Y, rgb.x, rgb.y, rgb.z);
            assert_true(rel_err(x, v->x) < PREETHAM_REL_TOL);
            assert_true(rel_err(y, v->y) < PREETHAM_REL_TOL);
            assert_true(rel_err(Y, v->Y) < PREETHAM_REL_TOL);
            assert_true(rel_err(rgb.x, v->r) < PREETHAM_REL_TOL);
            assert_true(rel_err(rgb.y, v->g) < PREETHAM_REL_TOL);
            assert_true(rel_err(rgb.z, v->b) < PREETHAM_REL_TOL);
        }
    }
}

static double luminance(const preetham_sky *s, vec3 d)
{
    double x, y, Y;
    preetham_xyY(s, d, &x, &y, &Y);
    return Y;
}

/* Over the model's range of turbidity and sun heights: radiance finite
 * and >= 0 everywhere (also below the horizon), and from T = 2.5 up the
 * brightest sky within 2 degrees of the sun (the grid's step is 1
 * degree).  Below that the paper's tables make the horizon the brightest
 * (T = 2, sun overhead: F_Y is 1.04 times brighter at the horizon than at
 * the sun), a property of the model, so the check leaves them out. */
static void test_preetham_shape(void **state)
{
    (void)state;
    const double turbidities[] = {1.7, 2.0, 2.5, 3.0, 6.0, 10.0};
    int clamped = 0, checked = 0;
    for (unsigned ti = 0; ti < sizeof turbidities / sizeof turbidities[0]; ti++)
        for (double theta_s = 0.0; theta_s <= 90.0; theta_s += 10.0) {
            preetham_sky s;
            preetham_init(&s, turbidities[ti], dir(theta_s, 40.0));
            vec3 brightest = v3(0, 1, 0);
            double best = -1.0;
            for (double th = 0.0; th <= 180.0; th += 1.0)
                for (double ph = 0.0; ph < 360.0; ph += 1.0) {
                    vec3 d = dir(th, ph);
                    double x, y, Y;
                    preetham_xyY(&s, d, &x, &y, &Y);
                    vec3 raw = xyY_to_rec709(x, y, Y / SKY_LUMINOUS_EFFICACY);
                    vec3 rgb = preetham_radiance(&s, d);
                    checked++;
                    clamped += raw.x < 0 || raw.y < 0 || raw.z < 0;
                    assert_true(v3_isfinite(rgb) && isfinite(Y) && Y > 0.0);
                    assert_true(rgb.x >= 0.0 && rgb.y >= 0.0 && rgb.z >= 0.0);
                    if (th <= 90.0 && Y > best) {
                        best = Y;
                        brightest = d;
                    }
                }
            double off = acos(fmin(1.0, v3_dot(brightest, s.sun))) * 180.0 / pi;
            if (turbidities[ti] >= 2.5) {
                if (off > 2.0)
                    print_message("T %g theta_s %g: brightest %.2f deg from the sun\n",
                                  turbidities[ti], theta_s, off);
                assert_true(off <= 2.0);
            }
            /* The sun's side of the sky is the brighter (the two are
             * alike with the sun overhead). */
            vec3 toward = dir(60.0, 40.0), away = dir(60.0, 220.0);
            if (theta_s > 0.0)
                assert_true(luminance(&s, toward) > luminance(&s, away));
        }
    /* The sun on the horizon, looking at it: chromaticity about (0.46,
     * 0.49), outside Rec. 709, blue down to -4% of Y. */
    print_message("%d of %d directions had a negative channel before the clamp\n", clamped, checked);
}

/* The header's clamps: turbidity into 1.7 .. 10, the sun onto the
 * horizon, and a view below the horizon taken at the horizon. */
static void test_preetham_clamps(void **state)
{
    (void)state;
    preetham_sky lo, hi, s;
    preetham_init(&lo, 0.5, dir(30.0, 0.0));
    preetham_init(&hi, 25.0, dir(30.0, 0.0));
    assert_true(lo.turbidity == 1.7 && hi.turbidity == 10.0);

    preetham_init(&s, 3.0, v3(1.0, -0.2, 0.0));
    assert_true(fabs(s.theta_s - pi / 2.0) < 1e-12 && fabs(s.sun.x - 1.0) < 1e-12);
    assert_true(isfinite(s.zenith_Y) && s.zenith_Y > 0.0);

    preetham_init(&s, 3.0, dir(50.0, 0.0));
    double xa, ya, Ya, xb, yb, Yb;
    preetham_xyY(&s, dir(90.0, 70.0), &xa, &ya, &Ya);
    preetham_xyY(&s, dir(120.0, 70.0), &xb, &yb, &Yb);
    assert_true(fabs(Ya - Yb) <= 1e-9 * Ya && fabs(xa - xb) < 1e-12 && fabs(ya - yb) < 1e-12);
}

static void test_xyY_d65_white(void **state)
{
    (void)state;
    vec3 w = xyY_to_rec709(0.3127, 0.3290, 1.0);
    print_message("D65 white: %.6f %.6f %.6f\n", w.x, w.y, w.z);
    assert_true(fabs(w.x - 1.0) < 1e-3 && fabs(w.y - 1.0) < 1e-3 && fabs(w.z - 1.0) < 1e-3);
    /* Luminance scales linearly. */
    vec3 w5 = xyY_to_rec709(0.3127, 0.3290, 5.0);
    assert_true(fabs(w5.x - 5.0 * w.x) < 1e-12 && fabs(w5.z - 5.0 * w.z) < 1e-12);
}

static double angle_diff(double a, double b)
{
    double d = fmod(fabs(a - b), 360.0);
    return d > 180.0 ? 360.0 - d : d;
}

/* Elevation and azimuth from a separate python3 implementation (not kept)
 * of the NOAA Solar Calculator spreadsheet's columns, written from the
 * spreadsheet's formulas with its acos form of the azimuth and the Julian
 * day from Python's date ordinal; the C code uses Meeus' calendar formula
 * and an atan2 azimuth, so the two agree only if both are right. */
typedef struct noaa_ref {
    const char *what;
    solar_time t;
    double elevation, azimuth;
} noaa_ref;

static void test_solar_position_reference(void **state)
{
    (void)state;
    const noaa_ref refs[] = {
        {"Karlsruhe 2026-06-21 15:00 CEST", {2026, 6, 21, 15.0, 2.0, 49.0069, 8.4037},
         58.69871556, 223.50916212},
        {"Karlsruhe 2026-06-21 09:00 CEST", {2026, 6, 21, 9.0, 2.0, 49.0069, 8.4037},
         32.34295733, 90.62474850},
        {"Karlsruhe 2026-12-21 12:00 CET", {2026, 12, 21, 12.0, 1.0, 49.0069, 8.4037},
         17.35055078, 174.12732429},
        {"Boulder 2010-06-21 12:00 (UTC-6)", {2010, 6, 21, 12.0, -6.0, 40.0, -105.0},
         68.92384371, 137.16999991},
        {"Sydney 2026-06-21 12:00 AEST", {2026, 6, 21, 12.0, 10.0, -33.8688, 151.2093},
         32.68855311, 359.15415478},
        /* 18:30 at UTC-10 is the next UTC day. */
        {"Honolulu 2026-06-21 18:30 HST", {2026, 6, 21, 18.5, -10.0, 21.3069, -157.8583},
         9.04573672, 291.72689015},
    };
    for (unsigned i = 0; i < sizeof refs / sizeof refs[0]; i++) {
        double el, az;
        solar_position(&refs[i].t, &el, &az);
        print_message("%s: elevation %.6f azimuth %.6f\n", refs[i].what, el, az);
        assert_true(fabs(el - refs[i].elevation) < 1e-6);
        assert_true(angle_diff(az, refs[i].azimuth) < 1e-6);
    }
}

/* Meeus, Astronomical Algorithms, examples 25.a and 28.b, 1992-10-13 0h:
 * declination -7.78507 deg and equation of time 13 min 42.7 s.  At the
 * pole the elevation is the declination; at longitude 180 - 13.7117 / 4
 * the true solar time is noon, so the sun is due south of latitude 45. */
static void test_solar_position_meeus(void **state)
{
    (void)state;
    double el, az;
    const solar_time pole = {1992, 10, 13, 0.0, 0.0, 90.0, 0.0};
    solar_position(&pole, &el, &az);
    print_message("pole: elevation %.6f (Meeus' declination -7.78507)\n", el);
    assert_true(fabs(el - -7.78507) < 1e-4);

    const solar_time noon = {1992, 10, 13, 0.0, 0.0, 45.0, 180.0 - (13.0 + 42.7 / 60.0) / 4.0};
    solar_position(&noon, &el, &az);
    print_message("true noon from Meeus' equation of time: azimuth %.5f\n", az);
    /* 0.01 deg of azimuth here is about 2 s of the equation of time. */
    assert_true(fabs(az - 180.0) < 0.01);
    assert_true(fabs(el - (90.0 - 45.0 - 7.78507)) < 1e-3);
}

/* Facts independent of any implementation: at local solar noon the sun
 * is due south (north in the southern hemisphere, outside the tropics) at
 * elevation 90 - |latitude| +- declination, and overhead at the equator at
 * the equinox.  Noon times are 720 min minus 4 min per degree of longitude
 * minus the equation of time (about -1.83 min on 2026-06-21). */
static void test_solar_position_facts(void **state)
{
    (void)state;
    double el, az;
    /* Solstice 2026-06-21 08:24 UTC, declination 23.44 deg; Karlsruhe's
     * solar noon is 13:28 CEST. */
    const solar_time karlsruhe = {2026, 6, 21, 13.0 + 28.2 / 60.0, 2.0, 49.0069, 8.4037};
    solar_position(&karlsruhe, &el, &az);
    print_message("Karlsruhe solar noon: elevation %.4f azimuth %.4f\n", el, az);
    assert_true(fabs(el - (90.0 - 49.0069 + 23.44)) < 0.1);
    assert_true(fabs(az - 180.0) < 1.0);

    const solar_time lat49 = {2026, 6, 21, 12.0 + 1.8 / 60.0, 0.0, 49.01, 0.0};
    solar_position(&lat49, &el, &az);
    assert_true(fabs(el - 64.43) < 0.1 && fabs(az - 180.0) < 1.0);

    /* Equinox 2026-03-20 14:46 UTC. */
    const solar_time equator = {2026, 3, 20, 12.0 + 7.4 / 60.0, 0.0, 0.0, 0.0};
    solar_position(&equator, &el, &az);
    print_message("equator at the equinox: elevation %.4f\n", el);
    assert_true(el > 89.0);

    const solar_time sydney = {2026, 6, 21, 11.0 + 56.9 / 60.0, 10.0, -33.8688, 151.2093};
    solar_position(&sydney, &el, &az);
    print_message("Sydney solar noon: elevation %.4f azimuth %.4f\n", el, az);
    assert_true(fabs(el - (90.0 - 33.8688 - 23.44)) < 0.1);
    assert_true(angle_diff(az, 0.0) < 1.0);

    /* Morning sun in the east, afternoon sun in the west. */
    const solar_time morning = {2026, 6, 21, 9.0, 2.0, 49.0069, 8.4037};
    const solar_time evening = {2026, 6, 21, 19.0, 2.0, 49.0069, 8.4037};
    solar_position(&morning, &el, &az);
    assert_true(az > 45.0 && az < 135.0 && el > 0.0);
    solar_position(&evening, &el, &az);
    assert_true(az > 225.0 && az < 315.0 && el > 0.0);
}

static void assert_near(vec3 a, vec3 b)
{
    if (v3_length(v3_sub(a, b)) >= 1e-12)
        print_message("got %.9f %.9f %.9f, want %.9f %.9f %.9f\n", a.x, a.y, a.z, b.x, b.y, b.z);
    assert_true(v3_length(v3_sub(a, b)) < 1e-12);
}

static void test_solar_direction(void **state)
{
    (void)state;
    const vec3 north = v3(0.0, 0.0, -1.0);
    assert_near(solar_direction(0.0, 0.0, north), v3(0.0, 0.0, -1.0));
    assert_near(solar_direction(0.0, 90.0, north), v3(1.0, 0.0, 0.0));
    assert_near(solar_direction(0.0, 180.0, north), v3(0.0, 0.0, 1.0));
    assert_near(solar_direction(0.0, 270.0, north), v3(-1.0, 0.0, 0.0));
    assert_near(solar_direction(90.0, 123.0, north), v3(0.0, 1.0, 0.0));
    double h = sqrt(0.5);
    assert_near(solar_direction(45.0, 90.0, north), v3(h, h, 0.0));
    /* Only north's horizontal part counts, whatever its length; north at
     * +x puts east at +z. */
    assert_near(solar_direction(0.0, 90.0, v3(3.0, 2.0, 0.0)), v3(0.0, 0.0, 1.0));
    vec3 d = solar_direction(58.7, 223.5, v3(0.3, 0.1, -0.8));
    assert_true(fabs(v3_length(d) - 1.0) < 1e-12 && fabs(d.y - sin(rad(58.7))) < 1e-12);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_preetham_zenith_and_coefficients),
        cmocka_unit_test(test_preetham_views),
        cmocka_unit_test(test_preetham_shape),
        cmocka_unit_test(test_preetham_clamps),
        cmocka_unit_test(test_xyY_d65_white),
        cmocka_unit_test(test_solar_position_reference),
        cmocka_unit_test(test_solar_position_meeus),
        cmocka_unit_test(test_solar_position_facts),
        cmocka_unit_test(test_solar_direction),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
