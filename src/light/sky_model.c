/* Daylight from published formulas: the Preetham, Shirley and Smits (1999)
 * analytic sky (Perez distributions scaled by the zenith values, Appendix
 * A.2 of the paper) and the sun's position from NOAA's Solar Calculator
 * equations.  Everything is in double precision; see sky_model.h for the
 * units. */
#include "light/sky_model.h"

#include <math.h>

static const double pi = 3.14159265358979323846;

static double radians(double a) { return a * (pi / 180.0); }
static double degrees(double a) { return a * (180.0 / pi); }
static double clamp(double v, double lo, double hi) { return v < lo ? lo : v > hi ? hi : v; }

/* v in [0, 360), as the spreadsheet's MOD(v, 360) gives for either sign. */
static double wrap_degrees(double v)
{
    double r = fmod(v, 360.0);
    return r < 0.0 ? r + 360.0 : r;
}

/* ---- Preetham sky ------------------------------------------------------ */

/* Turbidity range of the header; the paper fitted T in 2 .. 6 and its
 * formulas are used a little beyond that. */
#define TURBIDITY_MIN 1.7
#define TURBIDITY_MAX 10.0

/* Smallest cos(theta) of a view direction: keeps B / cos(theta) finite at
 * and below the horizon.  With the model's B < 0 the term e^(B / 0.01) is
 * below 2e-8 (Y) and 2e-5 (x, y) of its factor at T = 1.7, so the floor
 * changes the horizon value by far less than the model's accuracy. */
#define COS_THETA_FLOOR 0.01

/* Perez coefficients A..E as slope * T + offset, the paper's Appendix A.2
 * (four decimals as printed there). */
static const double perez_table_Y[5][2] = {
    {0.1787, -1.4630}, {-0.3554, 0.4275}, {-0.0227, 5.3251}, {0.1206, -2.5771}, {-0.0670, 0.3703},
};
static const double perez_table_x[5][2] = {
    {-0.0193, -0.2592}, {-0.0665, 0.0008}, {-0.0004, 0.2125}, {-0.0641, -0.8989}, {-0.0033, 0.0452},
};
static const double perez_table_y[5][2] = {
    {-0.0167, -0.2608}, {-0.0950, 0.0092}, {-0.0079, 0.2102}, {-0.0441, -1.6537}, {-0.0109, 0.0529},
};

/* Zenith chromaticity matrices: rows T^2, T, 1; columns theta_s^3 .. 1. */
static const double zenith_table_x[3][4] = {
    {0.00166, -0.00375, 0.00209, 0.0},
    {-0.02903, 0.06377, -0.03202, 0.00394},
    {0.11693, -0.21196, 0.06052, 0.25886},
};
static const double zenith_table_y[3][4] = {
    {0.00275, -0.00610, 0.00317, 0.0},
    {-0.04214, 0.08970, -0.04153, 0.00516},
    {0.15346, -0.26756, 0.06670, 0.26688},
};

static void perez_coefficients(const double table[5][2], double t, double out[5])
{
    for (int i = 0; i < 5; i++)
        out[i] = table[i][0] * t + table[i][1];
}

/* [T^2 T 1] M [theta_s^3 theta_s^2 theta_s 1]^T */
static double zenith_chromaticity(const double m[3][4], double t, double theta_s)
{
    const double tv[3] = {t * t, t, 1.0};
    const double sv[4] = {theta_s * theta_s * theta_s, theta_s * theta_s, theta_s, 1.0};
    double sum = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            sum += tv[i] * m[i][j] * sv[j];
    return sum;
}

/* The paper gives kcd/m^2; the header promises cd/m^2. */
static double zenith_luminance(double t, double theta_s)
{
    double chi = (4.0 / 9.0 - t / 120.0) * (pi - 2.0 * theta_s);
    return 1000.0 * ((4.0453 * t - 4.9710) * tan(chi) - 0.2155 * t + 2.4192);
}

