/* The path tracer's specular materials against closed forms: mirrors
 * under a uniform sky, Schlick's Fresnel of the "metallic" lobe, a glass
 * slab level by level (Fresnel at both faces, internal reflections,
 * R + T = 1), and light leaving glass (the 1/n^2 radiance factor and
 * Snell's law).  Tolerances as in test_path_analytic.c: means within
 * Z_MEAN standard errors estimated from the spread of the pixels, exact
 * estimates within float rounding. */
#include "test_support.h"
#include "fresnel.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#include "path_check.h"

/* ---------------------------------------------------------------------
 * Closed forms and cameras.
 * --------------------------------------------------------------------- */

static double schlick(double cos_i, double n)
{
    double r0 = (1 - n) / (1 + n);
    r0 *= r0;
    return r0 + (1 - r0) * pow(1 - cos_i, 5);
}

/* A nearly orthographic camera: the viewpoint 1000 units behind a screen
 * of half size half centred at centre and perpendicular to dir, so every
 * ray meets a plane at the same angle (to ~1e-3 rad across the image). */
static tcam far_cam(const double centre[3], const double dir_in[3],
                    const double up[3], double half, int n)
{
    double dir[3] = {dir_in[0], dir_in[1], dir_in[2]}, vp[3];
    v_norm(dir);
    for (int i = 0; i < 3; i++)
        vp[i] = centre[i] - 1000 * dir[i];
    return cam_look(vp, dir, up, 1000, half, n, n);
}

/* Pixels of an n x n image of the camera looking at a sphere's centre
 * (outline radius rho on a screen of half size half): wholly on it (in)
 * or wholly off it (out). */
static void sphere_masks(int n, double rho, double half, unsigned char *in,
                         unsigned char *out)
{
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            double x0 = half * (-1 + 2.0 * x / n), x1 = x0 + 2 * half / n;
            double y0 = half * (-1 + 2.0 * y / n), y1 = y0 + 2 * half / n;
            double fx = fmax(fabs(x0), fabs(x1)), fy = fmax(fabs(y0), fabs(y1));
            double nx = (x0 <= 0 && x1 >= 0) ? 0 : fmin(fabs(x0), fabs(x1));
            double ny = (y0 <= 0 && y1 >= 0) ? 0 : fmin(fabs(y0), fabs(y1));
            in[y * n + x] = fx * fx + fy * fy < rho * rho;
            out[y * n + x] = nx * nx + ny * ny > rho * rho;
        }
}

#define CHARACTER(d, m, r, t) "{\"diffuse\": " #d ", \"metallic\": " #m \
    ", \"reflecting\": " #r ", \"refractive\": " #t "}"

/* ---------------------------------------------------------------------
 * Mirrors and metals.
 * --------------------------------------------------------------------- */

/* A mirror sphere (colour c) under a sky of radiance Ls reflects only the
 * sky: c * Ls at every pixel that lies wholly on it, at level 1 exactly.
 * A half-diffuse, half-mirror sphere gives the same: both lobes see only
 * the sky. */
