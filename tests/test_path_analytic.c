/* The path tracer against closed-form answers: furnaces (a convex sphere
 * under a uniform sky, integrating spheres lit by a point light and by a
 * sphere light, a sphere inside an enclosing light sphere), and the
 * irradiance of triangle, point and sphere lights on a diffuse plane.
 *
 * Tolerances.  Every pixel of a path traced image is an independent
 * estimate (its samples are scrambled with the pixel's own key), so the
 * standard error of an image mean follows from the spread of the pixels'
 * relative residuals (pixel / expected - 1).  Means must agree within
 * Z_MEAN standard errors plus a small floor for float rounding and for the
 * numerical integration of the expected value over each pixel's footprint;
 * each test also bounds the standard error itself, so that noise cannot
 * make an assertion vacuous.  Estimates that are exact by construction
 * (e.g. level 1 under a point light) are held to the floor alone. */
#include "test_support.h"

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
 * Closed forms.
 * --------------------------------------------------------------------- */

/* Irradiance at x (normal n) from a polygon of unit radiance wholly above
 * x's horizon (Lambert's formula):
 *   E = 1/2 * | sum_i angle(v_i, v_i+1) * n . unit(v_i x v_i+1) |. */
static double polygon_irradiance(const double x[3], const double n[3],
                                 const double (*p)[3], int count)
{
    double sum = 0;
    for (int i = 0; i < count; i++) {
        double a[3], b[3], c[3];
        v_sub(p[i], x, a);
        v_sub(p[(i + 1) % count], x, b);
        v_norm(a);
        v_norm(b);
        v_cross(a, b, c);
        double s = v_len(c);
        if (s > 0)
            sum += atan2(s, v_dot(a, b)) * v_dot(n, c) / s;
    }
    return 0.5 * fabs(sum);
}

/* Averages f over the footprint of pixel (x, y) on the plane y = 0 with a
 * g x g midpoint rule. */
typedef double (*plane_fn)(const double X[3], const void *ctx);

static double pixel_average_on_floor(const tcam *c, int x, int y, int g,
                                     plane_fn f, const void *ctx)
{
    double sum = 0;
    for (int j = 0; j < g; j++)
        for (int i = 0; i < g; i++) {
            double o[3], d[3], X[3];
            cam_ray(c, x + (i + 0.5) / g, y + (j + 0.5) / g, o, d);
            double t = -o[1] / d[1];
            for (int k = 0; k < 3; k++)
                X[k] = o[k] + t * d[k];
            sum += f(X, ctx);
        }
    return sum / (g * g);
}

/* A camera above the floor y = 0 looking straight down: viewpoint at
 * (0.1, vy, 0.05), screen at height sy (below any light, so camera rays
 * start under it), footprint half size about half*vy/(vy-sy). */
static tcam floor_cam(double vy, double sy, double half, int n)
{
    double vp[3] = {0.1, vy, 0.05}, look[3] = {0, -1, 0}, up[3] = {0, 0, -1};
    return cam_look(vp, look, up, vy - sy, half, n, n);
}

/* Fills expect[] (w*h*3) with color[c] * g(pixel average of f). */
static void floor_expectation(const tcam *c, int g, plane_fn f, const void *ctx,
                              const double color[3], double *expect)
{
    for (int y = 0; y < c->h; y++)
        for (int x = 0; x < c->w; x++) {
            double v = pixel_average_on_floor(c, x, y, g, f, ctx);
            for (int k = 0; k < 3; k++)
                expect[(y * c->w + x) * 3 + k] = color[k] * v;
        }
}

/* The lights of a floor test; radiance = albedo/pi * E (diffuse floor). */
typedef struct floor_lights {
    int triangles;
    double tri[4][3][3];
    double tri_le[4];
    int spheres;
    double sph_c[2][3], sph_r[2], sph_le[2];
    int points;
    double pt[2][3], pt_i[2];
} floor_lights;

