/* The zone tracer's rules that need no reference image: determinism (two
 * runs, thread counts), the two Phase Two strategies giving the same bytes,
 * the per-zone terms adding up to the plain shading, the forest file (round
 * trip, rejections), camera moves without Phase One, levels adding up to
 * the depth image, single lights adding up to all lights.  Small images,
 * quality 0: seconds, also under AddressSanitizer. */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"
#include "zone/phase_two/phase_two.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define W 20
#define H 16

#define DIFFUSE(r, g, b) "{\"character\": {\"diffuse\": 1, \"metallic\": 0, " \
    "\"reflecting\": 0, \"refractive\": 0}, \"color\": [" #r ", " #g ", " #b "]}"

/* A small open box: diffuse walls, two ceiling lights (two light objects),
 * a mirror sphere, a glass sphere and a half-metallic triangle; SKY is
 * spliced in for the variant with a sky, seen past the box. */
#define BOX_SCENE(SKY, BACK_COLOR)                                                       \
    "{\"scene\": [" SKY                                                                  \
    "{\"lighttriangle\": {\"points\": [[-1, 4.9, -1], [1, 4.9, -1], [-1, 4.9, 1]], "     \
    "\"emission\": [8, 8, 7]}},"                                                         \
    "{\"lighttriangle\": {\"points\": [[1, 4.9, 1], [-1, 4.9, 1], [1, 4.9, -1]], "       \
    "\"emission\": [6, 7, 8]}},"                                                         \
    "{\"thing\": {\"material\": " DIFFUSE(0.7, 0.7, 0.7) ", \"parts\": ["                 \
    "{\"triangle\": {\"points\": [[-5, -5, -5], [5, -5, 5], [5, -5, -5]]}},"            \
    "{\"triangle\": {\"points\": [[-5, -5, -5], [-5, -5, 5], [5, -5, 5]]}},"            \
    "{\"triangle\": {\"points\": [[-5, 5, -5], [5, 5, -5], [5, 5, 5]]}},"               \
    "{\"triangle\": {\"points\": [[-5, 5, -5], [5, 5, 5], [-5, 5, 5]]}}]}},"            \
    "{\"thing\": {\"material\": " BACK_COLOR ", \"parts\": ["                             \
    "{\"triangle\": {\"points\": [[-5, -5, -5], [5, -5, -5], [5, 5, -5]]}},"            \
    "{\"triangle\": {\"points\": [[-5, -5, -5], [5, 5, -5], [-5, 5, -5]]}}]}},"         \
    "{\"thing\": {\"material\": " DIFFUSE(0.7, 0.15, 0.1) ", \"parts\": ["                \
    "{\"triangle\": {\"points\": [[-5, -5, -5], [-5, 5, -5], [-5, 5, 5]]}},"            \
    "{\"triangle\": {\"points\": [[-5, -5, -5], [-5, 5, 5], [-5, -5, 5]]}}]}},"         \
    "{\"sphere\": {\"center\": [-2, -3.5, -1], \"radius\": 1.5, \"material\": "          \
    "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 1, "              \
    "\"refractive\": 0}, \"color\": [0.9, 0.9, 0.9]}}},"                                 \
    "{\"sphere\": {\"center\": [2, -3.8, 1], \"radius\": 1.2, \"material\": "            \
    "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 0, "              \
    "\"refractive\": 1}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5}}},"             \
    "{\"triangle\": {\"points\": [[5, -5, -3], [5, 2, -3], [5, -5, 3]], \"material\": "  \
    "{\"character\": {\"diffuse\": 0.5, \"metallic\": 0.5, \"reflecting\": 0, "          \
    "\"refractive\": 0}, \"color\": [0.9, 0.7, 0.3], \"refractiveindex\": 0.3}}}"        \
    "], \"camera\": {\"viewpoint\": [0.3, 0.2, 14], \"screen\": [[-1, 1, 13], "          \
    "[1, 1, 13], [-1, -1, 13], [1, -1, 13]], \"gridresolution\": [20, 16]}}"

static const char *box_text = BOX_SCENE("", DIFFUSE(0.6, 0.6, 0.6));
static const char *other_box_text = BOX_SCENE("", DIFFUSE(0.6, 0.6, 0.5));
static const char *sky_box_text =
    BOX_SCENE("{\"sky\": {\"color\": [0.3, 0.4, 0.6]}},", DIFFUSE(0.6, 0.6, 0.6));

static zt_scene *scene_from(const char *text) { return test_scene_text(text, "box.json"); }

static const char *mesh_box_text(void);

/* The mesh box with a mirror sphere and a glass one: the gathers on the
 * slats add the caustics and glints their nodes keep apart (f->c). */