static void test_mirror_sphere_under_sky(void **state)
{
    (void)state;
    const int n = 16, px = n * n;
    const char *characters[] = {CHARACTER(0, 0, 1, 0), CHARACTER(0.3, 0, 0.7, 0)};
    const char *names[] = {"mirror sphere", "30% diffuse, 70% mirror sphere"};
    const double col[3] = {0.9, 0.6, 0.3}, sky[3] = {2, 3, 4};
    double vp[3] = {0.0, 0.0, 5}, look[3] = {0, 0, -1}, up[3] = {0, 1, 0};
    tcam c = cam_look(vp, look, up, 1.0, 0.5, n, n);
    char *cj = cam_json(&c);
    unsigned char in[256], out[256];
    sphere_masks(n, tan(asin(1.0 / 5.0)), 0.5, in, out);
    double e_on[3] = {col[0] * sky[0], col[1] * sky[1], col[2] * sky[2]};
    double *e = calloc((size_t)px * 3, sizeof(double));
    double *e_sky = calloc((size_t)px * 3, sizeof(double));
    fill(e, px, e_on);
    fill(e_sky, px, sky);
    for (int m = 0; m < 2; m++) {
        char *text = fmt_alloc(
            "{\"scene\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, "
            "\"material\": {\"character\": %s, \"color\": [0.9, 0.6, 0.3]}}}, "
            "{\"sky\": {\"color\": [2, 3, 4]}}], %s}", characters[m], cj);
        zt_scene *s = scene_from(text);
        zt_image *l0 = render(s, 0, 0, 8, 5);
        zt_image *l1 = render(s, 1, 1, 8, 5);
        zt_image *l2 = render(s, 2, 2, 8, 5);
        zt_image *d8 = render(s, -1, 8, 8, 5);
        char what[80];
        for (int k = 0; k < 3; k++) {
            snprintf(what, sizeof what, "%s, level 1 = c*Ls", names[m]);
            expect_each(what, k, residuals(l1, e, k, in), FLOAT_FLOOR);
            snprintf(what, sizeof what, "%s, depth 8 = c*Ls", names[m]);
            expect_each(what, k, residuals(d8, e, k, in), FLOAT_FLOOR);
            expect_each("sky around it, depth 8", k, residuals(d8, e_sky, k, out), FLOAT_FLOOR);
        }
        expect_black("sphere pixels at level 0", l0, in, 0);
        expect_black("level 2 (a convex mirror sees only the sky)", l2, NULL, 0);
        zt_image_release(l0);
        zt_image_release(l1);
        zt_image_release(l2);
        zt_image_release(d8);
        zt_scene_release(s);
        free(text);
    }
    free(e);
    free(e_sky);
    free(cj);
}

/* Camera rays meeting the plane z = 0 (normal -z, towards the camera) at
 * angle theta (degrees) from its normal; fills expect with
 * col * f(cos) averaged over each pixel. */
static tcam plane_view(double theta_deg, double half, int n)
{
    double t = theta_deg * PI / 180;
    /* 4 units back, so that even at 85 degrees the tilted screen stays in
     * front of the plane */
    double dir[3] = {sin(t), 0, cos(t)}, centre[3] = {-4 * sin(t), 0, -4 * cos(t)};
    double up[3] = {0, 1, 0};
    return far_cam(centre, dir, up, half, n);
}

/* A "metallic" plane is a mirror weighted by Schlick's Fresnel term with
 * R0 = ((1-n)/(1+n))^2, tinted by its colour: under a sky of radiance Ls,
 * level 1 = c * F(cos) * Ls exactly.  Indices 1.5 and 0.27 (metal-like),
 * from normal incidence to grazing.  With half of the lobe weight moved to
 * diffuse, the expectation is the weighted sum (noisy: lobe choice). */
static void test_metallic_plane_schlick(void **state)
{
    (void)state;
    const int n = 8, px = n * n, g = 4;
    const double col[3] = {0.9, 0.7, 0.5}, ls = 2;
    const double angles[] = {0, 45, 70, 85}, iors[] = {1.5, 0.27};
    double *e = calloc((size_t)px * 3, sizeof(double));
    for (int ii = 0; ii < 2; ii++)
        for (int ai = 0; ai < 4; ai++) {
            tcam c = plane_view(angles[ai], 0.2, n);
            char *cj = cam_json(&c);
            for (int mix = 0; mix < 2; mix++) {
                if (mix && ai != 2)
                    continue;
                char *text = fmt_alloc(
                    "{\"scene\": [{\"plane\": {\"normal\": [0, 0, -1], \"offset\": 0, "
                    "\"material\": {\"character\": %s, \"color\": [0.9, 0.7, 0.5], "
                    "\"refractiveindex\": %.17g}}}, {\"sky\": {\"color\": [2, 2, 2]}}], %s}",
                    mix ? CHARACTER(0.5, 0.5, 0, 0) : CHARACTER(0, 1, 0, 0), iors[ii], cj);
                zt_scene *s = scene_from(text);
                for (int y = 0; y < n; y++)
                    for (int x = 0; x < n; x++) {
                        double f = 0;
                        for (int j = 0; j < g; j++)
                            for (int i = 0; i < g; i++) {
                                double o[3], d[3];
                                cam_ray(&c, x + (i + 0.5) / g, y + (j + 0.5) / g, o, d);
                                f += schlick(d[2], iors[ii]) / (g * g);
                            }
                        for (int k = 0; k < 3; k++)
                            e[(y * n + x) * 3 + k] =
                                mix ? col[k] * ls * 0.5 * (f + 1) : col[k] * f * ls;
                    }
                char what[80];
                snprintf(what, sizeof what, "%s n=%.2f at %2.0f deg, level 1",
                         mix ? "half metal, half diffuse" : "metal", iors[ii], angles[ai]);
                zt_image *l1 = render(s, 1, 1, mix ? 2048 : 4, 5);
                for (int k = 0; k < 3; k++) {
                    resid r = residuals(l1, e, k, NULL);
                    if (mix)
                        expect_mean(what, k, r, FLOAT_FLOOR, 3e-3);
                    else
                        expect_each(what, k, r, 1e-4);
                }
                if (!mix) {
                    zt_image *l0 = render(s, 0, 0, 4, 5);
                    zt_image *l2 = render(s, 2, 2, 4, 5);
                    expect_black("level 0", l0, NULL, 0);
                    expect_black("level 2 (the plane sees only sky)", l2, NULL, 0);
                    zt_image_release(l0);
                    zt_image_release(l2);
                }
                zt_image_release(l1);
                zt_scene_release(s);
                free(text);
            }
            free(cj);
        }
    free(e);
}

