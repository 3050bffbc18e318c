/* Rules of the path tracer that need no closed form: levels add up to
 * the depth image, seeds and thread counts (same seed, same bytes; other
 * seeds, independent noise), and visibility (back-face culling, the
 * background layer, for camera and shadow rays, with both acceleration
 * structures).  Tolerances as in test_path_analytic.c. */
#define _POSIX_C_SOURCE 200809L /* setenv, strdup */
#include "test_support.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "geom/accel.h"
#include "path/path_tracer.h"
#include "render/render_scene.h"
#include "util/sampler.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#include "path_check.h"

/* ---------------------------------------------------------------------
 * Image statistics without a closed form.
 * --------------------------------------------------------------------- */

static double image_mean(const zt_image *img, int ch)
{
    double s = 0;
    for (int i = 0; i < img->width * img->height; i++)
        s += img->pixels[i * 3 + ch];
    return s / (img->width * img->height);
}

/* Root mean square of a - b over the pixels of one channel. */
static double rms_diff(const zt_image *a, const zt_image *b, int ch)
{
    double s = 0;
    for (int i = 0; i < a->width * a->height; i++) {
        double d = (double)a->pixels[i * 3 + ch] - b->pixels[i * 3 + ch];
        s += d * d;
    }
    return sqrt(s / (a->width * a->height));
}

static zt_scene *cornell(int size)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/cornell.json", ZT_SOURCE_DIR);
    zt_scene *s = NULL;
    zt_error err = {0};
    if (zt_scene_load_file(path, &s, &err) != ZT_OK)
        fail_msg("%s", err.message);
    zt_camera cam = zt_scene_get_camera(s);
    if (zt_camera_set_resolution(&cam, size, size, &err) != ZT_OK)
        fail_msg("%s", err.message);
    zt_scene_set_camera(s, &cam);
    return s;
}

static zt_image *render_threads(const zt_scene *s, int level, int depth,
                                int spp, uint64_t seed, int threads)
{
    zt_render_options o = zt_render_options_default();
    o.level = level;
    o.depth = depth;
    o.spp = spp;
    o.seed = seed;
    o.threads = threads;
    zt_image *img = NULL;
    zt_error err = {0};
    if (zt_render(s, &o, &img, NULL, &err) != ZT_OK)
        fail_msg("render failed: %s", err.message);
    return img;
}

/* ---------------------------------------------------------------------
 * 5. Levels add up to the depth image.
 * --------------------------------------------------------------------- */

/* The Cornell box at 16x16: levels 0..3 rendered one by one add up to the
 * depth-3 image.  The noise of a difference of two estimates is measured
 * by two depth-3 images of different seeds (independent, so their
 * difference has variance 2 sigma^2 per pixel): the means of sum and
 * depth image must agree within Z_MEAN of its standard error, and their
 * per-pixel rms difference must not exceed that of two independent
 * images (it is smaller when the level images share the depth image's
 * samples, as they do now). */