static const char *mesh_mirror_text(void)
{
    static char text[8192];
    if (text[0])
        return text;
    const char *base = mesh_box_text(), *cam = strstr(base, "], \"camera\"");
    assert_non_null(cam);
    snprintf(text, sizeof text, "%.*s,"
             "{\"sphere\": {\"center\": [-2, -3.5, -1], \"radius\": 1.5, \"material\": "
             "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 1, "
             "\"refractive\": 0}, \"color\": [0.9, 0.9, 0.9]}}},"
             "{\"sphere\": {\"center\": [2, -3.8, 1], \"radius\": 1.2, \"material\": "
             "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 0, "
             "\"refractive\": 1}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5}}}%s",
             (int)(cam - base), base, cam);
    return text;
}

/* The box with rough lobes: the mirror sphere at roughness 0.3, the glass
 * at 0.2, the metallic triangle at 0.5 (phase_two/rough.c). */
static const char *rough_box_text(void)
{
    static char text[8192];
    if (text[0])
        return text;
    const char *from[3] = {"[0.9, 0.9, 0.9]}", "\"refractiveindex\": 1.5}",
                           "\"refractiveindex\": 0.3}"};
    const char *to[3] = {"[0.9, 0.9, 0.9], \"roughness\": 0.3}",
                         "\"refractiveindex\": 1.5, \"roughness\": 0.2}",
                         "\"refractiveindex\": 0.3, \"roughness\": 0.5}"};
    const char *src = box_text;
    size_t len = 0;
    while (*src) {
        int k = 0;
        while (k < 3 && strncmp(src, from[k], strlen(from[k])) != 0)
            k++;
        if (k < 3) {
            len += (size_t)snprintf(text + len, sizeof text - len, "%s", to[k]);
            src += strlen(from[k]);
        } else {
            text[len++] = *src++;
        }
    }
    text[len] = 0;
    assert_non_null(strstr(text, "\"roughness\": 0.5"));
    return text;
}

/* The box without its specular things, and three slats of a mesh near the
 * floor: diffuse light of levels >= 2 on the slats is gathered (gather.c),
 * which every rule below must keep. */
static const char *mesh_box_text(void)
{
    static char text[4096];
    if (text[0])
        return text;
    char obj[4096];
    size_t len = (size_t)snprintf(obj, sizeof obj, "vn 0 -1 0\n");
    for (int k = 0; k < 3; k++)
        len = test_obj_sheet(obj, len, sizeof obj, 2, 1.0, -4.2 + 0.4 * k, 1 + 9 * k);
    const char *path = test_write_file("slats.obj", obj);
    snprintf(text, sizeof text,
             "{\"scene\": ["
             "{\"lighttriangle\": {\"points\": [[-1, 4.9, -1], [1, 4.9, -1], [-1, 4.9, 1]], "
             "\"emission\": [8, 8, 7]}},"
             "{\"lighttriangle\": {\"points\": [[1, 4.9, 1], [-1, 4.9, 1], [1, 4.9, -1]], "
             "\"emission\": [6, 7, 8]}},"
             "{\"thing\": {\"material\": " DIFFUSE(0.7, 0.7, 0.7) ", \"parts\": ["
             "{\"triangle\": {\"points\": [[-5, -5, -5], [5, -5, 5], [5, -5, -5]]}},"
             "{\"triangle\": {\"points\": [[-5, -5, -5], [-5, -5, 5], [5, -5, 5]]}},"
             "{\"triangle\": {\"points\": [[-5, 5, -5], [5, 5, -5], [5, 5, 5]]}},"
             "{\"triangle\": {\"points\": [[-5, 5, -5], [5, 5, 5], [-5, 5, 5]]}},"
             "{\"triangle\": {\"points\": [[-5, -5, -5], [5, -5, -5], [5, 5, -5]]}},"
             "{\"triangle\": {\"points\": [[-5, -5, -5], [5, 5, -5], [-5, 5, -5]]}}]}},"
             "{\"thing\": {\"material\": " DIFFUSE(0.7, 0.15, 0.1) ", \"parts\": ["
             "{\"triangle\": {\"points\": [[-5, -5, -5], [-5, 5, -5], [-5, 5, 5]]}},"
             "{\"triangle\": {\"points\": [[-5, -5, -5], [-5, 5, 5], [-5, -5, 5]]}}]}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": false, \"material\": "
             DIFFUSE(0.6, 0.65, 0.7) "}}"
             "], \"camera\": {\"viewpoint\": [0.3, 0.2, 14], \"screen\": [[-1, 1, 13], "
             "[1, 1, 13], [-1, -1, 13], [1, -1, 13]], \"gridresolution\": [20, 16]}}",
             path);
    return text;
}

static zt_render_options zone_options(int depth, int threads)
{
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = depth;
    o.threads = threads;
    o.quality = 0;
    return o;
}

