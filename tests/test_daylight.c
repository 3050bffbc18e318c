/* Light from far away in both renderers: the sun on a floor (closed form)
 * and the width of its penumbra, a furnace inside a constant environment
 * map, the map's orientation and rotation, what importance sampling of a
 * map with a small bright patch is worth to the path tracer, and maps that
 * cannot be used. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zonetrace/image.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#include "geom/accel.h"
#include "light/env_map.h"
#include "path/path_tracer.h"
#include "render/render_scene.h"
#include "util/sampler.h"

#define PI 3.14159265358979323846
#define DIFFUSE_HALF TEST_DIFFUSE(0.5)


static double image_mean(const zt_image *im, int channel)
{
    double sum = 0;
    for (int i = 0; i < im->width * im->height; i++)
        sum += im->pixels[3 * i + channel];
    return sum / (im->width * im->height);
}

/* Writes a width x height PFM map whose texel (i, j) is f(i, j). */
typedef void (*texel_fn)(int i, int j, float rgb[3]);
static const char *write_map(const char *name, int width, int height, texel_fn f)
{
    zt_image *im = zt_image_create(width, height);
    for (int j = 0; j < height; j++)
        for (int i = 0; i < width; i++)
            f(i, j, zt_image_pixel(im, i, j));
    const char *path = test_tmp_path(name);
    zt_error err = {0};
    if (zt_image_write(im, path, NULL, &err) != ZT_OK)
        fail_msg("map: %s", err.message);
    zt_image_release(im);
    return path;
}

/* A white floor under the sun at elevation e: a E sin(e) / pi. */
static void test_sun_floor(void **state)
{
    (void)state;
    const double e = 35 * PI / 180;
    char text[1024];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, %.17g], \"irradiance\": "
             "[1000, 800, 600]}}, {\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, "
             DIFFUSE_HALF "}}], \"camera\": {\"position\": [0, 2, 0], \"lookat\": [0, 0, -2], "
             "\"fov\": 40, \"gridresolution\": [24, 24]}}",
             0.6 * cos(e), sin(e), 0.8 * cos(e));
    zt_scene *s = test_scene_text(text, "sun_floor");
    const double irr[3] = {1000, 800, 600};
    for (int m = 0; m < 2; m++) {
        zt_image *im = test_render_level(s, m ? ZT_METHOD_ZONE : ZT_METHOD_PATH, -1, 3, 16);
        double worst = 0;
        for (int c = 0; c < 3; c++) {
            double want = 0.5 * irr[c] * sin(e) / PI;
            for (int i = 0; i < im->width * im->height; i++)
                worst = fmax(worst, fabs(im->pixels[3 * i + c] / want - 1));
        }
        print_message("%s: sun on a floor, largest error per pixel %.2e\n", m ? "zone" : "path",
                      worst);
        assert_true(worst < 0.005);
        zt_image_release(im);
    }
    zt_scene_release(s);
}

/* The visible share of a disc of radius 1 whose centre lies t beyond a
 * straight edge (t in [-1, 1]): the circular segment on the far side. */
static double disc_share(double t)
{
    if (t <= -1)
        return 0;
    if (t >= 1)
        return 1;
    double a = acos(-t);
    return (a + t * sqrt(1 - t * t)) / PI;
}

/* Where along the row the light first passes `share` of its full value. */
static double crossing(const double *row, int n, double share, const double *x)
{
    for (int i = 1; i < n; i++)
        if (row[i - 1] < share && row[i] >= share)
            return x[i - 1] + (x[i] - x[i - 1]) * (share - row[i - 1]) / (row[i] - row[i - 1]);
    return NAN;
}

/* An opaque sheet at height 1 over x < 0 under a sun of 2 degrees straight
 * above: across the edge the light rises over 2 tan(1 degree); the width
 * from 10% to 90% of full light is the disc's, within 10%. */