static void test_levels_sum_to_depth(void **state)
{
    (void)state;
    const int n = 16, px = n * n, spp = 256, depth = 3;
    zt_scene *s = cornell(n);
    zt_image *sum = zt_image_create(n, n);
    for (int level = 0; level <= depth; level++) {
        zt_image *l = render(s, level, depth, spp, 21);
        for (int i = 0; i < px * 3; i++)
            sum->pixels[i] += l->pixels[i];
        /* a level image of its own depth is the same image */
        zt_image *l2 = render(s, level, level, spp, 21);
        assert_memory_equal(l->pixels, l2->pixels, (size_t)px * 3 * sizeof(float));
        zt_image_release(l2);
        zt_image_release(l);
    }
    zt_image *d = render(s, -1, depth, spp, 21);
    zt_image *d2 = render(s, -1, depth, spp, 22);
    for (int k = 0; k < 3; k++) {
        double noise = rms_diff(d, d2, k); /* sqrt(2) sigma, pooled */
        double se = noise / sqrt((double)px);
        double diff = image_mean(sum, k) - image_mean(d, k);
        double rms = rms_diff(sum, d, k);
        printf("  ch%d: mean(levels) %.6g  mean(depth) %.6g  diff %+.2e  (se %.1e)  "
               "rms diff %.2e vs %.2e between seeds\n",
               k, image_mean(sum, k), image_mean(d, k), diff, se, rms, noise);
        if (!(fabs(diff) <= Z_MEAN * se))
            fail_msg("channel %d: levels 0..%d add up to %.6g, depth %d gives %.6g "
                     "(%.1f standard errors)", k, depth, image_mean(sum, k), depth,
                     image_mean(d, k), diff / se);
        if (!(rms <= 1.25 * noise))
            fail_msg("channel %d: per-pixel rms difference %.3e between the sum of "
                     "levels and the depth image exceeds the noise %.3e", k, rms, noise);
        /* the test has power: the noise is a small part of the image */
        assert_true(se < 0.01 * image_mean(d, k));
    }
    zt_image_release(sum);
    zt_image_release(d);
    zt_image_release(d2);
    zt_scene_release(s);
}

/* ---------------------------------------------------------------------
 * 6. Seeds and threads.
 * --------------------------------------------------------------------- */

/* The same seed gives the same bytes, at any thread count; other seeds
 * give other bytes with means that agree within the noise, and noise that
 * is uncorrelated from seed to seed (on a scene of uniform expectation:
 * level 2 of an integrating sphere lit by a sphere light). */
static void test_seeds_and_threads(void **state)
{
    (void)state;
    const int n = 16, px = n * n;
    zt_scene *s = cornell(n);
    zt_image *a = render_threads(s, -1, 4, 16, 5, 2);
    zt_image *b = render_threads(s, -1, 4, 16, 5, 2);
    zt_image *one = render_threads(s, -1, 4, 16, 5, 1);
    zt_image *three = render_threads(s, -1, 4, 16, 5, 3);
    assert_memory_equal(a->pixels, b->pixels, (size_t)px * 3 * sizeof(float));
    assert_memory_equal(a->pixels, one->pixels, (size_t)px * 3 * sizeof(float));
    assert_memory_equal(a->pixels, three->pixels, (size_t)px * 3 * sizeof(float));
    zt_image_release(b);
    zt_image_release(one);
    zt_image_release(three);

    /* six seeds: every pair differs in bytes and agrees in the mean */
    const uint64_t seeds[6] = {5, 6, 7, 1000, 0xdeadbeefULL, 123456789012345ULL};
    zt_image *img[6];
    img[0] = a;
    for (int i = 1; i < 6; i++)
        img[i] = render_threads(s, -1, 4, 16, seeds[i], 2);
    for (int i = 0; i < 6; i++)
        for (int j = i + 1; j < 6; j++) {
            assert_true(memcmp(img[i]->pixels, img[j]->pixels,
                               (size_t)px * 3 * sizeof(float)) != 0);
            for (int k = 0; k < 3; k++) {
                /* se of a difference of two means: rms of the pixel
                 * differences / sqrt(pixels) */
                double se = rms_diff(img[i], img[j], k) / sqrt((double)px);
                double diff = image_mean(img[i], k) - image_mean(img[j], k);
                if (!(fabs(diff) <= Z_MEAN * se))
                    fail_msg("seeds %llu and %llu, channel %d: means differ by %.3e, "
                             "%.1f standard errors", (unsigned long long)seeds[i],
                             (unsigned long long)seeds[j], k, diff, diff / se);
            }
        }
    printf("  6 seeds: pairwise distinct, means agree within %.1f se\n", Z_MEAN);
    for (int i = 0; i < 6; i++)
        zt_image_release(img[i]);
    zt_scene_release(s);

    /* uncorrelated noise between seeds */
    const int m = 64, mpx = m * m;
    double vp[3] = {0, 0.05, 0.55}, look[3] = {0.1, 0, 1}, up[3] = {0, 1, 0};
    tcam c = cam_look(vp, look, up, 0.05, 0.03, m, m);
    char *cj = cam_json(&c);
    char *text = fmt_alloc(
        "{\"scene\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, "
        "\"material\": " DIFFUSE(0.5, 0.5, 0.5) "}}, "
        "{\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": 0.5, "
        "\"emission\": [1, 1, 1]}}], %s}", cj);
    zt_scene *f = scene_from(text);
    zt_image *p = render(f, 2, 2, 2, 1), *q = render(f, 2, 2, 2, 2);
    double mp = image_mean(p, 0), mq = image_mean(q, 0), sxy = 0, sxx = 0, syy = 0;
    for (int i = 0; i < mpx; i++) {
        double x = p->pixels[i * 3] - mp, y = q->pixels[i * 3] - mq;
        sxy += x * y;
        sxx += x * x;
        syy += y * y;
    }
    double r = sxy / sqrt(sxx * syy);
    printf("  pixel noise correlation between seeds 1 and 2: %+.3f (limit %.3f)\n",
           r, Z_MEAN / sqrt((double)mpx));
    assert_true(sxx > 0 && syy > 0);
    assert_true(fabs(r) <= Z_MEAN / sqrt((double)mpx));
    zt_image_release(p);
    zt_image_release(q);
    zt_scene_release(f);
    free(text);
    free(cj);
}