static double floor_radiance(const double X[3], const void *ctx)
{
    const floor_lights *l = ctx;
    const double up[3] = {0, 1, 0};
    double e = 0;
    for (int i = 0; i < l->triangles; i++)
        e += l->tri_le[i] * polygon_irradiance(X, up, (const double (*)[3])l->tri[i], 3);
    for (int i = 0; i < l->spheres; i++) {
        /* a sphere wholly above the horizon acts as a point of intensity
         * pi r^2 L */
        double v[3];
        v_sub(l->sph_c[i], X, v);
        double d = v_len(v);
        e += PI * l->sph_le[i] * l->sph_r[i] * l->sph_r[i] * v[1] / (d * d * d);
    }
    for (int i = 0; i < l->points; i++) {
        double v[3];
        v_sub(l->pt[i], X, v);
        double d = v_len(v);
        e += l->pt_i[i] * v[1] / (d * d * d);
    }
    return e / PI;
}

static char *tri_json(const double t[3][3], double le, int culled)
{
    return fmt_alloc("{\"lighttriangle\": {\"points\": [[%.17g, %.17g, %.17g], "
                     "[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g]], "
                     "\"emission\": [%.17g, %.17g, %.17g], \"backculled\": %s}}",
                     t[0][0], t[0][1], t[0][2], t[1][0], t[1][1], t[1][2],
                     t[2][0], t[2][1], t[2][2], le, le, le,
                     culled ? "true" : "false");
}

/* A downward-facing (front = -y) triangle at height h, scaled by s around
 * (cx, cz). */
static void down_triangle(double s, double cx, double cz, double h,
                          double out[3][3])
{
    const double base[3][2] = {{-1, -1}, {1, -1}, {0, 1}};
    for (int i = 0; i < 3; i++) {
        out[i][0] = cx + s * base[i][0];
        out[i][1] = h;
        out[i][2] = cz + s * base[i][1];
    }
}

/* ---------------------------------------------------------------------
 * 1. Furnaces.
 * --------------------------------------------------------------------- */

/* A convex diffuse sphere under a constant sky: it cannot see itself, so
 * every point on it has radiance albedo * sky (level 1) and the sky is
 * level 0.  The camera looks at the centre, so the sphere's outline on
 * the screen is a circle and each pixel is classified exactly. */
static void test_convex_sphere_under_sky(void **state)
{
    (void)state;
    const int n = 16;
    const double albedo[3] = {0.5, 0.8, 0.25}, sky[3] = {2, 3, 4};
    double vp[3] = {0, 0, 5}, look[3] = {0, 0, -1}, up[3] = {0, 1, 0};
    tcam c = cam_look(vp, look, up, 1.0, 0.5, n, n);
    char *cj = cam_json(&c);
    char *text = fmt_alloc(
        "{\"scene\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, "
        "\"material\": " DIFFUSE(0.5, 0.8, 0.25) "}}, "
        "{\"sky\": {\"color\": [2, 3, 4]}}], %s}", cj);
    zt_scene *s = scene_from(text);

    /* Screen radius of the outline: tan(asin(1/5)) at distance 1. */
    double rho = tan(asin(1.0 / 5.0));
    unsigned char in[256], out[256];
    int n_in = 0, n_out = 0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            /* screen coordinates of the pixel's corners, centred */
            double x0 = -0.5 + (double)x / n, x1 = x0 + 1.0 / n;
            double y0 = -0.5 + (double)y / n, y1 = y0 + 1.0 / n;
            double fx = fmax(fabs(x0), fabs(x1)), fy = fmax(fabs(y0), fabs(y1));
            double nx = (x0 <= 0 && x1 >= 0) ? 0 : fmin(fabs(x0), fabs(x1));
            double ny = (y0 <= 0 && y1 >= 0) ? 0 : fmin(fabs(y0), fabs(y1));
            in[y * n + x] = fx * fx + fy * fy < rho * rho;
            out[y * n + x] = nx * nx + ny * ny > rho * rho;
            n_in += in[y * n + x];
            n_out += out[y * n + x];
        }
    assert_true(n_in >= 20 && n_out >= 100);

    double *e_sphere = calloc((size_t)n * n * 3, sizeof(double));
    double *e_sky = calloc((size_t)n * n * 3, sizeof(double));
    for (int i = 0; i < n * n; i++)
        for (int k = 0; k < 3; k++) {
            e_sphere[i * 3 + k] = albedo[k] * sky[k];
            e_sky[i * 3 + k] = sky[k];
        }

    zt_image *l0 = render(s, 0, 0, 16, 1);
    zt_image *l1 = render(s, 1, 1, 16, 1);
    zt_image *d4 = render(s, -1, 4, 16, 1);
    for (int k = 0; k < 3; k++) {
        expect_each("sky pixels, level 0 = sky", k, residuals(l0, e_sky, k, out), FLOAT_FLOOR);
        expect_each("sphere pixels, level 1 = albedo*sky", k,
                    residuals(l1, e_sphere, k, in), FLOAT_FLOOR);
        expect_each("sphere pixels, depth 4 = albedo*sky", k,
                    residuals(d4, e_sphere, k, in), FLOAT_FLOOR);
        expect_each("sky pixels, depth 4 = sky", k, residuals(d4, e_sky, k, out), FLOAT_FLOOR);
    }
    expect_black("sphere pixels at level 0", l0, in, 0);
    expect_black("sky pixels at level 1", l1, out, 0);

    zt_image_release(l0);
    zt_image_release(l1);
    zt_image_release(d4);
    free(e_sphere);
    free(e_sky);
    zt_scene_release(s);
    free(text);
    free(cj);
}

