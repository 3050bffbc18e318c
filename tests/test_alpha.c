/* Model files' alpha coverage (glTF's alphaMode MASK and BLEND), in both
 * renderers and every acceleration backend, against values written out
 * here from the models that tests/data/make_alpha_models.sh writes:
 *
 * - a white square 1 above a grey floor (albedo 0.5), its texture's alpha
 *   alternating 255 / 0 in 8 stripes (MASK), under a sun straight above of
 *   irradiance 100: at level 1 the floor under a hole stripe reads
 *   0.5 x 100 / pi, under a covered one 0 (the sun is blocked), and the
 *   camera above sees the floor through the holes and the square (100 /
 *   pi) on the covered stripes;
 * - the same square with a base colour alpha of 0.25 (BLEND): the floor
 *   under it gets 0.75 of the sun, and the camera above sees a quarter of
 *   the square and three quarters of the floor;
 * - every backend finds the same first hits through the stripes (the
 *   holes are no hits) and the same visibility;
 * - the zone tracer's terms, whose camera samples are split at partial
 *   coverage, add up to one zone_radiance per sample (which mixes the
 *   coverage itself further along), and both Phase Two strategies give the
 *   same bits;
 * - cutoffs outside [0, 1] are clamped, counted and named; a NaN (not
 *   JSON) makes the model unreadable, a parse error with the scene's
 *   file:line:column. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/transmittance.h"
#include "render/render_internal.h"
#include "render/render_scene.h"
#include "zone/phase_two/phase_two.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846
#define MODELS ZT_SOURCE_DIR "/tests/data/alpha/"
/* The sun's irradiance, the floor's albedo, the square's height. */
#define SUN 100.0
#define FLOOR 0.5
#define HEIGHT 1.0
/* The stripes: 8 columns of width 2/8 from x = -1, even ones covered. */
#define STRIPES 8

static const char *const method_name[] = {"path", "zone"};
static const zt_method methods[] = {ZT_METHOD_PATH, ZT_METHOD_ZONE};

static double stripe_centre(int i)
{
    return -1.0 + (i + 0.5) * 2.0 / STRIPES;
}

/* The scene: the sun straight above, the floor, and the model `file` as
 * a square of side 2 at height HEIGHT; the camera a narrow view (0.5
 * degrees) of point (x, y, z) from direction (0, wy, wz), 3 units away. */
static zt_scene *alpha_scene(const char *file, double x, double y, double z, double wy,
                             double wz)
{
    char text[2048];
    double len = sqrt(wy * wy + wz * wz);
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [%g, %g, %g], "
             "\"angle\": 0.53}}, {\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, "
             TEST_DIFFUSE_FMT "}}, {\"mesh\": {\"file\": \"%s\", \"transform\": {\"translate\": "
             "[0, %g, 0]}}}], \"camera\": {\"position\": [%.17g, %.17g, %.17g], \"lookat\": "
             "[%.17g, %.17g, %.17g], \"fov\": 0.5, \"gridresolution\": [8, 8]}}",
             SUN, SUN, SUN, FLOOR, FLOOR, FLOOR, file, HEIGHT, x, y + 3 * wy / len,
             z + 3 * wz / len, x, y, z);
    return test_scene_text(text, "alpha");
}

/* The mean of the scene's image at level 1 (light that scattered once). */
static double view_mean(zt_method method, const char *file, double x, double y, double z,
                        double wy, double wz, int spp)
{
    zt_scene *sc = alpha_scene(file, x, y, z, wy, wz);
    double mean = test_render_mean(sc, method, 1, 1, spp);
    zt_scene_release(sc);
    return mean;
}

/* The floor is seen from low on the side (under the square, 0.44 above
 * the floor at the eye), the square and what is behind it from above. */
#define SIDE 0.15, 1.0
#define ABOVE 1.0, 0.3

static void test_mask_stripes(void **state)
{
    (void)state;
    const char *file = MODELS "stripes.gltf";
    double lit = FLOOR * SUN / PI, top = SUN / PI;
    for (int mi = 0; mi < 2; mi++)
        for (int i = 0; i < STRIPES; i++) {
            double x = stripe_centre(i);
            int hole = i % 2;
            double floor = view_mean(methods[mi], file, x, 0, 0, SIDE, 16);
            double seen = view_mean(methods[mi], file, x, 0, 0, ABOVE, 16);
            print_message("%s: stripe %d (%s): floor %.6g, from above %.6g\n", method_name[mi], i,
                          hole ? "hole" : "covered", floor, seen);
            /* The sun through a hole is the open sun (its disc's edge lies
             * 0.005 from the stripe's centre line's 0.125), behind a
             * covered stripe nothing: 0.1% (float rounding, the path
             * tracer's sun is sampled but wholly visible). */
            if (hole) {
                assert_true(fabs(floor / lit - 1) < 1e-3);
                assert_true(fabs(seen / lit - 1) < 1e-3); /* the floor through the hole */
            } else {
                assert_true(floor < 1e-3 * lit);
                assert_true(fabs(seen / top - 1) < 1e-3); /* the square's top */
            }
        }
}