/* ---------------------------------------------------------------------
 * 8. Visibility rules: culling and the background layer.
 * --------------------------------------------------------------------- */

/* Renders an 8x8 image of a scene (camera at z = -10 looking along +z
 * over x, y in [-5, 5] at z = 0) and checks that every pixel equals v
 * (relative FLOAT_FLOOR, or exactly 0). */
static void expect_uniform(const char *what, const char *items, int level,
                           int depth, const double v[3])
{
    double vp[3] = {0.3, -0.2, -10}, look[3] = {0, 0, 1}, up[3] = {0, 1, 0};
    tcam c = cam_look(vp, look, up, 1, 0.5, 8, 8);
    char *cj = cam_json(&c);
    char *text = fmt_alloc("{\"scene\": [%s], %s}", items, cj);
    zt_scene *s = scene_from(text);
    zt_image *img = render(s, level, depth, 4, 3);
    double worst = 0;
    for (int i = 0; i < 64; i++)
        for (int k = 0; k < 3; k++) {
            double p = img->pixels[i * 3 + k];
            worst = fmax(worst, v[k] > 0 ? fabs(p / v[k] - 1) : fabs(p));
        }
    printf("  %-58s: worst %.1e\n", what, worst);
    if (!(worst <= FLOAT_FLOOR))
        fail_msg("%s: a pixel differs from (%g, %g, %g) by %.3e", what, v[0], v[1],
                 v[2], worst);
    zt_image_release(img);
    zt_scene_release(s);
    free(text);
    free(cj);
}

/* A triangle covering the view in the plane z = z0, its front facing the
 * camera (-z) or away from it (+z). */
static char *big_triangle(const char *kind, double z0, int facing_camera,
                          const char *settings)
{
    return facing_camera
        ? fmt_alloc("{\"%s\": {\"points\": [[-100, -100, %g], [0, 100, %g], [100, -100, %g]], %s}}",
                    kind, z0, z0, z0, settings)
        : fmt_alloc("{\"%s\": {\"points\": [[-100, -100, %g], [100, -100, %g], [0, 100, %g]], %s}}",
                    kind, z0, z0, z0, settings);
}

#define SKY "{\"sky\": {\"color\": [0.5, 0.25, 0.125]}}"