/* ---------------------------------------------------------------------
 * Glass.
 * --------------------------------------------------------------------- */

/* A slab of glass (index n, colour c, two parallel planes of one object)
 * between a red emitter behind it and a green one behind the camera, seen
 * at angle theta.  With F the Fresnel reflectance at theta (the same at
 * both faces, from outside and inside), the green (reflected) light at
 * level 1 is c F, the red (transmitted) light at level 2 is
 * c^2 (1-F)^2, and every pair of internal reflections adds two levels and
 * a factor c^2 F^2: red at even levels, green at odd ones.  For c = 1 the
 * sums are T = (1-F)/(1+F) and R = 2F/(1+F): R + T = 1. */
static void glass_slab(double ior, double theta_deg, double tint, int spp)
{
    const int n = 16, px = n * n;
    double th = theta_deg * PI / 180, F = fresnel(cos(th), 1, ior);
    /* independent check of the index of reflection inside: Stokes */
    double th_t = asin(sin(th) / ior);
    assert_true(fabs(fresnel(cos(th_t), ior, 1) - F) < 1e-12);
    tcam c = plane_view(theta_deg, 0.3, n);
    char *cj = cam_json(&c);
    char *text = fmt_alloc(
        "{\"scene\": ["
        "{\"thing\": {\"material\": {\"character\": " CHARACTER(0, 0, 0, 1) ", "
        "\"color\": [%.17g, %.17g, %.17g], \"refractiveindex\": %.17g}, \"backculled\": false, "
        "\"parts\": [{\"plane\": {\"normal\": [0, 0, -1], \"offset\": 0}}, "
        "{\"plane\": {\"normal\": [0, 0, 1], \"offset\": 0.5}}]}}, "
        "{\"lightplane\": {\"normal\": [0, 0, -1], \"offset\": -3, \"emission\": [1, 0, 0], "
        "\"backculled\": true}}, "
        "{\"lightplane\": {\"normal\": [0, 0, 1], \"offset\": -5, \"emission\": [0, 1, 0], "
        "\"backculled\": true}}], %s}", tint, tint, tint, ior, cj);
    zt_scene *s = scene_from(text);
    double *e = calloc((size_t)px * 3, sizeof(double));
    char what[96];
    printf("  glass n=%.2f at %.0f deg, colour %.2f: F = %.6f\n", ior, theta_deg, tint, F);

    zt_image *img = render(s, 0, 0, 4, 9);
    expect_black("glass: level 0", img, NULL, 0);
    zt_image_release(img);
    /* Levels 1..3 one by one (deeper ones are rare events, left to the
     * sums below).  Each sample is a Bernoulli trial (which way the
     * dielectric sends the path), so the standard error must be near the
     * ideal sqrt((1-p)/(p N)) of a trial with probability p = amount /
     * tint^level over N samples: the guard allows 2.5 times that. */
    for (int level = 1; level <= 3; level++) {
        double v[3] = {0, 0, 0};
        double p = level == 1 ? F : (1 - F) * (1 - F) * pow(F, level - 2);
        int ch = level % 2 ? 1 : 0;
        v[ch] = pow(tint, level) * p;
        fill(e, px, v);
        img = render(s, level, level, spp, 9);
        snprintf(what, sizeof what, "glass n=%.1f %2.0f deg c=%.1f, level %d (%s)", ior,
                 theta_deg, tint, level, ch ? "reflected" : "transmitted");
        expect_mean(what, ch, residuals(img, e, ch, NULL), FLOAT_FLOOR,
                    2.5 * sqrt((1 - p) / (p * px * spp)));
        /* the other colour is absent at this level */
        double worst = 0;
        for (int i = 0; i < px; i++)
            worst = fmax(worst, img->pixels[i * 3 + (1 - ch)] + img->pixels[i * 3 + 2]);
        assert_true(worst == 0);
        zt_image_release(img);
    }
    /* all levels: geometric series */
    double c2 = tint * tint, T = c2 * (1 - F) * (1 - F) / (1 - c2 * F * F);
    double R = tint * F + tint * c2 * (1 - F) * (1 - F) * F / (1 - c2 * F * F);
    double v[3] = {T, R, 0};
    fill(e, px, v);
    img = render(s, -1, 64, spp, 9);
    double pt = T / c2, pr = R / tint; /* roughly the chance of each colour */
    snprintf(what, sizeof what, "glass n=%.1f %2.0f deg c=%.1f, T, depth 64", ior, theta_deg, tint);
    expect_mean(what, 0, residuals(img, e, 0, NULL), FLOAT_FLOOR,
                2.5 * sqrt((1 - pt) / (pt * px * spp)));
    snprintf(what, sizeof what, "glass n=%.1f %2.0f deg c=%.1f, R, depth 64", ior, theta_deg, tint);
    expect_mean(what, 1, residuals(img, e, 1, NULL), FLOAT_FLOOR,
                2.5 * sqrt((1 - pr) / (pr * px * spp)));
    if (tint == 1) {
        /* energy: R + T = 1 (in the blue channel of a summed copy) */
        assert_true(fabs(R + T - 1) < 1e-12);
        for (int i = 0; i < px; i++) {
            img->pixels[i * 3 + 2] = img->pixels[i * 3] + img->pixels[i * 3 + 1];
            e[i * 3 + 2] = 1;
        }
        snprintf(what, sizeof what, "glass n=%.1f %2.0f deg, R + T = 1", ior, theta_deg);
        expect_mean(what, 2, residuals(img, e, 2, NULL), FLOAT_FLOOR, 2e-3);
    }
    zt_image_release(img);
    free(e);
    zt_scene_release(s);
    free(text);
    free(cj);
}

