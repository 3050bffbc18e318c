/* Helpers shared by the path tracer's tests (test_path_*.c): building
 * scenes from JSON text, a double-precision camera, rendering, and the
 * statistics the tolerances are made of (mean relative residuals against
 * a closed form, in standard errors).  Header-only: every function is
 * static, and each test uses the ones it needs. */
#ifndef ZT_TEST_PATH_CHECK_H
#define ZT_TEST_PATH_CHECK_H

#include "test_support.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"


#define Z_MEAN 4.5
#define PI 3.14159265358979323846
/* Float rounding of a float32 renderer on values that are exact in
 * every sample (measured below 3e-7), with a wide margin. */
#define FLOAT_FLOOR 2e-5
#define TEST_HELPER static __attribute__((unused))

#define DIFFUSE(r, g, b) "{\"character\": {\"diffuse\": 1, \"metallic\": 0, " \
    "\"reflecting\": 0, \"refractive\": 0}, \"color\": [" #r ", " #g ", " #b "]}"

TEST_HELPER char *fmt_alloc(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *s = malloc((size_t)n + 1);
    assert_non_null(s);
    va_start(ap, fmt);
    vsnprintf(s, (size_t)n + 1, fmt, ap);
    va_end(ap);
    return s;
}

TEST_HELPER zt_scene *scene_from(const char *text)
{
    zt_scene *s = NULL;
    zt_error err = {0};
    if (zt_scene_load_string(text, strlen(text), "test.json", &s, &err) != ZT_OK)
        fail_msg("scene does not load: %s\n%s", err.message, text);
    return s;
}

TEST_HELPER zt_image *render(const zt_scene *s, int level, int depth, int spp,
                        uint64_t seed)
{
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_PATH;
    o.level = level;
    o.depth = depth;
    o.spp = spp;
    o.seed = seed;
    o.threads = 2;
    zt_image *img = NULL;
    zt_error err = {0};
    if (zt_render(s, &o, &img, NULL, &err) != ZT_OK)
        fail_msg("render failed: %s", err.message);
    return img;
}