static void visibility_rules(void)
{
    const double sky[3] = {0.5, 0.25, 0.125}, le[3] = {1, 2, 3};
    const double black[3] = {0, 0, 0}, red[3] = {4, 0, 0}, green[3] = {0, 5, 0};
    const double lit_back[3] = {0.5 * 0.5, 0.5 * 0.25, 0.5 * 0.125};
    char *t, *u, *items;

    /* culled lights are seen only from the front */
    t = big_triangle("lighttriangle", 0, 1, "\"emission\": [1, 2, 3], \"backculled\": true");
    items = fmt_alloc("%s, " SKY, t);
    expect_uniform("culled light triangle, front: Le", items, 0, 0, le);
    expect_uniform("culled light triangle, front, depth 3: Le", items, -1, 3, le);
    free(items); free(t);
    t = big_triangle("lighttriangle", 0, 0, "\"emission\": [1, 2, 3], \"backculled\": true");
    items = fmt_alloc("%s, " SKY, t);
    expect_uniform("culled light triangle from behind: the sky", items, 0, 0, sky);
    expect_uniform("culled light triangle from behind, depth 3: sky", items, -1, 3, sky);
    free(items); free(t);
    t = big_triangle("lighttriangle", 0, 0, "\"emission\": [1, 2, 3], \"backculled\": false");
    items = fmt_alloc("%s, " SKY, t);
    expect_uniform("two-sided light triangle from behind: Le", items, 0, 0, le);
    free(items); free(t);

    /* culled things are invisible from behind, also to their own light */
    t = big_triangle("triangle", 0, 0, "\"backculled\": true, \"material\": " DIFFUSE(0.5, 0.5, 0.5));
    items = fmt_alloc("%s, " SKY, t);
    expect_uniform("culled triangle from behind, level 0: sky", items, 0, 0, sky);
    expect_uniform("culled triangle from behind, level 1: nothing", items, 1, 1, black);
    free(items); free(t);
    t = big_triangle("triangle", 0, 0, "\"backculled\": false, \"material\": " DIFFUSE(0.5, 0.5, 0.5));
    items = fmt_alloc("%s, " SKY, t);
    expect_uniform("two-sided triangle from behind, level 0: black", items, 0, 0, black);
    expect_uniform("two-sided triangle from behind, level 1: a*sky", items, 1, 1, lit_back);
    free(items); free(t);

    /* spheres: a culled one is invisible from inside */
    items = fmt_alloc("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 50, \"backculled\": true, "
                      "\"material\": " DIFFUSE(0.5, 0.5, 0.5) "}}, " SKY);
    expect_uniform("inside a culled sphere: the sky", items, -1, 3, sky);
    free(items);
    items = fmt_alloc("{\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": 50, \"backculled\": true, "
                      "\"emission\": [1, 2, 3]}}, " SKY);
    expect_uniform("inside a culled light sphere: the sky", items, -1, 3, sky);
    free(items);
    items = fmt_alloc("{\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": 50, \"backculled\": false, "
                      "\"emission\": [1, 2, 3]}}, " SKY);
    expect_uniform("inside a two-sided light sphere: Le", items, -1, 3, le);
    free(items);

    /* background objects lose to any foreground hit, however near */
    const char *flags[4][2] = {{"true", "false"}, {"false", "true"},
                               {"false", "false"}, {"true", "true"}};
    const char *names[4] = {"near background, far foreground: the far one",
                            "near foreground, far background: the near one",
                            "both foreground: the near one",
                            "both background: the near one"};
    for (int i = 0; i < 4; i++) {
        char a[96], b[96];
        snprintf(a, sizeof a, "\"emission\": [4, 0, 0], \"background\": %s", flags[i][0]);
        snprintf(b, sizeof b, "\"emission\": [0, 5, 0], \"background\": %s", flags[i][1]);
        t = big_triangle("lighttriangle", -2, 1, a); /* red, near */
        u = big_triangle("lighttriangle", 2, 1, b);  /* green, far */
        items = fmt_alloc("%s, %s, " SKY, t, u);
        expect_uniform(names[i], items, 0, 0, i == 0 ? green : red);
        free(items); free(t); free(u);
    }
    /* a background plane behind everything vs a foreground triangle */
    t = big_triangle("lighttriangle", 2, 1, "\"emission\": [0, 5, 0]");
    items = fmt_alloc("{\"lightplane\": {\"normal\": [0, 0, -1], \"offset\": 1, "
                      "\"emission\": [4, 0, 0], \"background\": true}}, %s, " SKY, t);
    expect_uniform("near background light plane, far triangle", items, 0, 0, green);
    free(items); free(t);
}