static zt_image *render(const zt_scene *s, const zt_render_options *o, zt_render_stats *stats)
{
    zt_image *img = NULL;
    zt_error err = {0};
    if (zt_render(s, o, &img, stats, &err) != ZT_OK)
        fail_msg("render failed: %s", err.message);
    return img;
}

static zt_renderer *renderer(const zt_scene *s, const zt_render_options *o)
{
    zt_renderer *r = NULL;
    zt_error err = {0};
    if (zt_renderer_create(s, o, &r, &err) != ZT_OK)
        fail_msg("renderer: %s", err.message);
    return r;
}

static zt_image *accumulate(zt_renderer *r, const zt_scene *s, zt_render_stats *stats)
{
    zt_camera cam = zt_scene_get_camera(s);
    zt_image *img = zt_image_create(cam.width, cam.height);
    assert_non_null(img);
    zt_error err = {0};
    if (zt_renderer_accumulate(r, 0, 1, img, stats, &err) != ZT_OK)
        fail_msg("accumulate: %s", err.message);
    return img;
}

static size_t floats(const zt_image *a) { return (size_t)a->width * a->height * 3; }

/* sqrt(mean((a-b)^2)) / mean(b), as `zonetrace compare` computes it. */
static double rel_rmse(const zt_image *a, const zt_image *b)
{
    double se = 0, sum = 0;
    size_t n = floats(a);
    for (size_t i = 0; i < n; i++) {
        double d = (double)a->pixels[i] - b->pixels[i];
        se += d * d;
        sum += b->pixels[i];
    }
    return sqrt(se / n) / (sum / n);
}

static double image_mean(const zt_image *a)
{
    double sum = 0;
    for (size_t i = 0; i < floats(a); i++)
        sum += a->pixels[i];
    return sum / floats(a);
}

/* ---------------------------------------------------------------------- */

static void test_deterministic(void **state)
{
    (void)state;
    zt_scene *s = scene_from(box_text);
    zt_render_options o1 = zone_options(2, 1), o2 = zone_options(2, 2);
    zt_image *a = render(s, &o2, NULL), *b = render(s, &o2, NULL), *c = render(s, &o1, NULL);
    assert_true(image_mean(a) > 0);
    test_assert_same_image(a, b, "two runs");
    test_assert_same_image(a, c, "1 vs 2 threads");
    zt_image_release(a);
    zt_image_release(b);
    zt_image_release(c);
    zt_scene_release(s);
}

/* One forest, four Phase Twos: both strategies at 1 and 2 threads (the
 * options are switched inside the renderer to spare Phase One). */
static void check_strategies(const char *text, int depth, int level)
{
    zt_scene *s = scene_from(text);
    zt_render_options o = zone_options(depth, 1);
    o.level = level;
    zt_renderer *r = renderer(s, &o);
    zt_image *img[4];
    for (int i = 0; i < 4; i++) {
        r->options.threads = 1 + i % 2;
        r->options.strategy = i < 2 ? ZT_STRATEGY_PIXEL : ZT_STRATEGY_ZONE;
        img[i] = accumulate(r, s, NULL);
    }
    assert_true(image_mean(img[0]) > 0);
    test_assert_same_image(img[0], img[1], "pixel strategy, 1 vs 2 threads");
    test_assert_same_image(img[0], img[2], "pixel vs zone strategy");
    test_assert_same_image(img[0], img[3], "pixel vs zone strategy, 2 threads");
    for (int i = 0; i < 4; i++)
        zt_image_release(img[i]);
    zt_renderer_release(r);
    zt_scene_release(s);
}

static void test_strategies_identical(void **state)
{
    (void)state;
    check_strategies(box_text, 3, -1);
    check_strategies(box_text, 2, 1);
    check_strategies(sky_box_text, 2, -1);
    check_strategies(mesh_box_text(), 3, -1);
    check_strategies(rough_box_text(), 3, -1);
}

/* The per-zone terms add up to one zone_radiance call per sample; the
 * mesh's samples gather, adding what their nodes keep apart. */
static void check_terms(const char *text, int depth, int apart)
{
    zt_scene *s = scene_from(text);
    zt_render_options o = zone_options(depth, 2);
    zt_renderer *r = renderer(s, &o);
    zt_image *terms = accumulate(r, s, NULL);
    assert_int_equal(r->forest->c != NULL, apart);
    zt_image *ref = zt_image_create(W, H);
    zt_error err = {0};
    assert_int_equal(zone_accumulate_reference(r, ref, &err), ZT_OK);
    double e = rel_rmse(terms, ref);
    if (!(e < 1e-5))
        fail_msg("terms vs plain shading: rel_rmse %g", e);
    zt_image_release(terms);
    zt_image_release(ref);
    zt_renderer_release(r);
    zt_scene_release(s);
}