TEST_HELPER void v_sub(const double a[3], const double b[3], double o[3])
{
    for (int i = 0; i < 3; i++)
        o[i] = a[i] - b[i];
}
TEST_HELPER double v_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
TEST_HELPER void v_cross(const double a[3], const double b[3], double o[3])
{
    double r[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    memcpy(o, r, sizeof r);
}
TEST_HELPER double v_len(const double a[3]) { return sqrt(v_dot(a, a)); }
TEST_HELPER void v_norm(double a[3])
{
    double l = v_len(a);
    for (int i = 0; i < 3; i++)
        a[i] /= l;
}

/* A pinhole camera as the scene format defines it, in double precision. */
typedef struct tcam {
    double vp[3], tl[3], tr[3], bl[3], br[3];
    int w, h;
} tcam;

/* Looking from vp along look; the screen (a square of half size half at
 * distance dist) is perpendicular to look. */
TEST_HELPER tcam cam_look(const double vp[3], const double look_in[3],
                     const double up_in[3], double dist, double half, int w,
                     int h)
{
    tcam c;
    double look[3] = {look_in[0], look_in[1], look_in[2]}, right[3], up[3];
    v_norm(look);
    v_cross(look, up_in, right);
    v_norm(right);
    v_cross(right, look, up);
    for (int i = 0; i < 3; i++) {
        double ctr = vp[i] + dist * look[i];
        c.vp[i] = vp[i];
        c.tl[i] = ctr - half * right[i] + half * up[i];
        c.tr[i] = ctr + half * right[i] + half * up[i];
        c.bl[i] = ctr - half * right[i] - half * up[i];
        c.br[i] = ctr + half * right[i] - half * up[i];
    }
    c.w = w;
    c.h = h;
    return c;
}

TEST_HELPER char *cam_json(const tcam *c)
{
    return fmt_alloc("\"camera\": {\"viewpoint\": [%.17g, %.17g, %.17g], "
                     "\"screen\": [[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g], "
                     "[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g]], "
                     "\"gridresolution\": [%d, %d]}",
                     c->vp[0], c->vp[1], c->vp[2], c->tl[0], c->tl[1], c->tl[2],
                     c->tr[0], c->tr[1], c->tr[2], c->bl[0], c->bl[1], c->bl[2],
                     c->br[0], c->br[1], c->br[2], c->w, c->h);
}

/* The camera ray through image position (px, py) in pixels. */
TEST_HELPER void cam_ray(const tcam *c, double px, double py, double o[3], double d[3])
{
    for (int i = 0; i < 3; i++)
        o[i] = c->tl[i] + (c->tr[i] - c->tl[i]) * px / c->w +
               (c->bl[i] - c->tl[i]) * py / c->h;
    v_sub(o, c->vp, d);
    v_norm(d);
}

/* Relative residuals pixel/expected - 1 of one channel over the pixels
 * where mask is set (NULL: all) and expected > 0. */
typedef struct resid {
    double mean, sd, se, worst;
    int n;
} resid;

TEST_HELPER resid residuals(const zt_image *img, const double *expect, int ch,
                       const unsigned char *mask)
{
    resid r = {0, 0, 0, 0, 0};
    double s = 0, s2 = 0;
    for (int i = 0; i < img->width * img->height; i++) {
        if ((mask && !mask[i]) || !(expect[i * 3 + ch] > 0))
            continue;
        double e = (double)img->pixels[i * 3 + ch] / expect[i * 3 + ch] - 1.0;
        s += e;
        s2 += e * e;
        if (fabs(e) > r.worst)
            r.worst = fabs(e);
        r.n++;
    }
    assert_true(r.n >= 2);
    r.mean = s / r.n;
    r.sd = sqrt(fmax(0.0, (s2 - s * s / r.n) / (r.n - 1)));
    r.se = r.sd / sqrt((double)r.n);
    return r;
}

/* The mean relative residual must be within Z_MEAN standard errors plus
 * floor, and the standard error at most max_se (the test's power). */
TEST_HELPER void expect_mean(const char *what, int ch, resid r, double floor,
                        double max_se)
{
    double tol = Z_MEAN * r.se + floor;
    printf("  %-44s ch%d: rel.err %+.2e  se %.1e  tol %.1e  (n=%d, worst px %.1e)\n",
           what, ch, r.mean, r.se, tol, r.n, r.worst);
    if (!(fabs(r.mean) <= tol))
        fail_msg("%s, channel %d: mean relative error %.3e exceeds %.3e "
                 "(%.1f standard errors)", what, ch, r.mean, tol,
                 r.se > 0 ? r.mean / r.se : INFINITY);
    if (!(r.se <= max_se))
        fail_msg("%s, channel %d: standard error %.3e above %.3e: the test "
                 "has lost its power", what, ch, r.se, max_se);
}

/* Every pixel within tol (relative) of its expectation: for estimates
 * that are exact up to float rounding or footprint integration. */
TEST_HELPER void expect_each(const char *what, int ch, resid r, double tol)
{
    printf("  %-44s ch%d: worst pixel rel.err %.2e (tol %.1e, n=%d)\n", what,
           ch, r.worst, tol, r.n);
    if (!(r.worst <= tol))
        fail_msg("%s, channel %d: a pixel is off by %.3e (relative), "
                 "more than %.3e", what, ch, r.worst, tol);
}

/* All channels of the masked pixels below tol in absolute value. */
TEST_HELPER void expect_black(const char *what, const zt_image *img,
                         const unsigned char *mask, double tol)
{
    double worst = 0;
    for (int i = 0; i < img->width * img->height; i++)
        if (!mask || mask[i])
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs((double)img->pixels[i * 3 + c]));
    printf("  %-44s     : largest value %.2e (tol %.1e)\n", what, worst, tol);
    if (!(worst <= tol))
        fail_msg("%s: expected black, found %.3e", what, worst);
}

/* Wall time of each test, printed after it (cmocka setup/teardown). */
static struct timespec test_started;
TEST_HELPER int timer_start(void **state)
{
    (void)state;
    timespec_get(&test_started, TIME_UTC);
    return 0;
}
TEST_HELPER int timer_stop(void **state)
{
    (void)state;
    struct timespec now;
    timespec_get(&now, TIME_UTC);
    printf("  (%.2f s)\n", (double)(now.tv_sec - test_started.tv_sec) +
                              1e-9 * (double)(now.tv_nsec - test_started.tv_nsec));
    return 0;
}
#define TIMED_TEST(f) cmocka_unit_test_setup_teardown(f, timer_start, timer_stop)

/* Sets every pixel's expectation to v. */
TEST_HELPER void fill(double *e, int pixels, const double v[3])
{
    for (int i = 0; i < pixels; i++)
        memcpy(e + i * 3, v, 3 * sizeof(double));
}


#endif