static void test_sun_penumbra(void **state)
{
    (void)state;
    const char *text =
        "{\"scene\": [{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [100, 100, 100], "
        "\"angle\": 2}},"
        "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " DIFFUSE_HALF "}},"
        "{\"triangle\": {\"points\": [[-40, 1, -40], [0, 1, -40], [0, 1, 40]], " DIFFUSE_HALF "}},"
        "{\"triangle\": {\"points\": [[-40, 1, -40], [0, 1, 40], [-40, 1, 40]], " DIFFUSE_HALF "}}],"
        "\"camera\": {\"viewpoint\": [0, 0.5, 0], \"screen\": [[-0.012, 0.4, -0.0004], "
        "[0.012, 0.4, -0.0004], [-0.012, 0.4, 0.0004], [0.012, 0.4, 0.0004]], "
        "\"gridresolution\": [240, 8]}}";
    zt_scene *s = test_scene_text(text, "sun_penumbra");
    const double r = tan(1.0 * PI / 180); /* the penumbra's half width at height 1 */
    /* The disc's own 10%-90% width: solve disc_share(t) = 0.1 and 0.9. */
    double t10 = -1, t90 = -1;
    for (double t = -1; t <= 1; t += 1e-5) {
        if (disc_share(t) < 0.1)
            t10 = t;
        if (disc_share(t) < 0.9)
            t90 = t;
    }
    double want = (t90 - t10) * r;
    for (int m = 0; m < 2; m++) {
        zt_image *im = test_render_level(s, m ? ZT_METHOD_ZONE : ZT_METHOD_PATH, 1, 1, 256);
        double row[240], x[240], full = 0;
        for (int i = 0; i < 240; i++) {
            double v = 0;
            for (int j = 0; j < 8; j++)
                v += zt_image_pixel(im, i, j)[1];
            row[i] = v / 8;
            x[i] = -0.06 + (i + 0.5) * 0.12 / 240; /* the pixel's centre on the floor */
            full = fmax(full, row[i]);
        }
        for (int i = 0; i < 240; i++)
            row[i] /= full;
        double width = crossing(row, 240, 0.9, x) - crossing(row, 240, 0.1, x);
        print_message("%s: penumbra 10%%-90%% %.5f, the disc's %.5f\n", m ? "zone" : "path",
                      width, want);
        assert_true(fabs(width / want - 1) < 0.1);
        zt_image_release(im);
    }
    zt_scene_release(s);
}

static void constant_texel(int i, int j, float rgb[3])
{
    (void)i;
    (void)j;
    rgb[0] = 2.0f;
    rgb[1] = 1.5f;
    rgb[2] = 1.0f;
}

/* A diffuse sphere of albedo a inside a constant map of radiance L: a L on
 * every pixel that sees the sphere. */
static void test_env_furnace(void **state)
{
    (void)state;
    const char *map = write_map("constant.pfm", 16, 8, constant_texel);
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sky\": {\"file\": \"%s\"}},"
             "{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, " TEST_DIFFUSE(0.6) "}}],"
             "\"camera\": {\"position\": [0, 0, 4], \"lookat\": [0, 0, 0], \"fov\": 12, "
             "\"gridresolution\": [16, 16]}}", map);
    zt_scene *s = test_scene_text(text, "env_furnace");
    const double want[3] = {1.2, 0.9, 0.6};
    for (int m = 0; m < 2; m++) {
        zt_image *im = test_render_level(s, m ? ZT_METHOD_ZONE : ZT_METHOD_PATH, -1, 8, 64);
        for (int c = 0; c < 3; c++) {
            double mean = image_mean(im, c);
            print_message("%s: furnace channel %d: %.5f (want %.5f)\n", m ? "zone" : "path", c,
                          mean, want[c]);
            assert_true(fabs(mean / want[c] - 1) < 0.005);
        }
        zt_image_release(im);
    }
    zt_scene_release(s);
}

/* Three columns, two rows, each texel its own colour. */
static void coloured_texel(int i, int j, float rgb[3])
{
    rgb[0] = (float)(1 + i);
    rgb[1] = (float)(1 + j);
    rgb[2] = (float)(10 + 3 * j + i);
}