static void test_terms_sum_to_shading(void **state)
{
    (void)state;
    check_terms(box_text, 3, 0);
    check_terms(sky_box_text, 2, 0);
    check_terms(mesh_box_text(), 3, 0);
    check_terms(rough_box_text(), 3, 0);
    check_terms(mesh_mirror_text(), 3, 1);
}

/* The images of levels 0..o.depth, rendered one by one, add up to `all`
 * (the depth image); each level but those below first_lit must be lit. */
static void assert_levels_sum(const zt_scene *s, zt_render_options o, const zt_image *all,
                              int first_lit, const char *what)
{
    zt_image *sum = zt_image_create(W, H);
    for (int l = 0; l <= o.depth; l++) {
        o.level = l;
        zt_image *li = render(s, &o, NULL);
        assert_true(l < first_lit || image_mean(li) > 0);
        for (size_t i = 0; i < floats(sum); i++)
            sum->pixels[i] += li->pixels[i];
        zt_image_release(li);
    }
    double e = rel_rmse(sum, all);
    if (!(e < 1e-5))
        fail_msg("%s 0..%d vs depth %d: rel_rmse %g", what, o.depth, o.depth, e);
    zt_image_release(sum);
}

static void test_levels_sum_to_depth(void **state)
{
    (void)state;
    const char *texts[2] = {box_text, mesh_box_text()};
    for (int i = 0; i < 2; i++) {
        zt_scene *s = scene_from(texts[i]);
        const int depth = 3;
        zt_render_options o = zone_options(depth, 2);
        zt_image *all = render(s, &o, NULL);
        assert_levels_sum(s, o, all, 1, i ? "levels, mesh box" : "levels");
        zt_image_release(all);
        zt_scene_release(s);
    }
}

/* Two triangles piercing each other (an X seen end on) under a point light
 * and a sky: their maps are cut along the line where they cross.  The cut
 * texels' other halves go into the forest file, and levels still add up. */
static const char *cross_text =
    "{\"scene\": [{\"sky\": {\"color\": [0.2, 0.1, 0.1]}},"
    "{\"lightpoint\": {\"point\": [1, 6, 3], \"emission\": [20, 20, 20]}},"
    "{\"triangle\": {\"points\": [[-4, -3, -4], [4, 3, -4], [0, 0, 4]], \"material\": "
    DIFFUSE(0.8, 0.5, 0.3) "}},"
    "{\"triangle\": {\"points\": [[-4, 3, -4], [4, -3, -4], [0, 0.5, 4]], \"material\": "
    DIFFUSE(0.3, 0.6, 0.8) "}}"
    /* from the side, as the triangles' planes nearly hold the z axis */
    "], \"camera\": {\"viewpoint\": [6, 5, 9], \"screen\": [[4.9109, 5.0797, 8.3578], "
    "[5.8261, 5.0797, 7.7476], [5.1669, 4.0812, 8.7418], [6.0821, 4.0812, 8.1317]], "
    "\"gridresolution\": [20, 16]}}";

static void test_crossings(void **state)
{
    (void)state;
    zt_scene *s = scene_from(cross_text);
    const int depth = 3;
    zt_render_options o = zone_options(depth, 2);
    zt_renderer *r = renderer(s, &o);
    const char *path = test_tmp_path("cross.forest");
    zt_error err = {0};
    assert_int_equal(zt_renderer_save_forest(r, path, &err), ZT_OK);
    zt_image *all = accumulate(r, s, NULL);
    zt_render_options lo = o;
    lo.forest_file = path;
    zt_image *loaded = render(s, &lo, NULL);
    test_assert_same_image(all, loaded, "crossings: built vs loaded forest");
    zt_image_release(loaded);
    assert_levels_sum(s, o, all, 0, "crossings: levels");
    zt_image_release(all);
    zt_renderer_release(r);
    zt_scene_release(s);
}

static void test_lights_add_up(void **state)
{
    (void)state;
    zt_scene *s = scene_from(box_text);
    zt_render_options o = zone_options(2, 2);
    o.quality = 2;
    zt_image *all = render(s, &o, NULL);
    o.lights_off_count = 1;
    o.lights_off[0] = 1;
    zt_image *a = render(s, &o, NULL);
    o.lights_off[0] = 0;
    zt_image *b = render(s, &o, NULL);
    assert_true(image_mean(a) > 0.1 * image_mean(all));
    assert_true(image_mean(b) > 0.1 * image_mean(all));
    for (size_t i = 0; i < floats(a); i++)
        a->pixels[i] += b->pixels[i];
    /* Each image is the forest of its own lights: the transfer's cut and
     * the node grids' refinement adapt to the light present, and a node
     * gathers or cuts by the light it holds (bounce_gather.h), so the parts
     * add up to the whole within those estimates' errors, not to the last
     * bit: measured 0.36% at quality 2 (the cuts alone: 0.05%), and 4.5% at
     * quality 0, whose 64 directions a node gathers with are few. */
    double e = rel_rmse(a, all);
    if (!(e < 5e-3))
        fail_msg("light 0 + light 1 vs both: rel_rmse %g", e);
    zt_image_release(a);
    zt_image_release(b);
    zt_image_release(all);
    zt_scene_release(s);
}