/* Level-by-level radiance of an integrating sphere: level L is
 * first * ratio^(L-1); depth D sums levels 1..D. */
static double geometric(double first, double ratio, int from, int to)
{
    double s = 0, t = first * pow(ratio, from - 1);
    for (int l = from; l <= to; l++, t *= ratio)
        s += t;
    return s;
}

/* The camera inside a closed diffuse sphere (radius R, albedo a, not
 * culled) with a point light of intensity I at its centre.  The direct
 * irradiance is I/R^2 everywhere on the wall, and an integrating sphere's
 * wall of radiance L irradiates itself with pi*L, so level 1 is
 * a*I/(pi R^2), each further level multiplies it by a, and depth D gives
 * L1 (1 - a^D)/(1 - a).  Levels 1..3 are exact in every sample (every wall
 * point sees the light at the same distance, and roulette starts after
 * the third event); deeper ones carry Russian roulette noise.  The three
 * channels are three furnaces: a = 0.5, 0.8, 0.2. */
static void test_integrating_sphere_point_light(void **state)
{
    (void)state;
    const int n = 16, px = n * n;
    const double a[3] = {0.5, 0.8, 0.2}, R = 2, I = 10;
    double vp[3] = {0, 0, 0.3}, look[3] = {0.2, 0.1, 1}, up[3] = {0, 1, 0};
    tcam c = cam_look(vp, look, up, 0.2, 0.15, n, n);
    char *cj = cam_json(&c);
    char *text = fmt_alloc(
        "{\"scene\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 2, "
        "\"backculled\": false, \"material\": " DIFFUSE(0.5, 0.8, 0.2) "}}, "
        "{\"lightpoint\": {\"point\": [0, 0, 0], \"emission\": [10, 10, 10]}}], %s}", cj);
    zt_scene *s = scene_from(text);
    double *e = calloc((size_t)px * 3, sizeof(double));
    double v[3];

    zt_image *img = render(s, 0, 0, 4, 1);
    expect_black("level 0 (a point light is never seen)", img, NULL, 0);
    zt_image_release(img);

    for (int level = 1; level <= 3; level++) {
        for (int k = 0; k < 3; k++)
            v[k] = geometric(a[k] * I / (PI * R * R), a[k], level, level);
        fill(e, px, v);
        img = render(s, level, level, 4, 1);
        for (int k = 0; k < 3; k++) {
            char what[64];
            snprintf(what, sizeof what, "point furnace, level %d (exact)", level);
            expect_each(what, k, residuals(img, e, k, NULL), FLOAT_FLOOR);
        }
        zt_image_release(img);
    }
    /* depth 1 (levels 0..1) is level 1 */
    for (int k = 0; k < 3; k++)
        v[k] = a[k] * I / (PI * R * R);
    fill(e, px, v);
    img = render(s, -1, 1, 4, 1);
    for (int k = 0; k < 3; k++)
        expect_each("point furnace, depth 1 = a E/pi", k, residuals(img, e, k, NULL), FLOAT_FLOOR);
    zt_image_release(img);

    /* depth 64: the whole series, with roulette noise from level 4 on */
    for (int k = 0; k < 3; k++)
        v[k] = geometric(a[k] * I / (PI * R * R), a[k], 1, 64);
    fill(e, px, v);
    img = render(s, -1, 64, 256, 1);
    for (int k = 0; k < 3; k++) {
        resid r = residuals(img, e, k, NULL);
        expect_mean("point furnace, depth 64 = L1/(1-a)", k, r, FLOAT_FLOOR, 4e-3);
    }
    zt_image_release(img);

    free(e);
    zt_scene_release(s);
    free(text);
    free(cj);
}