static void test_visibility_rules(void **state)
{
    (void)state;
    const char *old = getenv("ZT_ACCEL");
    char *saved = old ? strdup(old) : NULL;
    printf(" embree:\n");
    unsetenv("ZT_ACCEL");
    visibility_rules();
    printf(" brute force:\n");
    setenv("ZT_ACCEL", "brute", 1);
    visibility_rules();
    if (saved) {
        setenv("ZT_ACCEL", saved, 1);
        free(saved);
    } else {
        unsetenv("ZT_ACCEL");
    }
}

/* Shadows follow the same rule: a background object between a point and
 * a foreground light does not shadow it (the ray's hit would be the
 * light), a foreground one does.  A floor under a point light with a
 * large culled triangle between them, its front towards the floor (camera
 * rays from above pass through its back): as background the image is
 * the same as without it; as foreground it is black. */
static void test_background_does_not_shadow(void **state)
{
    (void)state;
    const int n = 8;
    double vp[3] = {0.1, 2, 0.05}, look[3] = {0, -1, 0}, up[3] = {0, 0, -1};
    tcam c = cam_look(vp, look, up, 1.1, 0.4, n, n); /* screen at y = 0.9 */
    char *cj = cam_json(&c);
    const char *floor_light =
        "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, \"material\": "
        DIFFUSE(0.8, 0.5, 0.3) "}}, "
        "{\"lightpoint\": {\"point\": [0.2, 0.7, -0.1], \"emission\": [3, 3, 3]}}";
    const char *tri = "{\"triangle\": {\"points\": [[-100, 0.3, -100], [100, 0.3, -100], "
                      "[0, 0.3, 100]], \"backculled\": true, \"background\": %s, "
                      "\"material\": " DIFFUSE(0.5, 0.5, 0.5) "}}";
    for (int accel = 0; accel < 2; accel++) {
        if (accel)
            setenv("ZT_ACCEL", "brute", 1);
        char *t_bg = fmt_alloc(tri, "true"), *t_fg = fmt_alloc(tri, "false");
        char *s0 = fmt_alloc("{\"scene\": [%s], %s}", floor_light, cj);
        char *s1 = fmt_alloc("{\"scene\": [%s, %s], %s}", floor_light, t_bg, cj);
        char *s2 = fmt_alloc("{\"scene\": [%s, %s], %s}", floor_light, t_fg, cj);
        zt_scene *a = scene_from(s0), *b = scene_from(s1), *f = scene_from(s2);
        zt_image *ia = render(a, 1, 1, 16, 4), *ib = render(b, 1, 1, 16, 4);
        zt_image *ifg = render(f, 1, 1, 16, 4);
        printf("  %s: floor pixel (4,4) = %.5f; with a background occluder the "
               "image is %s\n", accel ? "brute" : "embree", ia->pixels[(4 * n + 4) * 3],
               memcmp(ia->pixels, ib->pixels, (size_t)n * n * 3 * sizeof(float)) ? "different"
                                                                                   : "identical");
        assert_true(image_mean(ia, 0) > 0.1);
        assert_memory_equal(ia->pixels, ib->pixels, (size_t)n * n * 3 * sizeof(float));
        expect_black("foreground occluder: shadow", ifg, NULL, 0);
        zt_image_release(ia);
        zt_image_release(ib);
        zt_image_release(ifg);
        zt_scene_release(a);
        zt_scene_release(b);
        zt_scene_release(f);
        free(s0); free(s1); free(s2); free(t_bg); free(t_fg);
    }
    unsetenv("ZT_ACCEL");
    free(cj);
}