/* The colour the camera sees straight ahead, through a narrow view. */
static void centre_colour(const char *map, double rotate, const double look[3], float out[3])
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sky\": {\"file\": \"%s\", \"rotate\": %g}}],"
             "\"camera\": {\"position\": [0, 0, 0], \"lookat\": [%g, %g, %g], \"fov\": 2, "
             "\"gridresolution\": [2, 2]}}", map, rotate, look[0], look[1], look[2]);
    zt_scene *s = test_scene_text(text, "env_orientation");
    zt_image *im = test_render_level(s, ZT_METHOD_PATH, -1, 1, 4);
    for (int c = 0; c < 3; c++)
        out[c] = (float)image_mean(im, c);
    zt_image_release(im);
    zt_scene_release(s);
}

/* docs/scene-format.md's orientation: the map's centre column looks along
 * -z, its first quarter along -x, its third along +x, the top row up; and
 * rotate turns the map about +y (counter-clockwise seen from above). */
static void test_env_orientation(void **state)
{
    (void)state;
    const char *map = write_map("coloured.pfm", 4, 2, coloured_texel);
    struct {
        double rotate, look[3];
        int column, row;
    } cases[] = {
        {0, {-0.05, 0.3, -1}, 1, 0}, /* u just below 0.5: column 1 of 4, top row */
        {0, {0.05, 0.3, -1}, 2, 0},
        {0, {-1, -0.3, 0.05}, 0, 1},
        {0, {1, -0.3, 0.05}, 3, 1},
        {90, {-1, 0.3, -0.05}, 2, 0}, /* what looked along -z now looks along -x */
    };
    for (unsigned k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        float got[3], want[3];
        centre_colour(map, cases[k].rotate, cases[k].look, got);
        coloured_texel(cases[k].column, cases[k].row, want);
        print_message("rotate %g, look (%g, %g, %g): (%g, %g, %g), texel (%d, %d)\n",
                      cases[k].rotate, cases[k].look[0], cases[k].look[1], cases[k].look[2],
                      got[0], got[1], got[2], cases[k].column, cases[k].row);
        for (int c = 0; c < 3; c++)
            assert_float_equal(got[c], want[c], 1e-4);
    }
}

/* A sky of 1 with a patch of 4 x 4 texels of 10^4. */
#define PATCH_W 64
#define PATCH_H 32
static void patch_texel(int i, int j, float rgb[3])
{
    float v = (i >= 40 && i < 44 && j >= 6 && j < 10) ? 1e4f : 1.0f;
    rgb[0] = rgb[1] = rgb[2] = v;
}

static void uniform_texel(int i, int j, float rgb[3])
{
    (void)i;
    (void)j;
    rgb[0] = rgb[1] = rgb[2] = 1.0f;
}

/* The relative error over `pixels` estimates of 16 samples each of the
 * direct light on a white floor seen from above, against the exact one. */
static double floor_error_16spp(const rscene *rs, double exact, int pixels)
{
    path_params pp = {.min_level = 1, .max_level = 1, .seed = 0};
    double sq = 0;
    for (int k = 0; k < pixels; k++) {
        path_pixel px = path_pixel_make(sampler_hash3((uint32_t)k, 0, 0));
        double sum = 0;
        for (uint32_t i = 0; i < 16; i++) {
            uint64_t rays = 0;
            vec3f l = path_trace_sample(rs, &pp, f3(0.001f * k, 1, 0), f3(0, -1, 0), &px, i,
                                        sampler_reverse_bits(i), &rays);
            sum += l.y;
        }
        double err = sum / 16 - exact;
        sq += err * err;
    }
    return sqrt(sq / pixels) / exact;
}

/* The path tracer draws the map's directions by luminance: on a floor under
 * a sky with a small sun-like patch its error at 16 samples is more than
 * ten times lower than when it draws them uniformly over the sphere. */