static void test_blend_quarter(void **state)
{
    (void)state;
    const char *file = MODELS "quarter.gltf";
    double lit = FLOOR * SUN / PI, top = SUN / PI, c = 0.25;
    for (int mi = 0; mi < 2; mi++) {
        double floor = view_mean(methods[mi], file, 0.3, 0, -0.2, SIDE, 16);
        double seen = view_mean(methods[mi], file, 0.3, 0, -0.2, ABOVE, 256);
        double want_seen = c * top + (1 - c) * (1 - c) * lit;
        print_message("%s: under the quarter-covered square %.6g (%.6g), from above %.6g "
                      "(%.6g)\n",
                      method_name[mi], floor, (1 - c) * lit, seen, want_seen);
        /* Shadow rays weigh by 1 - c in both renderers: float rounding. */
        assert_true(fabs(floor / ((1 - c) * lit) - 1) < 1e-3);
        /* The zone tracer weighs the camera's samples by c and 1 - c; the
         * path tracer chooses with those probabilities: over 16,384 paths
         * its standard deviation is 0.4%, the bound 4 of them. */
        assert_true(fabs(seen / want_seen - 1) < (mi == 0 ? 0.016 : 1e-3));
    }
}

/* Rays straight down through the stripes at 64 points across them, and
 * visibility from the floor to the sun: each backend finds the square on
 * the covered stripes and the floor under the holes. */
static void test_backends_agree(void **state)
{
    (void)state;
    zt_scene *sc = alpha_scene(MODELS "stripes.gltf", 0, 0, 0, ABOVE);
    static const accel_kind kinds[] = {ACCEL_BRUTE, ACCEL_EMBREE, ACCEL_BVH};
    for (int k = 0; k < 3; k++) {
        rscene rs;
        zt_error err = {0};
        assert_int_equal(rscene_build(&rs, sc, NULL, 0, kinds[k], &err), ZT_OK);
        assert_true(rs.alpha_count == 1);
        for (int j = 0; j < 64; j++) {
            /* Away from the stripes' borders (by 1/8 of a stripe). */
            int i = j % STRIPES;
            double x = stripe_centre(i) + ((j / STRIPES) / 8.0 - 0.45) * 2.0 / STRIPES * 0.75;
            vec3f o = f3((float)x, 3.0f, (float)(-0.9 + 1.8 * j / 63.0));
            hit h = accel_intersect(&rs, o, f3(0, -1, 0));
            int hole = i % 2;
            assert_true(h.part >= 0);
            assert_true(fabsf(h.t - (hole ? 3.0f : 3.0f - (float)HEIGHT)) < 1e-5f);
            vec3f below = f3((float)x, 1e-3f, o.z);
            assert_int_equal(accel_occluded(&rs, below, f3(0, 1, 0), 1e30f, 1), !hole);
            vec3f tr = accel_transmittance(&rs, below, f3(0, 1, 0), 1e30f, 1);
            assert_true(tr.x == (hole ? 1.0f : 0.0f));
        }
        rscene_free(&rs);
    }
    zt_scene_release(sc);
}

static zt_image *accumulate(zt_renderer *r, int w, int h)
{
    zt_image *img = zt_image_create(w, h);
    assert_non_null(img);
    zt_error err = {0};
    if (zt_renderer_accumulate(r, 0, 1, img, NULL, &err) != ZT_OK)
        fail_msg("accumulate: %s", err.message);
    return img;
}