/* A plain scene (rscene.plain: smooth lobes only, nothing textured, no
 * panes, alpha or light from far away) is traced by a copy of the loop
 * compiled without those branches.  Both copies must give the same bytes
 * on it: the copy is a speed-up, never another estimator.  And the flag
 * must see what makes a scene not plain. */
static void test_plain_copy_same_bytes(void **state)
{
    (void)state;
    const char *plain[] = {"cornell.json", "materials.json", "pointlights.json"};
    for (int f = 0; f < 3; f++) {
        char path[512];
        snprintf(path, sizeof path, "%s/scenes/%s", ZT_SOURCE_DIR, plain[f]);
        zt_scene *s = NULL;
        zt_error err = {0};
        if (zt_scene_load_file(path, &s, &err) != ZT_OK)
            fail_msg("%s: %s", path, err.message);
        rscene rs;
        assert_int_equal(rscene_build(&rs, s, NULL, 0, ACCEL_BVH, &err), ZT_OK);
        if (!rs.plain)
            fail_msg("%s is not taken as plain", plain[f]);
        const zt_camera cam = zt_scene_get_camera(s), *sc = &cam;
        tcam c;
        for (int a = 0; a < 3; a++) {
            c.vp[a] = sc->viewpoint[a];
            c.tl[a] = sc->screen[0][a];
            c.tr[a] = sc->screen[1][a];
            c.bl[a] = sc->screen[2][a];
            c.br[a] = sc->screen[3][a];
        }
        c.w = c.h = 16;
        const int n = 16, spp = 8, count = n * n * spp;
        vec3f *l[2];
        uint64_t rays[2] = {0, 0};
        path_params pp = {0, 6, 1};
        for (int copy = 0; copy < 2; copy++) {
            rs.plain = copy == 0;
            l[copy] = malloc((size_t)count * sizeof(vec3f));
            for (int i = 0; i < n * n; i++) {
                path_pixel px = path_pixel_make(sampler_hash3((uint32_t)i, 7u, 1u));
                for (uint32_t k = 0; k < (uint32_t)spp; k++) {
                    double o[3], d[3];
                    cam_ray(&c, i % n + (k + 0.5) / spp, i / n + 0.5, o, d);
                    l[copy][i * spp + (int)k] = path_trace_sample(
                        &rs, &pp, f3((float)o[0], (float)o[1], (float)o[2]),
                        f3((float)d[0], (float)d[1], (float)d[2]), &px, k,
                        sampler_reverse_bits(k), &rays[copy]);
                }
            }
        }
        assert_memory_equal(l[0], l[1], (size_t)count * sizeof(vec3f));
        assert_true(rays[0] == rays[1] && rays[0] > (uint64_t)count);
        free(l[0]);
        free(l[1]);
        rscene_free(&rs);
        zt_scene_release(s);
    }
    const char *not_plain[] = {"cornell_rough.json", "sun_and_sky.json", "textured_box.json",
                               "house_inside.json"};
    for (int f = 0; f < 4; f++) {
        char path[512];
        snprintf(path, sizeof path, "%s/scenes/%s", ZT_SOURCE_DIR, not_plain[f]);
        zt_scene *s = NULL;
        zt_error err = {0};
        if (zt_scene_load_file(path, &s, &err) != ZT_OK) {
            printf("  %s not loaded (%s): skipped\n", not_plain[f], err.message);
            continue;
        }
        rscene rs;
        assert_int_equal(rscene_build(&rs, s, NULL, 0, ACCEL_BVH, &err), ZT_OK);
        if (rs.plain)
            fail_msg("%s is taken as plain", not_plain[f]);
        rscene_free(&rs);
        zt_scene_release(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        TIMED_TEST(test_levels_sum_to_depth),
        TIMED_TEST(test_seeds_and_threads),
        TIMED_TEST(test_visibility_rules),
        TIMED_TEST(test_background_does_not_shadow),
        TIMED_TEST(test_plain_copy_same_bytes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
