/* The zone tracer's preview (zt_renderer_preview, phase_two/preview.c):
 * one sample a pixel from the forest's nodes.  Against the full image of the
 * same renderer: at the second level, which both read from the nodes of the
 * box's walls, the preview's pixels are the full image's wherever the full
 * image shades its pixel's centre alone; with every level, its direct light
 * is the nodes' (E_0) instead of the exact one, which on the Cornell box
 * moves the image's mean by little. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "zonetrace/image.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define SIZE 96

static zt_scene *cornell(int size)
{
    zt_scene *s = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_file(ZT_SOURCE_DIR "/scenes/cornell.json", &s, &err), ZT_OK);
    zt_camera cam = zt_scene_get_camera(s);
    assert_int_equal(zt_camera_set_resolution(&cam, size, size, &err), ZT_OK);
    zt_scene_set_camera(s, &cam);
    return s;
}

/* The preview and the full image of one renderer. */
static void preview_and_full(int level, zt_image **preview, zt_image **full)
{
    zt_scene *s = cornell(SIZE);
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = level >= 0 ? level : 3;
    o.level = level;
    o.threads = 2;
    zt_renderer *r = NULL;
    zt_error err = {0};
    assert_int_equal(zt_renderer_create(s, &o, &r, &err), ZT_OK);
    *preview = zt_image_create(SIZE, SIZE);
    assert_non_null(*preview);
    assert_int_equal(zt_renderer_preview(r, *preview, NULL, &err), ZT_OK);
    /* Deterministic: a second preview adds the same values. */
    zt_image *again = zt_image_create(SIZE, SIZE);
    assert_int_equal(zt_renderer_preview(r, again, NULL, &err), ZT_OK);
    assert_memory_equal(again->pixels, (*preview)->pixels, SIZE * SIZE * 3 * sizeof(float));
    zt_image_release(again);
    assert_int_equal(zt_renderer_render(r, full, NULL, &err), ZT_OK);
    zt_renderer_release(r);
    zt_scene_release(s);
}

static void test_second_level_reads_the_same_nodes(void **state)
{
    (void)state;
    zt_image *pre, *full;
    preview_and_full(2, &pre, &full);
    int same = 0, n = SIZE * SIZE;
    for (int i = 0; i < n; i++)
        same += !memcmp(&pre->pixels[3 * i], &full->pixels[3 * i], 3 * sizeof(float));
    zt_compare_result c;
    zt_error err;
    assert_int_equal(zt_image_compare(pre, full, &c, &err), ZT_OK);
    printf("level 2: %d of %d pixels equal to the full image's, rel_rmse %.3f%%\n", same, n,
           100 * c.rel_rmse);
    /* Every pixel that the full image shades at its centre alone (no edge,
     * no sphere in it): most of the box's walls. */
    assert_true(same >= n * 3 / 4); /* 87% measured */
    assert_true(c.rel_rmse < 0.12); /* the edges' and the spheres' pixels: 8.4% */
    zt_image_release(pre);
    zt_image_release(full);
}

static void test_all_levels_near_the_full_image(void **state)
{
    (void)state;
    zt_image *pre, *full;
    preview_and_full(-1, &pre, &full);
    /* The pixels that see no light: the light's few pixels, measured by
     * coverage in the full image and by one ray in the preview, would
     * outweigh everything else (its emission is 100 times the walls'). */
    double sum_pre = 0, sum_full = 0, sq = 0;
    int n = 0;
    for (int i = 0; i < SIZE * SIZE; i++) {
        const float *a = &pre->pixels[3 * i], *b = &full->pixels[3 * i];
        for (int k = 0; k < 3; k++)
            assert_true(isfinite(a[k]) && a[k] >= 0.0f);
        if (a[0] > 100.0f || b[0] > 100.0f)
            continue;
        for (int k = 0; k < 3; k++) {
            sum_pre += a[k];
            sum_full += b[k];
            sq += (double)(a[k] - b[k]) * (a[k] - b[k]);
        }
        n++;
    }
    double mean_full = sum_full / (3.0 * n), rel = sqrt(sq / (3.0 * n)) / mean_full;
    printf("depth 3, %d pixels without the light: preview mean %+.2f%% from the full image's, "
           "rel_rmse %.2f%%\n",
           n, 100 * (sum_pre / sum_full - 1), 100 * rel);
    assert_true(n > SIZE * SIZE * 9 / 10);
    /* Direct light from the nodes: soft where the exact light is sharp,
     * but the same light. */
    assert_true(fabs(sum_pre / sum_full - 1) < 0.02); /* -0.24% measured */
    assert_true(rel < 0.15); /* 9.2%, most of it the glass ball's caustic */
    zt_image_release(pre);
    zt_image_release(full);
}