static void test_forest_round_trip(void **state)
{
    (void)state;
    zt_scene *s = scene_from(box_text);
    const char *path = test_tmp_path("box.forest");
    zt_render_options o = zone_options(3, 2);
    zt_renderer *r = renderer(s, &o);
    zt_error err = {0};
    assert_int_equal(zt_renderer_save_forest(r, path, &err), ZT_OK);
    zt_render_stats built_stats;
    zt_image *built = accumulate(r, s, &built_stats);
    assert_int_equal(built_stats.forest_loaded, 0);
    assert_true(built_stats.zones > 0 && built_stats.memory_bytes > 0);
    /* Depth 3 builds two transfer levels: a cut per computed node each. */
    assert_true(built_stats.cuts > 0 && built_stats.cuts_capped <= built_stats.cuts);
    /* Reported with the first image too (the renderer was made without
     * stats, as when the command line saves the forest first). */
    assert_true(built_stats.memory_estimate > 0);

    for (int strategy = 0; strategy < 2; strategy++) {
        zt_render_options lo = o;
        lo.forest_file = path;
        lo.strategy = strategy ? ZT_STRATEGY_ZONE : ZT_STRATEGY_PIXEL;
        lo.threads = 1 + strategy;
        zt_render_stats stats;
        zt_image *loaded = render(s, &lo, &stats);
        test_assert_same_image(built, loaded, "built vs loaded forest");
        assert_int_equal(stats.forest_loaded, 1);
        assert_int_equal(stats.cuts, 0); /* not kept in the file */
        assert_int_equal(stats.zones, built_stats.zones);
        assert_int_equal(stats.zones_pruned, built_stats.zones_pruned);
        assert_int_equal(stats.memory_bytes, built_stats.memory_bytes);
        for (int l = 0; l < 32; l++)
            assert_int_equal(stats.zones_per_level[l], built_stats.zones_per_level[l]);
        zt_image_release(loaded);
    }
    /* Saving a loaded forest gives the same file. */
    zt_render_options lo = o;
    lo.forest_file = path;
    zt_renderer *r2 = renderer(s, &lo);
    const char *path2 = test_tmp_path("box2.forest");
    assert_int_equal(zt_renderer_save_forest(r2, path2, &err), ZT_OK);
    test_assert_same_file(path, path2);
    zt_renderer_release(r2);

    /* A path-tracing renderer has no forest. */
    zt_render_options po = zt_render_options_default();
    po.spp = 1;
    zt_renderer *pr = renderer(s, &po);
    assert_int_equal(zt_renderer_save_forest(pr, path2, &err), ZT_ERR_ARGUMENT);
    zt_renderer_release(pr);

    zt_image_release(built);
    zt_renderer_release(r);
    zt_scene_release(s);
}

/* The Cornell box's nodes on the seams between walls move a quarter cell
 * into the room in Phase One; the reader must take them back. */
static void test_forest_round_trip_seams(void **state)
{
    (void)state;
    zt_scene *s = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_file(ZT_SOURCE_DIR "/scenes/cornell.json", &s, &err), ZT_OK);
    zt_camera cam = zt_scene_get_camera(s);
    assert_int_equal(zt_camera_set_resolution(&cam, 24, 24, &err), ZT_OK);
    zt_scene_set_camera(s, &cam);
    const char *path = test_tmp_path("cornell.forest");
    zt_render_options o = zone_options(2, 2);
    o.quality = 1;
    zt_renderer *r = renderer(s, &o);
    assert_int_equal(zt_renderer_save_forest(r, path, &err), ZT_OK);
    zt_image *built = accumulate(r, s, NULL);
    o.forest_file = path;
    zt_render_stats stats;
    zt_image *loaded = render(s, &o, &stats);
    assert_int_equal(stats.forest_loaded, 1);
    test_assert_same_image(built, loaded, "Cornell box: built vs loaded forest");
    zt_image_release(built);
    zt_image_release(loaded);
    zt_renderer_release(r);
    zt_scene_release(s);
}

/* Creating a renderer from path with options o must fail with status and a
 * message naming the file and containing what. */
static void expect_rejected(const zt_scene *s, zt_render_options o, const char *path,
                            zt_status status, const char *what)
{
    o.forest_file = path;
    zt_renderer *r = NULL;
    zt_error err = {0};
    zt_status st = zt_renderer_create(s, &o, &r, &err);
    if (st != status)
        fail_msg("loading %s: status %d (%s), expected %d", path, st, err.message, status);
    assert_null(r);
    if (!strstr(err.message, path) || !strstr(err.message, what))
        fail_msg("message '%s' lacks '%s' or the file name", err.message, what);
}