/* The camera inside a closed diffuse sphere (radius 1, albedo a) with a
 * light sphere (radius r, radiance Le) at its centre.  With s = r/1, the
 * light's direct irradiance on the wall is pi Le s^2 and the wall sees
 * itself over the rest of its cosine-weighted hemisphere, 1 - s^2; so
 * level L = a s^2 Le (a (1 - s^2))^(L-1).  Every bounce mixes light
 * sampling (the cone) and BSDF sampling under MIS: a wrong weight, cone
 * pdf or light pdf changes every level. */
static void sphere_furnace(double r, double le, int spp_level, int spp_depth,
                           double max_se)
{
    const int n = 16, px = n * n;
    const double a[3] = {0.5, 0.8, 0.2};
    double s2 = r * r;
    /* camera between the light and the wall, looking away from the light */
    double vp[3] = {0, 0.05, r + 0.05}, look[3] = {0.1, 0, 1}, up[3] = {0, 1, 0};
    tcam c = cam_look(vp, look, up, 0.05, 0.03, n, n);
    char *cj = cam_json(&c);
    char *text = fmt_alloc(
        "{\"scene\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, "
        "\"material\": " DIFFUSE(0.5, 0.8, 0.2) "}}, "
        "{\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": %.17g, "
        "\"emission\": [%.17g, %.17g, %.17g]}}], %s}", r, le, le, le, cj);
    zt_scene *s = scene_from(text);
    double *e = calloc((size_t)px * 3, sizeof(double));
    double v[3];
    char what[80];

    for (int level = 1; level <= 3; level++) {
        for (int k = 0; k < 3; k++)
            v[k] = geometric(a[k] * s2 * le, a[k] * (1 - s2), level, level);
        fill(e, px, v);
        zt_image *img = render(s, level, level, spp_level, 7);
        snprintf(what, sizeof what, "sphere furnace r=%g, level %d", r, level);
        /* From level 2 on, a share s^2 of the bounces hits the light and
         * ends: a rare event the spread between pixels does not show when
         * the light is tiny, so allow for it explicitly (once per bounce). */
        double floor = FLOAT_FLOOR + 2.0 * (level - 1) * s2;
        for (int k = 0; k < 3; k++)
            expect_mean(what, k, residuals(img, e, k, NULL), floor, max_se);
        zt_image_release(img);
    }
    for (int k = 0; k < 3; k++)
        v[k] = geometric(a[k] * s2 * le, a[k] * (1 - s2), 1, 64);
    fill(e, px, v);
    zt_image *img = render(s, -1, 64, spp_depth, 7);
    snprintf(what, sizeof what, "sphere furnace r=%g, depth 64", r);
    for (int k = 0; k < 3; k++)
        expect_mean(what, k, residuals(img, e, k, NULL), FLOAT_FLOOR, max_se);
    zt_image_release(img);

    free(e);
    zt_scene_release(s);
    free(text);
    free(cj);
}

static void test_integrating_sphere_sphere_light(void **state)
{
    (void)state;
    sphere_furnace(0.5, 1.0, 256, 256, 3e-3);   /* s^2 = 0.25: both strategies */
    sphere_furnace(0.02, 2500.0, 16, 512, 4e-3); /* a small cone: light sampling */
}

/* A diffuse sphere inside an enclosing (not culled) light sphere: the
 * camera sees the light (level 0 = Le) and the sphere, which sees nothing
 * but the light, so its radiance is albedo * Le (level 1) and nothing
 * else.  Light sampling from inside a sphere light uses its area density
 * (the other branch of the sphere sampler). */
