/* glTF emissive textures, emissiveFactor and KHR_materials_emissive_strength
 * in both renderers, against values written out here (in double, from the
 * texel codes, factor and strength that tests/data/make_emissive_models.sh
 * writes):
 *
 * - a square lamp whose texture is half bright (sRGB 255, 200, 100), half
 *   black, seen from below: every pixel is emissiveFactor x texel (sRGB
 *   decoded) x strength, or 0;
 * - the diffuse floor under it: its level-1 radiance at points under the
 *   bright half, the black half, the edge between them and beside the
 *   lamp against albedo / pi times the irradiance integrated numerically
 *   over the lamp's emission (the texture read bilinearly, as the
 *   renderers read it): the path tracer within its noise, the zone tracer
 *   within its approximation (docs/zone-tracer.md, "Emissive textures");
 * - glTF's default emissiveFactor is black: a texture without a factor
 *   emits nothing and is counted as unused; a texture that cannot be
 *   decoded is left out (the factor alone), counted and named. */
#include "test_support.h"
#include "d3.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846
#define MODELS ZT_SOURCE_DIR "/tests/data/emissive/"

static const char *const method_name[] = {"path", "zone"};
static const zt_method methods[] = {ZT_METHOD_PATH, ZT_METHOD_ZONE};

/* What make_emissive_models.sh gives lamp.gltf: the left half's codes,
 * the factor, the strength, the texture's width. */
static const int left_code[3] = {255, 200, 100};
static const double factor[3] = {1.0, 0.8, 0.5};
#define STRENGTH 6.0
#define TEXELS 8
/* The lamp hangs at this height, facing down; the floor's albedo. */
#define HEIGHT 1.0
#define ALBEDO 0.5

static double srgb(int code)
{
    double x = code / 255.0;
    return x <= 0.04045 ? x / 12.92 : pow((x + 0.055) / 1.055, 2.4);
}

/* The bright half's radiance in channel c. */
static double bright(int c)
{
    return factor[c] * srgb(left_code[c]) * STRENGTH;
}

/* The share of the bright radiance at texture coordinate u: 1 up to the
 * last bright texel's centre, 0 from the first black one's, linear
 * between (bilinear filtering; the sampler clamps at the edges). */
static double ramp(double u)
{
    double a = 3.5 / TEXELS, b = 4.5 / TEXELS;
    return u <= a ? 1.0 : u >= b ? 0.0 : (b - u) / (b - a);
}

/* The irradiance at floor point (qx, 0, qz) from the lamp
 * [-1, 1] x [-1, 1] at height h facing down, per unit bright radiance:
 * the integral of ramp(u(x)) h^2 / r^4 over the lamp, in z in closed form
 * (the integral of 1 / (a^2 + w^2)^2), in x by the midpoint rule. */
static double irradiance(double qx, double qz)
{
    const int n = 40000;
    double h = HEIGHT, x0 = -1.0, x1 = 0.125, sum = 0.0;
    for (int i = 0; i < n; i++) {
        double x = x0 + (x1 - x0) * (i + 0.5) / n;
        double a2 = (x - qx) * (x - qx) + h * h, a = sqrt(a2);
        double w1 = -1.0 - qz, w2 = 1.0 - qz;
        double g2 = w2 / (2 * a2 * (a2 + w2 * w2)) + atan(w2 / a) / (2 * a2 * a);
        double g1 = w1 / (2 * a2 * (a2 + w1 * w1)) + atan(w1 / a) / (2 * a2 * a);
        /* u along +x: the model's u, kept by the half turn about x. */
        sum += ramp((x + 1.0) / 2.0) * h * h * (g2 - g1);
    }
    return sum * (x1 - x0) / n;
}

/* The scene: the lamp `file` at HEIGHT over a grey floor, the camera at
 * eye looking at q with a narrow view (0.5 degrees, 8 x 8 pixels). */
static zt_scene *lamp_scene(const char *file, d3 eye, d3 q)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.5)
             "}}, {\"mesh\": {\"file\": \"%s\", \"backculled\": true, \"transform\": "
             "{\"rotate\": [[1, 0, 0, 180]], \"translate\": [0, %.17g, 0]}}}], "
             "\"camera\": {\"position\": [%.17g, %.17g, %.17g], \"lookat\": [%.17g, %.17g, "
             "%.17g], \"fov\": 0.5, \"gridresolution\": [8, 8]}}",
             file, HEIGHT, eye.x, eye.y, eye.z, q.x, q.y, q.z);
    return test_scene_text(text, "emissive");
}

/* The lamp seen from below at lamp point (x, HEIGHT, z), level 0: every
 * pixel's channel c must be want[c] (relative 1e-5, or exactly 0). */
static void check_seen(const char *file, double x, double z, const double want[3])
{
    for (int mi = 0; mi < 2; mi++) {
        zt_scene *sc = lamp_scene(file, mk(x + 0.1, 0.3, z + 0.2), mk(x, HEIGHT, z));
        zt_image *im = test_render_level(sc, methods[mi], 0, 0, 4);
        double worst = 0;
        for (int i = 0; i < im->width * im->height; i++)
            for (int c = 0; c < 3; c++) {
                double got = im->pixels[3 * i + c];
                double err = want[c] > 0 ? fabs(got / want[c] - 1) : fabs(got);
                worst = fmax(worst, err);
            }
        print_message("%s: %s seen at x = %+.2f: pixel 0 (%.7g, %.7g, %.7g), want (%.7g, %.7g, "
                      "%.7g), worst %s %.2g\n",
                      method_name[mi], strrchr(file, '/') + 1, x, im->pixels[0],
                      im->pixels[1], im->pixels[2], want[0], want[1], want[2],
                      want[0] > 0 ? "relative error" : "value", worst);
        assert_true(worst < 1e-5);
        zt_image_release(im);
        zt_scene_release(sc);
    }
}