/* Depth 1: the forest keeps no maps, and the preview takes the exact
 * direct light at the pixels' centres, as the full image does on its
 * pixels that shade the centre alone. */
static void test_depth_one_takes_exact_direct_light(void **state)
{
    (void)state;
    zt_image *pre, *full;
    preview_and_full(1, &pre, &full);
    int same = 0, n = SIZE * SIZE;
    for (int i = 0; i < n; i++)
        same += !memcmp(&pre->pixels[3 * i], &full->pixels[3 * i], 3 * sizeof(float));
    printf("level 1: %d of %d pixels equal to the full image's\n", same, n);
    assert_true(same >= n * 4 / 5); /* 90% measured */
    zt_image_release(pre);
    zt_image_release(full);
}

/* A coated white sphere in a white furnace: its preview is the sky's
 * radiance on every pixel.  The coat reflects its irradiance as a white
 * diffuse surface of albedo s E(cos_o) (ZR_SMOOTH_COAT); its one direction
 * a hit, taken with probability s E(cos_o) and weighed by the inverse,
 * would put pixels at 1 - s E or far above 1. */
static void test_coat_without_grain(void **state)
{
    (void)state;
    zt_scene *s = test_scene_text(
        "{\"scene\": [{\"sky\": {\"color\": [1, 1, 1]}}, {\"sphere\": {\"center\": [0, 0, 0], "
        "\"radius\": 1, \"material\": {\"character\": {\"diffuse\": 1, \"metallic\": 0, "
        "\"reflecting\": 0, \"refractive\": 0}, \"color\": [1, 1, 1], \"specular\": 1, "
        "\"roughness\": 0.3}}}], \"camera\": {\"position\": [0, 0, 4], \"lookat\": [0, 0, 0], "
        "\"fov\": 30, \"gridresolution\": [32, 32]}}",
        "coat_preview");
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.threads = 2;
    zt_renderer *r = NULL;
    zt_error err = {0};
    assert_int_equal(zt_renderer_create(s, &o, &r, &err), ZT_OK);
    zt_image *pre = zt_image_create(32, 32);
    assert_int_equal(zt_renderer_preview(r, pre, NULL, &err), ZT_OK);
    /* The sphere's pixels well inside its outline (it spans about 15
     * pixels from the centre). */
    double lo = 1e9, hi = -1e9;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            double dx = x + 0.5 - 16, dy = y + 0.5 - 16;
            if (dx * dx + dy * dy > 10.0 * 10.0)
                continue;
            for (int k = 0; k < 3; k++) {
                double v = pre->pixels[3 * (y * 32 + x) + k];
                lo = fmin(lo, v);
                hi = fmax(hi, v);
            }
        }
    printf("coated white sphere in a white furnace, preview: %.4f to %.4f\n", lo, hi);
    assert_true(lo > 0.98 && hi < 1.02);
    zt_image_release(pre);
    zt_renderer_release(r);
    zt_scene_release(s);
}

/* The path tracer's preview is its sample 0. */
static void test_path_preview_is_sample_zero(void **state)
{
    (void)state;
    zt_scene *s = cornell(16);
    zt_render_options o = zt_render_options_default();
    o.threads = 2;
    zt_renderer *r = NULL;
    zt_error err = {0};
    assert_int_equal(zt_renderer_create(s, &o, &r, &err), ZT_OK);
    zt_image *a = zt_image_create(16, 16), *b = zt_image_create(16, 16);
    assert_int_equal(zt_renderer_preview(r, a, NULL, &err), ZT_OK);
    assert_int_equal(zt_renderer_accumulate(r, 0, 1, b, NULL, &err), ZT_OK);
    assert_memory_equal(a->pixels, b->pixels, 16 * 16 * 3 * sizeof(float));
    /* A wrong size is refused. */
    zt_image *small = zt_image_create(8, 8);
    assert_int_equal(zt_renderer_preview(r, small, NULL, &err), ZT_ERR_ARGUMENT);
    zt_image_release(small);
    zt_image_release(a);
    zt_image_release(b);
    zt_renderer_release(r);
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_second_level_reads_the_same_nodes),
        cmocka_unit_test(test_all_levels_near_the_full_image),
        cmocka_unit_test(test_depth_one_takes_exact_direct_light),
        cmocka_unit_test(test_path_preview_is_sample_zero),
        cmocka_unit_test(test_coat_without_grain),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