static void test_inside_light_sphere(void **state)
{
    (void)state;
    const int n = 16, px = n * n;
    const double albedo[3] = {0.5, 0.8, 0.25}, le[3] = {1, 2, 3};
    double vp[3] = {0, 0, 2.5}, look[3] = {0, 0, -1}, up[3] = {0, 1, 0};
    /* outline radius on the screen at distance 0.2 */
    double rho = 0.2 * tan(asin(1 / 2.5)), half = 0.12;
    tcam c = cam_look(vp, look, up, 0.2, half, n, n);
    char *cj = cam_json(&c);
    char *text = fmt_alloc(
        "{\"scene\": [{\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": 3, "
        "\"emission\": [1, 2, 3]}}, "
        "{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, "
        "\"material\": " DIFFUSE(0.5, 0.8, 0.25) "}}], %s}", cj);
    zt_scene *s = scene_from(text);
    unsigned char in[256], out[256];
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
    double *e_light = calloc((size_t)px * 3, sizeof(double));
    double *e_sphere = calloc((size_t)px * 3, sizeof(double));
    double v[3] = {albedo[0] * le[0], albedo[1] * le[1], albedo[2] * le[2]};
    fill(e_light, px, le);
    fill(e_sphere, px, v);

    zt_image *l0 = render(s, 0, 0, 4, 3);
    zt_image *d8 = render(s, -1, 8, 64, 3);
    zt_image *l2 = render(s, 2, 2, 8, 3);
    for (int k = 0; k < 3; k++) {
        expect_each("enclosing light seen from inside, level 0", k,
                    residuals(l0, e_light, k, out), FLOAT_FLOOR);
        expect_each("enclosing light, depth 8", k, residuals(d8, e_light, k, out), FLOAT_FLOOR);
        expect_mean("sphere inside a light, depth 8 = albedo*Le", k,
                    residuals(d8, e_sphere, k, in), FLOAT_FLOOR, 2e-3);
    }
    expect_black("sphere pixels at level 0", l0, in, 0);
    expect_black("level 2 (lights absorb: nothing)", l2, NULL, 0);

    zt_image_release(l0);
    zt_image_release(d8);
    zt_image_release(l2);
    free(e_light);
    free(e_sphere);
    zt_scene_release(s);
    free(text);
    free(cj);
}

/* ---------------------------------------------------------------------
 * 2, 3, 7. Irradiance of triangle, point and sphere lights on a diffuse
 * floor (albedo rho): level 1 radiance = rho/pi * E, averaged over each
 * pixel's footprint numerically.
 * --------------------------------------------------------------------- */

#define FLOOR_ALBEDO "[0.8, 0.5, 0.3]"
static const double floor_albedo[3] = {0.8, 0.5, 0.3};
/* footprint integration grid: against a 40x40 grid its error on these
 * smooth irradiances is below 2.5e-6 on average and 2e-5 per pixel */
#define FOOT_GRID 16

static char *floor_json(const char *material_character)
{
    return fmt_alloc("{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, "
                     "\"material\": {\"character\": %s, \"color\": " FLOOR_ALBEDO "}}}",
                     material_character);
}

#define CHAR_DIFFUSE "{\"diffuse\": 1, \"metallic\": 0, \"reflecting\": 0, \"refractive\": 0}"

/* Renders level 1 of a diffuse floor (lobe weight diffuse_weight of
 * character) under the lights of lights_json, described for the closed
 * form by fl, and compares it with rho/pi * E per pixel footprint: the
 * mean within the noise (max_se bounds the standard error), or, when
 * exact (a single point light: every sample is exact but for its place in
 * the pixel), every pixel within 1e-4.  The depth-1 image must be the
 * same bytes: level 0 is empty (the lights are out of view). */