static void test_env_importance(void **state)
{
    (void)state;
    const char *map = write_map("patch.pfm", PATCH_W, PATCH_H, patch_texel);
    const char *flat = write_map("flat.pfm", PATCH_W, PATCH_H, uniform_texel);
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sky\": {\"file\": \"%s\"}},"
             "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(1) "}}],"
             "\"camera\": {\"position\": [0, 1, 0], \"lookat\": [0, 0, -1], \"fov\": 40, "
             "\"gridresolution\": [2, 2]}}", map);
    zt_scene *s = test_scene_text(text, "env_importance");
    zt_scene *flat_scene = NULL;
    snprintf(text, sizeof text, "{\"scene\": [{\"sky\": {\"file\": \"%s\"}}], \"camera\": "
             "{\"position\": [0, 1, 0], \"lookat\": [0, 0, -1], \"gridresolution\": [2, 2]}}",
             flat);
    flat_scene = test_scene_text(text, "flat");
    rscene rs;
    zt_error err = {0};
    assert_int_equal(rscene_build(&rs, s, NULL, 0, ACCEL_EMBREE, &err), ZT_OK);
    /* The exact light on the floor: every texel of the upper half (the
     * horizon is a row boundary) times the integral of cos over it. */
    double e = 0;
    for (int j = 0; j < PATCH_H / 2; j++)
        for (int i = 0; i < PATCH_W; i++) {
            float rgb[3];
            patch_texel(i, j, rgb);
            double t0 = PI * j / PATCH_H, t1 = PI * (j + 1) / PATCH_H;
            e += rgb[1] * (2 * PI / PATCH_W) * (sin(t1) * sin(t1) - sin(t0) * sin(t0)) / 2;
        }
    double exact = e / PI;
    double importance = floor_error_16spp(&rs, exact, 4096);
    rs.distant.sampling = flat_scene->sky_map; /* the same size, uniform over the sphere */
    double uniform = floor_error_16spp(&rs, exact, 4096);
    print_message("16 spp: error %.4f by importance, %.4f uniformly (%.1fx)\n", importance,
                  uniform, uniform / importance);
    assert_true(uniform > 10 * importance);
    rscene_free(&rs);
    zt_scene_release(flat_scene);
    zt_scene_release(s);
}

/* Maps that cannot be used: a clear message at the "file" value, status
 * ZT_ERR_READ for a file that cannot be read, ZT_ERR_PARSE for one that is
 * not a usable map. */
static void test_bad_maps(void **state)
{
    (void)state;
    const char *garbage = test_write_file("garbage.exr", "v/1\001 this is not an image");
    const char *empty = test_write_file("empty.pfm", "PF\n0 0\n-1.0\n");
    /* A 2 x 1 PFM whose second texel is NaN. */
    const char *nan_path = test_tmp_path("nan.pfm");
    FILE *f = fopen(nan_path, "wb");
    assert_non_null(f);
    fputs("PF\n2 1\n-1.0\n", f);
    float texels[6] = {1, 1, 1, 1, NAN, 1};
    fwrite(texels, sizeof texels, 1, f);
    fclose(f);
    struct {
        const char *path;
        zt_status status;
        const char *word;
    } cases[] = {
        {"/nonexistent/sky.exr", ZT_ERR_READ, "sky"},
        {garbage, ZT_ERR_PARSE, "sky"},
        {empty, ZT_ERR_PARSE, "sky"},
        {nan_path, ZT_ERR_PARSE, "NaN"},
    };
    for (unsigned k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[1024];
        snprintf(text, sizeof text, "{\n\"scene\": [\n{\"sky\": {\"file\": \"%s\"}}\n],\n"
                 "\"camera\": {\"position\": [0, 0, 0], \"lookat\": [0, 0, -1]}}",
                 cases[k].path);
        zt_scene *s = NULL;
        zt_error err = {0};
        zt_status st = zt_scene_load_string(text, strlen(text), "bad.json", &s, &err);
        print_message("%s: %s\n", cases[k].path, err.message);
        assert_int_equal(st, cases[k].status);
        assert_null(s);
        assert_non_null(strstr(err.message, "bad.json:3:18:"));
        assert_non_null(strstr(err.message, cases[k].word));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sun_floor),
        cmocka_unit_test(test_sun_penumbra),
        cmocka_unit_test(test_env_furnace),
        cmocka_unit_test(test_env_orientation),
        cmocka_unit_test(test_env_importance),
        cmocka_unit_test(test_bad_maps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