static void test_zone_terms(void **state)
{
    (void)state;
    /* Both squares (the mask, and the BLEND square beside it) seen from
     * above at a slant, with all levels of depth 3. */
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [0.2, 1, 0.1], \"irradiance\": [10, 10, 10], "
             "\"angle\": 0.53}}, {\"sky\": {\"color\": [0.2, 0.2, 0.2]}}, {\"plane\": {\"normal\": "
             "[0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.5) "}}, {\"mesh\": {\"file\": \"%s\", "
             "\"transform\": {\"translate\": [0, 1, 0]}}}, {\"mesh\": {\"file\": \"%s\", "
             "\"transform\": {\"translate\": [2.5, 1, 0]}}}], \"camera\": {\"position\": [1.2, 6, "
             "4], \"lookat\": [1.2, 0, 0], \"fov\": 50, \"gridresolution\": [24, 16]}}",
             MODELS "stripes.gltf", MODELS "quarter.gltf");
    zt_scene *sc = test_scene_text(text, "alpha terms");
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 3;
    o.quality = 0;
    o.threads = 2;
    zt_renderer *r = NULL;
    zt_error err = {0};
    if (zt_renderer_create(sc, &o, &r, &err) != ZT_OK)
        fail_msg("renderer: %s", err.message);
    zt_image *terms = accumulate(r, 24, 16);
    r->options.strategy = ZT_STRATEGY_ZONE;
    zt_image *zones = accumulate(r, 24, 16);
    test_assert_same_image(terms, zones, "pixel vs zone strategy");
    zt_image *ref = zt_image_create(24, 16);
    assert_int_equal(zone_accumulate_reference(r, ref, &err), ZT_OK);
    double se = 0, sum = 0;
    size_t n = (size_t)24 * 16 * 3;
    for (size_t i = 0; i < n; i++) {
        double d = (double)terms->pixels[i] - ref->pixels[i];
        se += d * d;
        sum += ref->pixels[i];
    }
    double e = sqrt(se / n) / (sum / n);
    print_message("zone terms against one zone_radiance per sample: rel_rmse %g\n", e);
    assert_true(sum > 0 && e < 1e-5);
    zt_image_release(terms);
    zt_image_release(zones);
    zt_image_release(ref);
    zt_renderer_release(r);
    zt_scene_release(sc);
}

static void test_bad_cutoffs(void **state)
{
    (void)state;
    /* -0.5 is taken as 0 (every texel covered: the floor is dark under
     * every stripe), 2 as 1 (only alpha 255 covers: the stripes as with
     * the default); each counted and named. */
    static const struct {
        const char *file;
        double hole_floor; /* the floor under a hole stripe, over lit */
        const char *taken;
    } cases[] = {{MODELS "cutoff_negative.gltf", 0.0, "0 taken"},
                 {MODELS "cutoff_above.gltf", 1.0, "1 taken"}};
    double lit = FLOOR * SUN / PI;
    for (int k = 0; k < 2; k++) {
        zt_scene *sc = alpha_scene(cases[k].file, stripe_centre(1), 0, 0, SIDE);
        zt_scene_info info;
        zt_scene_get_info(sc, &info);
        assert_int_equal(info.alpha_fallbacks, 1);
        assert_int_equal(info.alpha_masks, 1);
        assert_non_null(strstr(info.alpha_problem, "alphaCutoff"));
        assert_non_null(strstr(info.alpha_problem, cases[k].taken));
        zt_scene_release(sc);
        for (int mi = 0; mi < 2; mi++) {
            double floor = view_mean(methods[mi], cases[k].file, stripe_centre(1), 0, 0, SIDE, 4);
            print_message("%s: %s: under a hole stripe %.6g\n", method_name[mi], cases[k].file,
                          floor);
            assert_true(fabs(floor - cases[k].hole_floor * lit) < 1e-3 * lit);
        }
    }
    /* NaN is not JSON: the model cannot be read, and the scene says where. */
    char scene[1024];
    snprintf(scene, sizeof scene,
             "{\"scene\": [\n  {\"mesh\": {\"file\": \"%s\"}}\n],\n \"camera\": {\"position\": "
             "[0, 3, 3], \"lookat\": [0, 0, 0], \"fov\": 40, \"gridresolution\": [8, 8]}}",
             MODELS "cutoff_nan.gltf");
    const char *path = test_write_file("nan_cutoff.json", scene);
    char args[1200], *err = NULL;
    snprintf(args, sizeof args, "render '%s' -o '%s'", path, test_tmp_path("nan.pfm"));
    int status = test_run_cli(args, &err);
    print_message("NaN cutoff: status %d, %s", status, err ? err : "(no message)\n");
    assert_int_equal(status, 3);
    assert_non_null(err);
    assert_non_null(strstr(err, "nan_cutoff.json:2:3"));
    assert_non_null(strstr(err, "cutoff_nan.gltf"));
    free(err);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mask_stripes),
        cmocka_unit_test(test_blend_quarter),
        cmocka_unit_test(test_backends_agree),
        cmocka_unit_test(test_zone_terms),
        cmocka_unit_test(test_bad_cutoffs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