static void write_bytes(const char *path, const char *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static void test_forest_rejections(void **state)
{
    (void)state;
    zt_scene *s = scene_from(box_text), *other = scene_from(other_box_text);
    const char *path = test_tmp_path("reject.forest");
    zt_render_options o = zone_options(2, 2);
    zt_renderer *r = renderer(s, &o);
    zt_error err = {0};
    assert_int_equal(zt_renderer_save_forest(r, path, &err), ZT_OK);
    zt_renderer_release(r);

    expect_rejected(other, o, path, ZT_ERR_PARSE, "another scene");
    zt_render_options x = o;
    x.depth = 3;
    expect_rejected(s, x, path, ZT_ERR_PARSE, "depth 2");
    x = o;
    x.cutoff = 0.5;
    expect_rejected(s, x, path, ZT_ERR_PARSE, "cutoff");
    x = o;
    x.quality = 1;
    expect_rejected(s, x, path, ZT_ERR_PARSE, "quality");
    x = o;
    x.lights_off_count = 1;
    x.lights_off[0] = 1;
    expect_rejected(s, x, path, ZT_ERR_PARSE, "lights off");
    expect_rejected(s, o, test_tmp_path("missing.forest"), ZT_ERR_READ, "cannot open");

    size_t n;
    char *data = test_read_file(path, &n);
    assert_non_null(data);
    const char *bad = test_tmp_path("bad.forest");
    write_bytes(bad, data, n / 2);
    expect_rejected(s, o, bad, ZT_ERR_PARSE, "truncated");
    write_bytes(bad, data, 10);
    expect_rejected(s, o, bad, ZT_ERR_PARSE, "truncated");
    data[n / 2] ^= 0x10;
    write_bytes(bad, data, n);
    expect_rejected(s, o, bad, ZT_ERR_PARSE, "corrupt");
    data[n / 2] ^= 0x10;
    data[8] = 99; /* the format version */
    write_bytes(bad, data, n);
    expect_rejected(s, o, bad, ZT_ERR_PARSE, "version 99");
    write_bytes(bad, "{\"scene\": []}", 13);
    expect_rejected(s, o, bad, ZT_ERR_PARSE, "not a zonetrace forest file");
    free(data);

    /* The camera is not part of the forest: another view loads it. */
    zt_camera cam = zt_scene_get_camera(s);
    cam.viewpoint[0] += 1;
    cam.width = 12;
    cam.height = 10;
    zt_scene_set_camera(s, &cam);
    o.forest_file = path;
    r = renderer(s, &o);
    zt_renderer_release(r);
    zt_scene_release(other);
    zt_scene_release(s);
}

static void test_camera_moves_without_phase_one(void **state)
{
    (void)state;
    zt_scene *s = scene_from(box_text);
    zt_render_options o = zone_options(2, 2);
    zt_renderer *r = renderer(s, &o);
    const void *forest = r->forest;
    zt_render_stats st1, st2;
    zt_image *a = accumulate(r, s, &st1);
    assert_true(st1.phase_one_seconds > 0);

    zt_camera cam = zt_scene_get_camera(s);
    for (int k = 0; k < 4; k++) {
        cam.screen[k][0] += 0.8;
        cam.screen[k][1] -= 0.3;
    }
    cam.viewpoint[0] += 0.8;
    cam.viewpoint[1] -= 0.3;
    zt_error err = {0};
    assert_int_equal(zt_renderer_set_camera(r, &cam, &err), ZT_OK);
    zt_scene_set_camera(s, &cam);
    zt_image *b = accumulate(r, s, &st2);
    assert_ptr_equal(r->forest, forest);
    assert_true(st2.phase_one_seconds == 0.0);
    assert_true(st2.phase_two_seconds > 0);
    assert_true(rel_rmse(a, b) > 1e-3); /* the view did change */

    /* The moved view from a saved forest: the same bytes. */
    const char *path = test_tmp_path("moved.forest");
    assert_int_equal(zt_renderer_save_forest(r, path, &err), ZT_OK);
    o.forest_file = path;
    o.strategy = ZT_STRATEGY_ZONE;
    zt_renderer *r2 = renderer(s, &o);
    zt_image *c = accumulate(r2, s, NULL);
    test_assert_same_image(b, c, "moved camera: kept vs loaded forest");
    zt_image_release(a);
    zt_image_release(b);
    zt_image_release(c);
    zt_renderer_release(r2);
    zt_renderer_release(r);
    zt_scene_release(s);
}

/* The command line: --save-forest, --load-forest, -v statistics. */
/* Phase Two's time split (zt_render_stats): every pixel counted once, by
 * the kind its samples say, and no more thread-seconds than the threads
 * had in Phase Two. */
static void check_split(const zt_render_stats *st, int pixels, int threads, int shaded)
{
    uint64_t all = 0;
    double spent = st->p2_lists_seconds + st->p2_records_seconds;
    for (int k = 0; k < ZT_PIXEL_KINDS; k++) {
        all += st->p2_pixels[k];
        spent += st->p2_shade_seconds[k];
        assert_true(st->p2_shade_seconds[k] >= 0.0);
        assert_true(st->p2_samples[k] >= st->p2_pixels[k]);
    }
    assert_int_equal(all, shaded ? (uint64_t)pixels : 0);
    assert_true(st->p2_lists_seconds > 0.0);
    assert_true(spent <= threads * st->phase_two_seconds + 1e-9);
    /* The kinds' sample counts are the design's (quality 0: one sample on
     * a smooth surface). */
    assert_int_equal(st->p2_samples[ZT_PIXEL_ONE], st->p2_pixels[ZT_PIXEL_ONE]);
    assert_int_equal(st->p2_samples[ZT_PIXEL_CURVED], 4 * st->p2_pixels[ZT_PIXEL_CURVED]);
    /* A detail pixel's 2 x 2 blocks on one facet are shaded once each. */
    assert_true(st->p2_samples[ZT_PIXEL_DETAIL] >= 16 * st->p2_pixels[ZT_PIXEL_DETAIL]);
    assert_true(st->p2_samples[ZT_PIXEL_DETAIL] <= 64 * st->p2_pixels[ZT_PIXEL_DETAIL]);
    assert_int_equal(st->p2_samples[ZT_PIXEL_SHADOW], 4 * st->p2_pixels[ZT_PIXEL_SHADOW]);
}

static void test_phase_two_split(void **state)
{
    (void)state;
    zt_scene *s = scene_from(mesh_box_text());
    zt_render_options o = zone_options(2, 2);
    zt_render_stats st;
    zt_image *img = render(s, &o, &st);
    check_split(&st, 20 * 16, 2, 1);
    print_message("split: one %llu, detail %llu, shadow %llu, edge %llu, fine %llu pixels\n",
                  (unsigned long long)st.p2_pixels[ZT_PIXEL_ONE],
                  (unsigned long long)st.p2_pixels[ZT_PIXEL_DETAIL],
                  (unsigned long long)st.p2_pixels[ZT_PIXEL_SHADOW],
                  (unsigned long long)st.p2_pixels[ZT_PIXEL_EDGE],
                  (unsigned long long)st.p2_pixels[ZT_PIXEL_FINE]);
    /* The box's walls meet along edges; the slats are a mesh. */
    assert_true(st.p2_pixels[ZT_PIXEL_ONE] > 0);
    assert_true(st.p2_pixels[ZT_PIXEL_EDGE] > 0);
    assert_true(st.p2_records_seconds > 0.0);
    zt_image_release(img);
    /* The zone strategy finds the same samples but shades zone by zone:
     * its shading is not split. */
    o.strategy = ZT_STRATEGY_ZONE;
    img = render(s, &o, &st);
    check_split(&st, 20 * 16, 2, 0);
    zt_image_release(img);
    zt_scene_release(s);
}

/* A flat sheet seen at a grazing angle under the Preetham sky and the
 * sun: its pixels are mesh detail pixels (the distance spreads across
 * each), whose 2 x 2 blocks on the one facet are each shaded by one
 * sample standing for the four (samples.c).  Nothing is in the way of the
 * sky, so every point of the sheet receives the open surface's irradiance
 * exactly, whatever share of the directions it takes: the sheet must come
 * out as bright as the same sheet written as a plane (one sample a pixel),
 * which a block's sample weighing its share of the sky wrongly (its four
 * samples' directions against one's) would miss by a factor of 4. */
static void test_detail_blocks_under_sky(void **state)
{
    (void)state;
    char obj[4096];
    size_t len = (size_t)snprintf(obj, sizeof obj, "vn 0 1 0\n");
    const int n = 8;
    for (int i = 0; i <= n; i++)
        for (int j = 0; j <= n; j++)
            len += (size_t)snprintf(obj + len, sizeof obj - len, "v %g 0 %g\n", -40.0 + 10.0 * j,
                                    -40.0 + 10.0 * i);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            int a = 1 + i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
            len += (size_t)snprintf(obj + len, sizeof obj - len,
                                    "f %d//1 %d//1 %d//1\nf %d//1 %d//1 %d//1\n", a, c, d, a, d, b);
        }
    const char *path = test_write_file("sheet.obj", obj);
    const char *head = "{\"camera\": {\"position\": [0, 0.5, 20], \"lookat\": [0, 0, 0], "
                       "\"fov\": 30, \"gridresolution\": [24, 16]}, \"scene\": ["
                       "{\"sun\": {\"direction\": [0.3, 0.8, 0.2], \"irradiance\": [2, 2, 2]}},"
                       "{\"sky\": {\"model\": \"preetham\", \"turbidity\": 3}},";
    char mesh_text[1024], plane_text[1024];
    snprintf(mesh_text, sizeof mesh_text,
             "%s{\"mesh\": {\"file\": \"%s\", \"material\": " DIFFUSE(0.5, 0.5, 0.5) "}}]}",
             head, path);
    snprintf(plane_text, sizeof plane_text,
             "%s{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, \"material\": "
             DIFFUSE(0.5, 0.5, 0.5) "}}]}",
             head);
    zt_scene *mesh = scene_from(mesh_text), *plane = scene_from(plane_text);
    zt_render_options o = zone_options(1, 2);
    o.level = 1;
    zt_render_stats st;
    zt_image *a = render(mesh, &o, &st);
    zt_image *b = render(plane, &o, NULL);
    assert_true(st.p2_pixels[ZT_PIXEL_DETAIL] > 0);
    assert_true(st.p2_samples[ZT_PIXEL_DETAIL] < 64 * st.p2_pixels[ZT_PIXEL_DETAIL]);
    /* The bottom rows see the sheet alone (well inside its 80 x 80). */
    double worst = 0;
    for (int y = 10; y < 16; y++)
        for (int x = 0; x < 24; x++)
            for (int c = 0; c < 3; c++) {
                size_t i = ((size_t)y * 24 + (size_t)x) * 3 + (size_t)c;
                double rel = fabs(a->pixels[i] - b->pixels[i]) / b->pixels[i];
                worst = rel > worst ? rel : worst;
            }
    print_message("detail pixels %llu (%llu samples); the sheet against the plane: %.2e\n",
                  (unsigned long long)st.p2_pixels[ZT_PIXEL_DETAIL],
                  (unsigned long long)st.p2_samples[ZT_PIXEL_DETAIL], worst);
    assert_true(worst < 1e-3);
    zt_image_release(a);
    zt_image_release(b);
    zt_scene_release(mesh);
    zt_scene_release(plane);
}