static void test_glass_slab(void **state)
{
    (void)state;
    glass_slab(2.5, 0, 1, 512);  /* F = 0.184 */
    glass_slab(1.5, 60, 1, 512); /* F = 0.089 */
    glass_slab(1.5, 30, 0.8, 512);
}

/* Light inside glass: camera paths entering a denser medium carry the
 * factor (eta_i/eta_t)^2 = 1/n^2 (radiance/n^2 is invariant), so an
 * emitter of radiance Le inside glass looks like Le (1-F)/n^2 from air.
 * First a light plane under a glass surface at normal incidence; then a
 * light strip under the surface seen at 60 degrees, where only the pixels
 * whose rays, bent by Snell's law, reach the strip may be lit: it tests
 * the direction of refraction too (unbent rays would light other
 * pixels). */
static void test_light_inside_glass(void **state)
{
    (void)state;
    /* normal incidence, n = 2.5 */
    {
        const int n = 8, px = n * n;
        double ior = 2.5, F = fresnel(1, 1, ior), le = 3;
        tcam c = plane_view(0, 0.3, n);
        char *cj = cam_json(&c);
        char *text = fmt_alloc(
            "{\"scene\": [{\"plane\": {\"normal\": [0, 0, -1], \"offset\": 0, "
            "\"material\": {\"character\": " CHARACTER(0, 0, 0, 1) ", \"color\": [1, 1, 1], "
            "\"refractiveindex\": 2.5}}}, "
            "{\"lightplane\": {\"normal\": [0, 0, -1], \"offset\": -1, \"emission\": [3, 3, 3]}}], %s}",
            cj);
        zt_scene *s = scene_from(text);
        double v = le * (1 - F) / (ior * ior), ev[3] = {v, v, v};
        double *e = calloc((size_t)px * 3, sizeof(double));
        fill(e, px, ev);
        zt_image *img = render(s, -1, 8, 1024, 13);
        for (int k = 0; k < 3; k++)
            expect_mean("light plane under glass n=2.5: Le(1-F)/n^2", k,
                        residuals(img, e, k, NULL), FLOAT_FLOOR, 3e-3);
        zt_image_release(img);
        free(e);
        zt_scene_release(s);
        free(text);
        free(cj);
    }
    /* a strip x in [-0.3, 0.3] at depth 1 under glass n = 1.5, at 60 deg */
    {
        const int n = 24, px = n * n, g = 8;
        double ior = 1.5, th = 60 * PI / 180, le = 2;
        double dir[3] = {sin(th), 0, cos(th)};
        /* footprint centre on the surface at x = -1.05 */
        double centre[3] = {-1.05 - 2 * dir[0], 0, -2 * dir[2]}, up[3] = {0, 1, 0};
        tcam c = far_cam(centre, dir, up, 0.625, n);
        char *cj = cam_json(&c);
        char *text = fmt_alloc(
            "{\"scene\": [{\"plane\": {\"normal\": [0, 0, -1], \"offset\": 0, "
            "\"material\": {\"character\": " CHARACTER(0, 0, 0, 1) ", \"color\": [1, 1, 1], "
            "\"refractiveindex\": 1.5}}}, "
            "{\"light\": {\"emission\": [2, 2, 2], \"backculled\": true, \"parts\": ["
            "{\"lighttriangle\": {\"points\": [[-0.3, -5, 1], [-0.3, 5, 1], [0.3, 5, 1]]}}, "
            "{\"lighttriangle\": {\"points\": [[-0.3, -5, 1], [0.3, 5, 1], [0.3, -5, 1]]}}]}}], %s}",
            cj);
        zt_scene *s = scene_from(text);
        unsigned char lit[576], dark[576], dark_if_straight[576];
        int n_lit = 0, n_dark = 0, n_trap = 0;
        double *e = calloc((size_t)px * 3, sizeof(double));
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                int hits = 0, straight = 0;
                for (int j = 0; j < g; j++)
                    for (int i = 0; i < g; i++) {
                        double o[3], d[3];
                        cam_ray(&c, x + (i + 0.5) / g, y + (j + 0.5) / g, o, d);
                        double t = -o[2] / d[2], xe = o[0] + t * d[0], ye = o[1] + t * d[1];
                        /* Snell: tangential component scaled by 1/n */
                        double tx = d[0] / ior, ty = d[1] / ior;
                        double tz = sqrt(1 - tx * tx - ty * ty);
                        double xs = xe + tx / tz, ys = ye + ty / tz;
                        hits += fabs(xs) <= 0.3 && fabs(ys) <= 5;
                        straight += fabs(xe + d[0] / d[2]) <= 0.3;
                    }
                int i = y * n + x;
                lit[i] = hits == g * g;
                dark[i] = hits == 0;
                dark_if_straight[i] = dark[i] && straight == g * g;
                n_lit += lit[i];
                n_dark += dark[i];
                n_trap += dark_if_straight[i];
            }
        printf("  strip under glass: %d lit, %d dark pixels (%d lit if unbent)\n",
               n_lit, n_dark, n_trap);
        assert_true(n_lit >= 60 && n_trap >= 60);
        double v = le * (1 - fresnel(cos(th), 1, ior)) / (ior * ior), ev[3] = {v, v, v};
        fill(e, px, ev);
        zt_image *img = render(s, -1, 8, 256, 13);
        for (int k = 0; k < 3; k++)
            expect_mean("strip under glass at 60 deg: lit pixels", k,
                        residuals(img, e, k, lit), FLOAT_FLOOR, 3e-3);
        expect_black("strip under glass: dark pixels", img, dark, 0);
        zt_image_release(img);
        free(e);
        zt_scene_release(s);
        free(text);
        free(cj);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        TIMED_TEST(test_mirror_sphere_under_sky),
        TIMED_TEST(test_metallic_plane_schlick),
        TIMED_TEST(test_glass_slab),
        TIMED_TEST(test_light_inside_glass),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