static void test_seen_by_the_camera(void **state)
{
    (void)state;
    /* x = -0.5, u = 0.25: inside the bright half, texels 1 and 2 (and
     * their neighbours) all bright; x = +0.5 inside the black half. */
    double want[3], black[3] = {0, 0, 0};
    for (int c = 0; c < 3; c++)
        want[c] = bright(c);
    check_seen(MODELS "lamp.gltf", -0.5, 0.3, want);
    check_seen(MODELS "lamp.gltf", 0.5, -0.3, black);
}

/* The floor's mean radiance in the view of q, level 1. */
static void floor_view(zt_method method, d3 q, int spp, double out[3])
{
    d3 wo = unit(mk(0, 0.6, 1));
    zt_scene *sc = lamp_scene(MODELS "lamp.gltf", add(q, scale(wo, 3)), q);
    zt_image *im = test_render_level(sc, method, 1, 1, spp);
    int n = im->width * im->height;
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            assert_true(isfinite(im->pixels[3 * i + c]));
            out[c] += im->pixels[3 * i + c] / n;
        }
    zt_image_release(im);
    zt_scene_release(sc);
}

static void test_floor_irradiance(void **state)
{
    (void)state;
    /* Under the bright half, under the black half, under the edge between
     * them, beside the lamp on its bright side. */
    const d3 q[4] = {mk(-0.5, 0, 0), mk(0.5, 0, 0.2), mk(0, 0, -0.4), mk(-1.6, 0, 0.3)};
    const char *where[4] = {"under the bright half", "under the black half", "under the edge",
                            "beside the lamp"};
    /* The path tracer: its noise at 1024 samples a pixel (64 pixels),
     * measured within 0.3% at these points.  The zone tracer: each piece
     * of the lamp (a texel wide, emissive_split.c) sends its mean
     * radiance; measured within 1% at these points (the whole two
     * triangles' means, uncut, gave -20% to +62%). */
    const double tolerance[2] = {0.01, 0.015};
    for (int k = 0; k < 4; k++) {
        double e = irradiance(q[k].x, q[k].z);
        for (int mi = 0; mi < 2; mi++) {
            double got[3];
            floor_view(methods[mi], q[k], mi == 0 ? 1024 : 1, got);
            for (int c = 0; c < 3; c++) {
                double want = ALBEDO / PI * e * bright(c);
                if (c == 0)
                    print_message("%s: floor %s (%.1f, %.1f): %.6g, integral %.6g (%+.3f%%)\n",
                                  method_name[mi], where[k], q[k].x, q[k].z, got[c], want,
                                  100 * (got[c] / want - 1));
                assert_true(fabs(got[c] / want - 1) < tolerance[mi]);
            }
        }
    }
}

static void test_unused_and_left_out(void **state)
{
    (void)state;
    /* With its texture used, nothing of lamp.gltf is reported unused. */
    zt_scene *sc = lamp_scene(MODELS "lamp.gltf", mk(0.1, 0.3, 0.2), mk(0, 1, 0));
    zt_scene_info info;
    zt_scene_get_info(sc, &info);
    assert_string_equal(info.unused, "");
    assert_int_equal(info.map_fallbacks, 0);
    /* Its two triangles, 8 texels along their legs, cut 8 ways each. */
    assert_int_equal(info.emissive_pieces, 2 * 8 * 8 - 2);
    zt_scene_release(sc);

    /* No emissiveFactor: glTF's default, black, so no light; the texture
     * multiplies nothing and is reported unused. */
    sc = lamp_scene(MODELS "no_factor.gltf", mk(0.1, 0.3, 0.2), mk(0, 1, 0));
    zt_scene_get_info(sc, &info);
    print_message("no_factor.gltf: unused \"%s\"\n", info.unused);
    assert_non_null(strstr(info.unused, "1 emissive textures under a black emissive factor"));
    zt_scene_release(sc);
    double black[3] = {0, 0, 0};
    check_seen(MODELS "no_factor.gltf", -0.5, 0.3, black);

    /* A texture that cannot be decoded: left out, counted and named; the
     * lamp then emits its factor times its strength all over. */
    test_copy_file(MODELS "lamp.gltf", test_tmp_path("lamp.gltf"));
    test_copy_file(MODELS "lamp.bin", test_tmp_path("lamp.bin"));
    test_write_file("lamp_e.png", "\x89PNG\r\n\x1a\n but cut short");
    char file[512];
    snprintf(file, sizeof file, "%s", test_tmp_path("lamp.gltf"));
    sc = lamp_scene(file, mk(0.1, 0.3, 0.2), mk(0, 1, 0));
    zt_scene_get_info(sc, &info);
    print_message("lamp.gltf with a broken texture: %d left out (%s)\n", info.map_fallbacks,
                  info.map_problem);
    assert_int_equal(info.map_fallbacks, 1);
    assert_non_null(strstr(info.map_problem, "emissive texture"));
    assert_non_null(strstr(info.map_problem, "lamp_e.png"));
    zt_scene_release(sc);
    double plain[3];
    for (int c = 0; c < 3; c++)
        plain[c] = factor[c] * STRENGTH;
    check_seen(file, -0.5, 0.3, plain);
    check_seen(file, 0.5, -0.3, plain);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_seen_by_the_camera),
        cmocka_unit_test(test_floor_irradiance),
        cmocka_unit_test(test_unused_and_left_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