static void floor_case(const char *what, const tcam *c, const char *lights_json,
                       const floor_lights *fl, const char *character,
                       double diffuse_weight, int spp, double max_se,
                       int exact)
{
    int px = c->w * c->h;
    char *cj = cam_json(c);
    char *fj = floor_json(character);
    char *text = fmt_alloc("{\"scene\": [%s, %s], %s}", fj, lights_json, cj);
    zt_scene *s = scene_from(text);
    double *e = calloc((size_t)px * 3, sizeof(double));
    double col[3];
    for (int k = 0; k < 3; k++)
        col[k] = diffuse_weight * floor_albedo[k];
    floor_expectation(c, FOOT_GRID, floor_radiance, fl, col, e);
    zt_image *img = render(s, 1, 1, spp, 11);
    for (int k = 0; k < 3; k++) {
        resid r = residuals(img, e, k, NULL);
        if (exact)
            expect_each(what, k, r, 1e-4);
        else
            expect_mean(what, k, r, 2e-5, max_se);
    }
    zt_image *d1 = render(s, -1, 1, spp, 11);
    assert_memory_equal(d1->pixels, img->pixels, (size_t)px * 3 * sizeof(float));
    zt_image_release(d1);
    zt_image_release(img);
    free(e);
    zt_scene_release(s);
    free(text);
    free(fj);
    free(cj);
}

/* Sanity of the closed form itself: a tiny triangle acts as a point. */
static void test_polygon_formula(void **state)
{
    (void)state;
    double t[3][3], x[3] = {0.3, 0, -0.2}, n[3] = {0, 1, 0};
    down_triangle(1e-3, 0, 0, 1, t);
    double e = polygon_irradiance(x, n, (const double (*)[3])t, 3);
    /* the centroid of the triangle is at (0, 1, -1e-3/3) */
    double area = 0.5 * 2e-3 * 2e-3, v[3] = {-0.3, 1, 0.2 - 1e-3 / 3}, d = v_len(v);
    double approx = area * (1 / d) * (1 / d) / (d * d);
    assert_true(fabs(e / approx - 1) < 1e-4);
    /* a huge triangle above: E -> pi (the whole hemisphere) */
    down_triangle(1e6, 0, 0, 1, t);
    e = polygon_irradiance(x, n, (const double (*)[3])t, 3);
    assert_true(fabs(e / PI - 1) < 1e-5);
}

/* Triangle lights of three sizes against Lambert's formula: a large one
 * (BSDF sampling carries most), a medium one (both strategies compete)
 * and a tiny one (light sampling carries all); then two lights at once
 * (light selection by power inside the MIS weights), a light emitting
 * from both sides turned upside down, a culled one turned away (black),
 * and a half-diffuse half-mirror floor. */