static void test_cli(void **state)
{
    (void)state;
    const char *scene = test_write_file("cli_box.json", box_text);
    char forest[512], a[512], b[512], args[2048];
    snprintf(forest, sizeof forest, "%s", test_tmp_path("cli.forest"));
    snprintf(a, sizeof a, "%s", test_tmp_path("cli_a.pfm"));
    snprintf(b, sizeof b, "%s", test_tmp_path("cli_b.pfm"));
    char *out = NULL;
    snprintf(args, sizeof args, "render '%s' --method zone --depth 2 --quality 0 -o '%s' "
             "--save-forest '%s' -v", scene, a, forest);
    int code = test_run_cli(args, &out);
    if (code != 0)
        fail_msg("render --save-forest: exit %d: %s", code, out ? out : "");
    assert_non_null(strstr(out, "zones: level 0: 2"));
    assert_non_null(strstr(out, "pruned"));
    assert_non_null(strstr(out, "forest memory"));
    assert_non_null(strstr(out, "phase one"));
    free(out);
    snprintf(args, sizeof args, "render '%s' --method zone --depth 2 --quality 0 -o '%s' "
             "--load-forest '%s' --strategy zone -v", scene, b, forest);
    code = test_run_cli(args, &out);
    if (code != 0)
        fail_msg("render --load-forest: exit %d: %s", code, out ? out : "");
    assert_non_null(strstr(out, "read from"));
    free(out);
    test_assert_same_file(a, b);
    /* Other options: exit 3 (invalid input) with the reason. */
    snprintf(args, sizeof args, "render '%s' --method zone --depth 3 --quality 0 -o '%s' "
             "--load-forest '%s'", scene, b, forest);
    code = test_run_cli(args, &out);
    assert_int_equal(code, 3);
    assert_non_null(strstr(out, "other options"));
    free(out);
    snprintf(args, sizeof args, "render '%s' --method path -o '%s' --load-forest '%s'", scene,
             b, forest);
    code = test_run_cli(args, &out);
    assert_int_equal(code, 1);
    free(out);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_strategies_identical),
        cmocka_unit_test(test_terms_sum_to_shading),
        cmocka_unit_test(test_levels_sum_to_depth),
        cmocka_unit_test(test_lights_add_up),
        cmocka_unit_test(test_forest_round_trip),
        cmocka_unit_test(test_forest_round_trip_seams),
        cmocka_unit_test(test_crossings),
        cmocka_unit_test(test_forest_rejections),
        cmocka_unit_test(test_camera_moves_without_phase_one),
        cmocka_unit_test(test_phase_two_split),
        cmocka_unit_test(test_detail_blocks_under_sky),
        cmocka_unit_test(test_cli),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