/* Perez et al.'s F(theta, gamma), given cos(theta) and gamma. */
static double perez(const double c[5], double cos_theta, double gamma)
{
    double cos_gamma = cos(gamma);
    return (1.0 + c[0] * exp(c[1] / cos_theta)) *
           (1.0 + c[2] * exp(c[3] * gamma) + c[4] * cos_gamma * cos_gamma);
}

/* Unit d moved up onto the horizon when it points below it.  Straight
 * down has no azimuth; it takes the horizon at +x, an arbitrary choice
 * for a single direction. */
static vec3 clamp_to_upper_hemisphere(vec3 d)
{
    if (d.y >= 0.0)
        return d;
    vec3 h = v3(d.x, 0.0, d.z);
    return v3_length(h) > 1e-12 ? v3_normalize(h) : v3(1.0, 0.0, 0.0);
}

void preetham_init(preetham_sky *s, double turbidity, vec3 sun)
{
    double t = clamp(turbidity, TURBIDITY_MIN, TURBIDITY_MAX);
    s->turbidity = t;
    s->sun = clamp_to_upper_hemisphere(v3_normalize(sun));
    s->theta_s = acos(clamp(s->sun.y, -1.0, 1.0));
    s->zenith_Y = zenith_luminance(t, s->theta_s);
    s->zenith_x = zenith_chromaticity(zenith_table_x, t, s->theta_s);
    s->zenith_y = zenith_chromaticity(zenith_table_y, t, s->theta_s);
    perez_coefficients(perez_table_Y, t, s->perez_Y);
    perez_coefficients(perez_table_x, t, s->perez_x);
    perez_coefficients(perez_table_y, t, s->perez_y);
}

/* zenith * F(theta, gamma) / F(0, theta_s): the sun's zenith angle is the
 * zenith's angle to the sun. */
static double perez_scaled(const double c[5], double zenith, double cos_theta, double gamma,
                           double theta_s)
{
    return zenith * perez(c, cos_theta, gamma) / perez(c, 1.0, theta_s);
}

void preetham_xyY(const preetham_sky *s, vec3 d, double *x, double *y, double *Y)
{
    vec3 v = clamp_to_upper_hemisphere(d);
    double cos_theta = v.y > COS_THETA_FLOOR ? v.y : COS_THETA_FLOOR;
    double gamma = acos(clamp(v3_dot(v, s->sun), -1.0, 1.0));
    *x = perez_scaled(s->perez_x, s->zenith_x, cos_theta, gamma, s->theta_s);
    *y = perez_scaled(s->perez_y, s->zenith_y, cos_theta, gamma, s->theta_s);
    *Y = perez_scaled(s->perez_Y, s->zenith_Y, cos_theta, gamma, s->theta_s);
}

/* Channels are clamped at 0: a chromaticity of the model outside the
 * Rec. 709 triangle would give a negative one, which no light emits. */
vec3 preetham_radiance(const preetham_sky *s, vec3 d)
{
    double x, y, Y;
    preetham_xyY(s, d, &x, &y, &Y);
    vec3 rgb = xyY_to_rec709(x, y, Y / SKY_LUMINOUS_EFFICACY);
    return v3(dmax(rgb.x, 0.0), dmax(rgb.y, 0.0), dmax(rgb.z, 0.0));
}

/* y <= 0 is no colour (X and Z would be infinite); it gives black. */
vec3 xyY_to_rec709(double x, double y, double Y)
{
    if (!(y > 0.0))
        return v3(0.0, 0.0, 0.0);
    double X = x * Y / y, Z = (1.0 - x - y) * Y / y;
    return v3(3.2406 * X - 1.5372 * Y - 0.4986 * Z,
              -0.9689 * X + 1.8758 * Y + 0.0415 * Z,
              0.0557 * X - 0.2040 * Y + 1.0570 * Z);
}

/* ---- NOAA solar position ----------------------------------------------- */

/* Julian day at 0h UT of a Gregorian date (Meeus, Astronomical Algorithms,
 * ch. 7); the spreadsheet gets the same from its date serial. */
static double julian_day(int year, int month, int day)
{
    if (month <= 2) {
        year -= 1;
        month += 12;
    }
    double a = floor(year / 100.0);
    double b = 2.0 - a + floor(a / 4.0);
    return floor(365.25 * (year + 4716)) + floor(30.6001 * (month + 1)) + day + b - 1524.5;
}