static void test_triangle_light_on_floor(void **state)
{
    (void)state;
    tcam c = floor_cam(1.6, 0.8, 0.4, 16);
    floor_lights fl;
    char *lj;

    struct { const char *what; double s, le; int spp; } sizes[] = {
        {"large triangle light (BSDF-dominated)", 10, 0.5, 64},
        {"medium triangle light (MIS)", 1, 1, 64},
        {"tiny triangle light (NEE-dominated)", 0.05, 400, 16},
    };
    for (int i = 0; i < 3; i++) {
        memset(&fl, 0, sizeof fl);
        fl.triangles = 1;
        down_triangle(sizes[i].s, 0.1, -0.1, 1, fl.tri[0]);
        fl.tri_le[0] = sizes[i].le;
        lj = tri_json((const double (*)[3])fl.tri[0], sizes[i].le, 1);
        floor_case(sizes[i].what, &c, lj, &fl, CHAR_DIFFUSE, 1, sizes[i].spp, 2e-3, 0);
        free(lj);
    }

    /* a tiny bright light and a large dim one together, of similar power
     * (4000 * 0.005 vs 0.3 * 18): the light choice enters both MIS
     * weights */
    memset(&fl, 0, sizeof fl);
    fl.triangles = 2;
    down_triangle(0.05, 0.3, 0.2, 1, fl.tri[0]);
    /* the tiny light hides its own solid angle of the large one (which
     * lies behind it from every floor point): 4000 - 0.3 net */
    fl.tri_le[0] = 4000 - 0.3;
    down_triangle(3, 0, 0, 1.3, fl.tri[1]);
    fl.tri_le[1] = 0.3;
    {
        char *a = tri_json((const double (*)[3])fl.tri[0], 4000, 1);
        char *b = tri_json((const double (*)[3])fl.tri[1], 0.3, 1);
        lj = fmt_alloc("%s, %s", a, b);
        free(a);
        free(b);
    }
    floor_case("tiny bright + large dim triangle lights", &c, lj, &fl,
               CHAR_DIFFUSE, 1, 256, 3e-3, 0);
    free(lj);

    /* the medium light upside down: not culled it lights the floor with
     * its back; culled it is dark */
    memset(&fl, 0, sizeof fl);
    fl.triangles = 1;
    down_triangle(1, 0.1, -0.1, 1, fl.tri[0]);
    fl.tri_le[0] = 1;
    double flipped[3][3];
    memcpy(flipped[0], fl.tri[0][0], sizeof flipped[0]);
    memcpy(flipped[1], fl.tri[0][2], sizeof flipped[1]);
    memcpy(flipped[2], fl.tri[0][1], sizeof flipped[2]);
    lj = tri_json((const double (*)[3])flipped, 1, 0);
    floor_case("two-sided triangle light, back down", &c, lj, &fl, CHAR_DIFFUSE,
               1, 64, 2e-3, 0);
    free(lj);
    {
        lj = tri_json((const double (*)[3])flipped, 1, 1);
        tcam cc = c;
        char *cj = cam_json(&cc);
        char *fj = floor_json(CHAR_DIFFUSE);
        char *text = fmt_alloc("{\"scene\": [%s, %s], %s}", fj, lj, cj);
        zt_scene *s = scene_from(text);
        zt_image *img = render(s, -1, 4, 16, 11);
        expect_black("culled triangle light facing away", img, NULL, 0);
        zt_image_release(img);
        zt_scene_release(s);
        free(text);
        free(fj);
        free(cj);
        free(lj);
    }

    /* the Cornell box arrangement: the light lies in the plane of a
     * background ceiling, which must neither hide it from the floor nor
     * shadow it (the light is foreground) */
    memset(&fl, 0, sizeof fl);
    fl.triangles = 1;
    down_triangle(1, 0.1, -0.1, 1, fl.tri[0]);
    fl.tri_le[0] = 1;
    {
        char *t = tri_json((const double (*)[3])fl.tri[0], 1, 1);
        lj = fmt_alloc("%s, {\"plane\": {\"normal\": [0, -1, 0], \"offset\": -1, "
                       "\"background\": true, \"backculled\": true, \"material\": "
                       DIFFUSE(0.5, 0.5, 0.5) "}}", t);
        free(t);
    }
    floor_case("light in a background ceiling", &c, lj, &fl, CHAR_DIFFUSE, 1, 64,
               2e-3, 0);
    free(lj);

    /* half diffuse, half mirror under the large light: every mirror ray
     * meets the light, so level 1 = 0.5 rho/pi E + 0.5 rho Le */
    {
        memset(&fl, 0, sizeof fl);
        fl.triangles = 1;
        down_triangle(10, 0.1, -0.1, 1, fl.tri[0]);
        fl.tri_le[0] = 0.5;
        lj = tri_json((const double (*)[3])fl.tri[0], 0.5, 1);
        int px = c.w * c.h;
        char *cj = cam_json(&c);
        char *fj = floor_json("{\"diffuse\": 0.5, \"metallic\": 0, \"reflecting\": 0.5, \"refractive\": 0}");
        char *text = fmt_alloc("{\"scene\": [%s, %s], %s}", fj, lj, cj);
        zt_scene *s = scene_from(text);
        double *e = calloc((size_t)px * 3, sizeof(double));
        double col[3] = {0.5 * floor_albedo[0], 0.5 * floor_albedo[1], 0.5 * floor_albedo[2]};
        floor_expectation(&c, FOOT_GRID, floor_radiance, &fl, col, e);
        for (int i = 0; i < px; i++)
            for (int k = 0; k < 3; k++)
                e[i * 3 + k] += 0.5 * floor_albedo[k] * 0.5;
        zt_image *img = render(s, 1, 1, 128, 11);
        for (int k = 0; k < 3; k++)
            expect_mean("half diffuse, half mirror floor", k, residuals(img, e, k, NULL),
                        2e-5, 2e-3);
        zt_image_release(img);
        free(e);
        zt_scene_release(s);
        free(text);
        free(fj);
        free(cj);
        free(lj);
    }
}

/* A point light of intensity I at height h: level 1 = rho/pi I cos/d^2,
 * exactly in every sample (the only randomness is the position inside the
 * pixel), so each pixel must match its footprint average closely.  With
 * two point lights, next-event estimation picks one per sample (by
 * power), which makes the estimate noisy but still exact on average. */
static void test_point_light_on_floor(void **state)
{
    (void)state;
    tcam c = floor_cam(1.6, 0.8, 0.4, 16);
    floor_lights fl;
    memset(&fl, 0, sizeof fl);
    fl.points = 1;
    fl.pt[0][0] = 0.2, fl.pt[0][1] = 0.7, fl.pt[0][2] = -0.1;
    fl.pt_i[0] = 3;
    char *lj = fmt_alloc(
        "{\"lightpoint\": {\"point\": [0.2, 0.7, -0.1], \"emission\": [3, 3, 3]}}");
    /* 256 scrambled Sobol points per pixel integrate the smooth footprint
     * average to ~2.5e-5 (worst pixel, measured); 1e-4 leaves room and
     * still catches any error in cos, d^2 or the intensity. */
    floor_case("point light, level 1 per pixel", &c, lj, &fl, CHAR_DIFFUSE,
               1, 256, 0, 1);
    free(lj);

    fl.points = 2;
    fl.pt[1][0] = -0.9, fl.pt[1][1] = 2.0, fl.pt[1][2] = 0.4;
    fl.pt_i[1] = 8;
    lj = fmt_alloc(
        "{\"lightpoint\": {\"point\": [0.2, 0.7, -0.1], \"emission\": [3, 3, 3]}}, "
        "{\"lightpoint\": {\"point\": [-0.9, 2.0, 0.4], \"emission\": [8, 8, 8]}}");
    floor_case("two point lights (light choice)", &c, lj, &fl, CHAR_DIFFUSE,
               1, 1024, 3e-3, 0);
    free(lj);
}

/* Sphere lights wholly above the floor act as points of intensity
 * pi r^2 L: a large one (a wide cone), a medium one and a tiny one (the
 * small-cone branch of the sampler). */
static void test_sphere_light_on_floor(void **state)
{
    (void)state;
    struct { const char *what; double cy, r, le, vy, sy, half; int spp; } cases[] = {
        {"large sphere light (r=1.2, h=1.5)", 1.5, 1.2, 1, 0.5, 0.25, 0.1, 64},
        {"medium sphere light (r=0.3, h=1)", 1, 0.3, 4, 1.6, 0.6, 0.4, 64},
        {"tiny sphere light (r=0.01, h=1)", 1, 0.01, 3000, 1.6, 0.8, 0.4, 16},
    };
    for (int i = 0; i < 3; i++) {
        tcam c = floor_cam(cases[i].vy, cases[i].sy, cases[i].half, 16);
        floor_lights fl;
        memset(&fl, 0, sizeof fl);
        fl.spheres = 1;
        fl.sph_c[0][0] = 0.15, fl.sph_c[0][1] = cases[i].cy, fl.sph_c[0][2] = -0.05;
        fl.sph_r[0] = cases[i].r;
        fl.sph_le[0] = cases[i].le;
        char *lj = fmt_alloc("{\"lightsphere\": {\"center\": [0.15, %.17g, -0.05], "
                             "\"radius\": %.17g, \"emission\": [%.17g, %.17g, %.17g]}}",
                             cases[i].cy, cases[i].r, cases[i].le, cases[i].le,
                             cases[i].le);
        floor_case(cases[i].what, &c, lj, &fl, CHAR_DIFFUSE, 1, cases[i].spp, 2e-3, 0);
        free(lj);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        TIMED_TEST(test_polygon_formula),
        TIMED_TEST(test_convex_sphere_under_sky),
        TIMED_TEST(test_integrating_sphere_point_light),
        TIMED_TEST(test_integrating_sphere_sphere_light),
        TIMED_TEST(test_inside_light_sphere),
        TIMED_TEST(test_triangle_light_on_floor),
        TIMED_TEST(test_point_light_on_floor),
        TIMED_TEST(test_sphere_light_on_floor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