/* The sun's declination (degrees) and the equation of time (minutes) at
 * Julian century jc, the spreadsheet's columns G .. V. */
static void sun_declination_and_eot(double jc, double *declination, double *eot_minutes)
{
    double mean_long = wrap_degrees(280.46646 + jc * (36000.76983 + jc * 0.0003032));
    double mean_anom = 357.52911 + jc * (35999.05029 - 0.0001537 * jc);
    double ecc = 0.016708634 - jc * (0.000042037 + 0.0000001267 * jc);
    double m = radians(mean_anom);
    double center = sin(m) * (1.914602 - jc * (0.004817 + 0.000014 * jc)) +
                    sin(2.0 * m) * (0.019993 - 0.000101 * jc) + sin(3.0 * m) * 0.000289;
    /* Nutation and aberration through the longitude of the Moon's node. */
    double omega = radians(125.04 - 1934.136 * jc);
    double app_long = mean_long + center - 0.00569 - 0.00478 * sin(omega);
    double mean_obliq =
        23.0 + (26.0 + (21.448 - jc * (46.815 + jc * (0.00059 - jc * 0.001813))) / 60.0) / 60.0;
    double obliq = radians(mean_obliq + 0.00256 * cos(omega));
    *declination = degrees(asin(sin(obliq) * sin(radians(app_long))));

    double vy = tan(obliq / 2.0) * tan(obliq / 2.0);
    double l0 = radians(mean_long);
    double eot = vy * sin(2.0 * l0) - 2.0 * ecc * sin(m) + 4.0 * ecc * vy * sin(m) * cos(2.0 * l0) -
                 0.5 * vy * vy * sin(4.0 * l0) - 1.25 * ecc * ecc * sin(2.0 * m);
    *eot_minutes = 4.0 * degrees(eot);
}

void solar_position(const solar_time *t, double *elevation_deg, double *azimuth_deg)
{
    double jd = julian_day(t->year, t->month, t->day) + (t->hour - t->utc_offset) / 24.0;
    double jc = (jd - 2451545.0) / 36525.0;
    double decl_deg, eot;
    sun_declination_and_eot(jc, &decl_deg, &eot);

    double true_solar_min = fmod(t->hour * 60.0 + eot + 4.0 * t->longitude - 60.0 * t->utc_offset, 1440.0);
    if (true_solar_min < 0.0)
        true_solar_min += 1440.0;
    double hour_angle = radians(true_solar_min / 4.0 - 180.0);

    double lat = radians(t->latitude), decl = radians(decl_deg);
    double cos_zenith = sin(lat) * sin(decl) + cos(lat) * cos(decl) * cos(hour_angle);
    *elevation_deg = 90.0 - degrees(acos(clamp(cos_zenith, -1.0, 1.0)));
    /* The spreadsheet's acos form divided by sin(zenith) and cos(latitude);
     * atan2 of the same two components (azimuth from south, westward, as
     * Meeus 13.5) stays finite with the sun at the zenith or at a pole. */
    double from_south = atan2(sin(hour_angle) * cos(decl),
                              cos(hour_angle) * sin(lat) * cos(decl) - sin(decl) * cos(lat));
    *azimuth_deg = wrap_degrees(degrees(from_south) + 180.0);
}

vec3 solar_direction(double elevation_deg, double azimuth_deg, vec3 north)
{
    const vec3 up = v3(0.0, 1.0, 0.0);
    vec3 n = v3(north.x, 0.0, north.z);
    /* A vertical north names no direction; take the header's example, -z. */
    n = v3_length(n) > 1e-12 ? v3_normalize(n) : v3(0.0, 0.0, -1.0);
    vec3 east = v3_cross(n, up);
    double el = radians(elevation_deg), az = radians(azimuth_deg);
    vec3 horizontal = v3_add(v3_scale(n, cos(az)), v3_scale(east, sin(az)));
    return v3_add(v3_scale(horizontal, cos(el)), v3_scale(up, sin(el)));
}
