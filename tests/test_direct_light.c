/* Exact direct light where the shadows are too busy to clip
 * (zone/light/direct.h): a triangle light over a floor, with a comb of
 * 2,500 small separate triangles between them (an OBJ mesh), so that a floor
 * point under it has far more occluders than clipping takes and sees the
 * light by rays.  Checked: the occluder search stops once it has more than
 * it may return; the by-rays test says which points see the light by rays;
 * the four split points (direct_irradiance_split, which Phase Two's
 * sub-pixel samples use) together see what one point sees, within stated
 * bounds, against a 64 times finer reference (which one 4 times coarser,
 * added up the other way, confirms); and split points, which always see
 * the light by rays, agree with the exact cut where few occluders or none
 * stand in the way.  The sky's gather shares its directions among split
 * points the same way: a block of them sees, between them, what one point
 * sees.  A lamp cut into 64 triangles costs a point about the rays of the
 * lamp whole, for about its accuracy.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/shapes.h"
#include "render/render_internal.h"
#include "zone/light/direct.h"
#include "zone/light/lambert.h"
#include "zone/light/occluders.h"
#include "zone/light/sky_gather.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define TEETH 50    /* a side of the comb */
#define PITCH 0.2
#define TOOTH 0.12  /* a tooth's legs */
#define COMB_Y 7.0

static const char *write_comb(void)
{
    size_t cap = (size_t)TEETH * TEETH * 2 * 120 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t len = 0;
    int v = 1;
    for (int i = 0; i < TEETH; i++)
        for (int j = 0; j < TEETH; j++) {
            double x = -5.0 + PITCH * i, z = -5.0 + PITCH * j;
            len += (size_t)snprintf(text + len, cap - len,
                                    "v %g %g %g\nv %g %g %g\nv %g %g %g\nf %d %d %d\n", x,
                                    COMB_Y, z, x + TOOTH, COMB_Y, z, x, COMB_Y, z + TOOTH, v,
                                    v + 1, v + 2);
            v += 3;
        }
    const char *path = test_write_file("direct_comb.obj", text);
    free(text);
    return path;
}

#define TRIANGLE_LIGHT                                                                         \
    "{\"light\": {\"emission\": [10, 10, 10], \"backculled\": false, \"parts\": ["             \
    "{\"lighttriangle\": {\"points\": [[-2, 10, -2], [2, 10, -2], [0, 10, 2]]}}]}},"
#define SPHERE_LIGHT                                                                           \
    "{\"lightsphere\": {\"center\": [0, 10, 0], \"radius\": 1.5, \"emission\": [10, 10, 10]}},"

#define COLOUR_SKY "{\"sky\": {\"color\": [0.3, 0.5, 0.9]}},"
#define MODEL_SKY "{\"sky\": {\"model\": \"preetham\", \"turbidity\": 3, " \
                  "\"sun_direction\": [0.3, 1, 0.2]}},"

/* The comb under `light`, one of those above. */
static zt_renderer *comb_renderer(zt_scene **scene_out, const char *light)
{
    static char text[20480];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [0, 8, -30], \"lookat\": [0, 0, 0], "
             "\"up\": [0, 1, 0], \"fov\": 50, \"gridresolution\": [8, 8]}, \"scene\": [%s"
             "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.5) "}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": false, \"backculled\": false, "
             TEST_DIFFUSE(0.5) "}}]}",
             light, write_comb());
    zt_scene *scene = test_scene_text(text, "direct_comb.json");
    *scene_out = scene;
    return test_zone_renderer(scene, 1, 1, zt_render_options_default().quality);
}

/* The comb under `light`, with its one light part and its floor. */
static zt_renderer *comb_lit(const char *light, zt_scene **scene, int *light_part,
                             int *floor_part)
{
    zt_renderer *r = comb_renderer(scene, light);
    assert_int_equal(r->rs.light_count, 1);
    *light_part = r->rs.lights[0].part;
    *floor_part = -1;
    for (int i = 0; i < r->rs.part_count; i++)
        if (r->rs.parts[i].shape == SHAPE_PLANE)
            *floor_part = i;
    assert_true(*floor_part >= 0);
    return r;
}

/* Where nothing stands between x and the light, a split point, which sees
 * by rays whatever the search would find, sees all of it: Lambert's formula
 * over the whole light, as the exact cut takes. */
static void assert_splits_see_all(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver)
{
    double exact = direct_irradiance(c, light, x, n, receiver);
    assert_true(exact > 0);
    for (int j = 1; j <= 3; j++)
        for (int i = 0; i < 1 << (2 * j); i++)
            assert_true(fabs(direct_irradiance_split(c, light, x, n, receiver,
                                                     DIRECT_SPLIT(j, i)) -
                             exact) <= 1e-9 * exact);
}

/* The mean of the 4^levels points of a block that share one point's rays,
 * all at x. */
static double split_mean(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver, int levels)
{
    int count = 1 << (2 * levels);
    double mean = 0;
    for (int i = 0; i < count; i++)
        mean += direct_irradiance_split(c, light, x, n, receiver, DIRECT_SPLIT(levels, i)) / count;
    return mean;
}

static void test_query_stops_past_max(void **state)
{
    (void)state;
    zt_scene *scene;
    zt_renderer *r = comb_renderer(&scene, TRIANGLE_LIGHT);
    const occluder_index *ix = r->forest->direct.occ;
    occ_region all = {v3(-100, -100, -100), v3(100, 100, 100), 0, {{0, 0, 0}}, {0}};
    int32_t out[DIRECT_MAX_OCCLUDERS];
    /* The comb's 2,500 teeth and the light: more than max. */
    assert_int_equal(occluders_query(ix, &all, out, 10), 11);
    /* A region around one tooth: all of them, in ascending order. */
    occ_region one = {v3(-5.01, COMB_Y - 0.01, -5.01), v3(-4.95, COMB_Y + 0.01, -4.95), 0,
                      {{0, 0, 0}}, {0}};
    int n = occluders_query(ix, &one, out, DIRECT_MAX_OCCLUDERS);
    assert_true(n >= 1 && n <= DIRECT_MAX_OCCLUDERS);
    for (int k = 1; k < n; k++)
        assert_true(out[k - 1] < out[k]);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

static void test_splits_share_the_rays(void **state)
{
    (void)state;
    zt_scene *scene;
    int light, floor_part;
    zt_renderer *r = comb_lit(TRIANGLE_LIGHT, &scene, &light, &floor_part);
    const direct_ctx *c = &r->forest->direct;
    direct_ctx fine = *c, kept = *c;
    fine.fallback = 64 * c->fallback;
    /* Up to 1,024 pieces the rays' results are kept and the smaller side
     * weighed; past them (the fine reference) each seen piece is weighed as
     * its ray returns.  The two ways must agree to the pieces' size. */
    kept.fallback = 16 * c->fallback;
    vec3 up = v3(0, 1, 0);

    /* Under the comb: seen by rays.  Points across one tooth's shadow. */
    double worst_split = 0, worst_one = 0, worst_fine = 0, worst_block[3] = {0, 0, 0};
    int points = 0;
    for (int i = 0; i < 8; i++) {
        vec3 x = v3(0.01 + 0.025 * i, 0, 0.02 + 0.01 * i);
        assert_true(direct_by_rays(c, light, x, up));
        double one = direct_irradiance(c, light, x, up, floor_part);
        double ref = direct_irradiance(&fine, light, x, up, floor_part);
        double ref_kept = direct_irradiance(&kept, light, x, up, floor_part);
        worst_fine = fmax(worst_fine, fabs(ref_kept - ref) / ref);
        assert_true(ref > 0);
        worst_one = fmax(worst_one, fabs(one - ref) / ref);
        /* A block of 4, 16 or 64 points sees the centres one point sees;
         * they differ only by the weights of the centres within a piece (a
         * block of 64 takes the whole triangle as its piece). */
        for (int j = 1; j <= 3; j++) {
            double mean = split_mean(c, light, x, up, floor_part, j);
            worst_split = fmax(worst_split, fabs(mean - ref) / ref);
            worst_block[j - 1] = fmax(worst_block[j - 1], fabs(mean - one) / one);
        }
        points++;
    }
    printf("%d points under the comb: one point %.2f%%, blocks of 4/16/64 splits %.2f%% from "
           "the fine reference at worst (%.2f%% / %.2f%% / %.2f%% from the one point); one 4 "
           "times coarser %.2f%% from it\n",
           points, 100 * worst_one, 100 * worst_split, 100 * worst_block[0],
           100 * worst_block[1], 100 * worst_block[2], 100 * worst_fine);
    for (int j = 0; j < 3; j++)
        assert_true(worst_block[j] <= 0.03);
    assert_true(worst_split < 0.10);
    assert_true(worst_fine < 0.05); /* 2.1% measured: the pieces' size */

    /* Beside the comb, nothing between the point and the light: clipped
     * exactly, and all of it seen by the split points. */
    vec3 x = v3(30, 0, 0.5);
    assert_false(direct_by_rays(c, light, x, up));
    assert_splits_see_all(c, light, x, up, floor_part);
    /* At the comb's edge a few teeth, few enough to clip, hide 3% of the
     * light: the split points by rays agree with the exact value to the
     * pieces' size (0.6% measured). */
    x = v3(18, 0, 0.5);
    assert_false(direct_by_rays(c, light, x, up));
    double exact = direct_irradiance(c, light, x, up, floor_part);
    vec3 tri[3] = {v3(-2, 10, -2), v3(2, 10, -2), v3(0, 10, 2)};
    double open = lambert_polygon(x, up, tri, 3); /* the light unhidden */
    double mean = split_mean(c, light, x, up, floor_part, 1);
    printf("at the comb's edge: unhidden %.5g, exact %.5g, split points by rays %.5g (%.2f%%)\n",
           open, exact, mean, 100 * fabs(mean - exact) / exact);
    assert_true(exact > 0.5 * open && exact < 0.99 * open);
    assert_true(fabs(mean - exact) <= 0.02 * exact);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

/* A sphere light's pieces lie on its silhouette's disc, inside the
 * sphere: seen by rays, the light must not hide itself.  Beside the comb a
 * split point sees all of it, as the exact cut does; under the comb, by
 * rays, what the teeth leave of it. */
static void test_sphere_light_by_rays(void **state)
{
    (void)state;
    zt_scene *scene;
    int light, floor_part;
    zt_renderer *r = comb_lit(SPHERE_LIGHT, &scene, &light, &floor_part);
    const direct_ctx *c = &r->forest->direct;
    vec3 up = v3(0, 1, 0);
    assert_splits_see_all(c, light, v3(30, 0, 0.5), up, floor_part);
    vec3 x = v3(0.01, 0, 0.02);
    assert_true(direct_by_rays(c, light, x, up));
    double under = direct_irradiance(c, light, x, up, floor_part);
    /* Unhidden, a sphere of radius r at distance D straight above gives
     * pi (r / D)^2 per unit radiance; the comb's teeth cover 18% of its
     * plane. */
    vec3 d = v3_sub(v3(0, 10, 0), x);
    double unhidden = 3.14159265358979 * 1.5 * 1.5 / v3_dot(d, d) * d.y / v3_length(d);
    printf("sphere light under the comb, by rays: %.5g, unhidden %.5g (%.1f%% seen)\n", under,
           unhidden, 100 * under / unhidden);
    assert_true(under > 0.6 * unhidden && under < 0.95 * unhidden);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

/* The sky's gather (zone_sky_irradiance) at x for split point `split`. */
static vec3 sky_at(const zt_renderer *r, vec3 x, vec3 n, int split)
{
    zone_trace t = {.f = r->forest, .r = r};
    t.light_split = split;
    return zone_sky_irradiance(&t, x, n);
}

/* The mean of a block of 4^levels split points' sky gathers, all at x,
 * against one point's; returns the largest relative difference of a
 * channel, and sets *spread to the largest one point's of the block. */
static double sky_block(const zt_renderer *r, vec3 x, vec3 n, int levels, double *spread)
{
    vec3 one = sky_at(r, x, n, 0);
    int count = 1 << (2 * levels);
    vec3 mean = v3(0, 0, 0);
    *spread = 0;
    for (int i = 0; i < count; i++) {
        vec3 e = sky_at(r, x, n, DIRECT_SPLIT(levels, i));
        mean = v3_add(mean, v3_scale(e, 1.0 / count));
        *spread = fmax(*spread, fabs(e.y - one.y) / one.y);
    }
    return fmax(fabs(mean.x - one.x) / one.x,
                fmax(fabs(mean.y - one.y) / one.y, fabs(mean.z - one.z) / one.z));
}

/* Under the comb (part of the sky hidden) and beside it (none hidden),
 * under a sky of one colour (fixed directions about the normal) and under
 * the Preetham sky's map (directions drawn from it): a block of 4, 16 or 64
 * split points together sees what one point sees, for one point's rays.
 * Its points differ from each other (each sees its own directions) except
 * under the open colour sky, where every direction escapes. */
static void test_sky_splits_share_the_directions(void **state)
{
    (void)state;
    const char *skies[2] = {COLOUR_SKY, MODEL_SKY};
    vec3 up = v3(0, 1, 0), under = v3(0.01, 0, 0.02), beside = v3(30, 0, 0.5);
    for (int k = 0; k < 2; k++) {
        char light[256];
        snprintf(light, sizeof light, "%s%s", skies[k], TRIANGLE_LIGHT);
        zt_scene *scene;
        zt_renderer *r = comb_renderer(&scene, light);
        assert_true(r->forest->sky);
        assert_int_equal(r->forest->sky_set.count > 0, k == 1);
        double worst = 0, spread_under = 0, spread_beside = 0;
        for (int j = 1; j <= 3; j++) {
            double s;
            worst = fmax(worst, sky_block(r, under, up, j, &s));
            spread_under = fmax(spread_under, s);
            worst = fmax(worst, sky_block(r, beside, up, j, &s));
            spread_beside = fmax(spread_beside, s);
        }
        vec3 hidden = sky_at(r, under, up, 0), open = sky_at(r, beside, up, 0);
        printf("%s sky: under the comb %.1f%% of the open sky's light; blocks of split points "
               "%.2g from one point at worst; a split point %.0f%% (under) and %.0f%% (beside) "
               "from it at most\n",
               k ? "Preetham" : "colour", 100 * hidden.y / open.y, worst, 100 * spread_under,
               100 * spread_beside);
        assert_true(hidden.y < 0.95 * open.y); /* the comb hides some */
        assert_true(worst < 1e-5);             /* float sums in another order */
        assert_true(spread_under > 0.01);      /* each point its own directions */
        if (k == 0)
            assert_true(spread_beside < 1e-6);
        zt_renderer_release(r);
        zt_scene_release(scene);
    }
}

/* A pane (light passes part of it) is no shadow that clipping can draw, so
 * a point it may shade sees the light by rays (direct_rays_take counts
 * them); a point whose pyramid to the light it misses is clipped exactly, though the pane's box
 * (what the occluder index tests) holds that pyramid: a long diagonal
 * sliver of glass halfway up, across the floor. */
static void test_pane_beside_the_pyramid(void **state)
{
    (void)state;
    zt_scene *scene = test_scene_text(
        "{\"camera\": {\"position\": [0, 8, -30], \"lookat\": [0, 0, 0], "
        "\"up\": [0, 1, 0], \"fov\": 50, \"gridresolution\": [8, 8]}, \"scene\": ["
        TRIANGLE_LIGHT
        "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.5) "}},"
        "{\"triangle\": {\"points\": [[-10, 5, -10.5], [-10, 5, -9.5], [10, 5, 10]], "
        "\"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 0, "
        "\"refractive\": 1}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5, "
        "\"thin\": true}}}]}",
        "direct_pane.json");
    zt_renderer *r = test_zone_renderer(scene, 1, 1, zt_render_options_default().quality);
    assert_int_equal(r->rs.light_count, 1);
    assert_true(r->rs.pane_count == 1);
    int light = r->rs.lights[0].part, floor_part = -1;
    for (int i = 0; i < r->rs.part_count; i++)
        if (r->rs.parts[i].shape == SHAPE_PLANE)
            floor_part = i;
    const direct_ctx *c = &r->forest->direct;
    vec3 up = v3(0, 1, 0), tri[3] = {v3(-2, 10, -2), v3(2, 10, -2), v3(0, 10, 2)};
    /* Under the sliver: by rays, which see through the glass (less its
     * reflection, so less than the open light). */
    vec3 under = v3(0, 0, 0.2);
    direct_rays_take();
    double seen = direct_irradiance(c, light, under, up, floor_part);
    assert_true(direct_rays_take() > 0);
    double open = lambert_polygon(under, up, tri, 3);
    assert_true(seen > 0.5 * open && seen < 0.99 * open);
    /* Beside it: the sliver's box holds the pyramid, the sliver does not
     * meet it; clipped exactly, all of the light. */
    vec3 beside = v3(8, 0, -8);
    double exact = direct_irradiance(c, light, beside, up, floor_part);
    assert_true(direct_rays_take() == 0);
    open = lambert_polygon(beside, up, tri, 3);
    assert_true(fabs(exact - open) <= 1e-9 * open);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

/* Triangle (a, b, c) cut into 4^levels triangles by midpoints, as light
 * parts appended to out: a lamp as a model writes it.  At 64 parts it has
 * more than are taken one by one (ZONE_LIGHTS_EXACT): the light tree's
 * cut opens them. */
static void cut_triangle(char *out, size_t cap, size_t *len, const double a[3],
                         const double b[3], const double c[3], int levels)
{
    if (levels == 0) {
        *len += (size_t)snprintf(out + *len, cap - *len,
                                 "%s{\"lighttriangle\": {\"points\": [[%g, %g, %g], [%g, %g, "
                                 "%g], [%g, %g, %g]]}}",
                                 *len && out[*len - 1] == '}' ? ", " : "", a[0], a[1], a[2],
                                 b[0], b[1], b[2], c[0], c[1], c[2]);
        return;
    }
    double ab[3], bc[3], ca[3];
    for (int i = 0; i < 3; i++) {
        ab[i] = 0.5 * (a[i] + b[i]);
        bc[i] = 0.5 * (b[i] + c[i]);
        ca[i] = 0.5 * (c[i] + a[i]);
    }
    cut_triangle(out, cap, len, a, ab, ca, levels - 1);
    cut_triangle(out, cap, len, ab, b, bc, levels - 1);
    cut_triangle(out, cap, len, ca, bc, c, levels - 1);
    cut_triangle(out, cap, len, ab, bc, ca, levels - 1);
}

/* zone_lights_at at x, with the rays it cast (the cut's and by_rays'). */
static vec3 lights_at(const zt_renderer *r, int receiver, vec3 x, vec3 n, uint64_t *rays)
{
    zone_trace t = {.f = r->forest, .r = r};
    direct_rays_take();
    vec3 e = zone_lights_at(&t, receiver, x, n);
    *rays = t.rays + direct_rays_take();
    return e;
}

/* A lamp cut into many parts costs a point about the rays of the lamp
 * whole, for about its accuracy: each part that the point sees by rays
 * takes the fallback's rays by its share of the light
 * (direct_rays_by_share), not the fallback's all.  Under the comb and
 * beside it, against the whole lamp's light cut 4,096 ways. */
static void test_lamp_cut_into_parts(void **state)
{
    (void)state;
    /* A lamp large enough that its parts' pyramids over the comb's middle
     * meet more teeth than clipping takes: the whole, and in 64 parts. */
    const double a[3] = {-12, 10, -12}, b[3] = {12, 10, -12}, c[3] = {0, 10, 12};
    static char lamps[2][16384];
    for (int levels = 0; levels <= 3; levels += 3) {
        char *light = lamps[levels > 0];
        size_t len = (size_t)snprintf(light, sizeof lamps[0],
                                      "{\"light\": {\"emission\": [10, 10, 10], "
                                      "\"backculled\": false, \"parts\": [");
        cut_triangle(light, sizeof lamps[0], &len, a, b, c, levels);
        snprintf(light + len, sizeof lamps[0] - len, "]}},");
    }
    zt_scene *one_scene, *cut_scene;
    int one_light, floor_part;
    zt_renderer *one = comb_lit(lamps[0], &one_scene, &one_light, &floor_part);
    zt_renderer *cut = comb_renderer(&cut_scene, lamps[1]);
    assert_int_equal(cut->rs.light_count, 64);
    int cut_floor = -1;
    for (int i = 0; i < cut->rs.part_count; i++)
        if (cut->rs.parts[i].shape == SHAPE_PLANE)
            cut_floor = i;
    assert_true(cut_floor >= 0);
    assert_true(cut->forest->light_tree.elem_count >= 64);
    const direct_ctx *dc = &one->forest->direct;
    vec3 up = v3(0, 1, 0);
    const vec3 at[6] = {v3(0.01, 0, 0.02), v3(1.3, 0, -0.7), v3(30, 0, 0.5),
                        v3(3.1, 0, 2.3),   v3(-4, 0, 4),     v3(6, 0, -1)};
    for (int k = 0; k < 6; k++) {
        double ref =
            10 * direct_irradiance_rays(dc, one_light, at[k], up, floor_part, 0, 4096).y;
        uint64_t rays_one, rays_cut;
        double e_one = lights_at(one, floor_part, at[k], up, &rays_one).y;
        double e_cut = lights_at(cut, cut_floor, at[k], up, &rays_cut).y;
        printf("lamp whole / in 64 parts at (%g, %g): %.5g / %.5g against %.5g, %llu / %llu "
               "rays\n",
               at[k].x, at[k].z, e_one, e_cut, ref, (unsigned long long)rays_one,
               (unsigned long long)rays_cut);
        assert_true(ref > 0);
        /* The parts are no further from the reference than the whole by the
         * same budget (the comb's regular teeth alias with the fallback's
         * regular pieces: up to a quarter off at the comb's middle, in
         * both), within 5% of the light. */
        assert_true(fabs(e_cut - ref) <= fabs(e_one - ref) + 0.05 * ref);
        /* Every part its own fallback: 2,624 rays at the comb's middle; one
         * ray a part (the shares dropped): 64.  The nearer parts take more. */
        assert_true(rays_cut <= (uint64_t)(2 * dc->fallback));
        assert_true(rays_cut > (uint64_t)dc->fallback);
    }
    zt_renderer_release(one);
    zt_renderer_release(cut);
    zt_scene_release(one_scene);
    zt_scene_release(cut_scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_query_stops_past_max),
        cmocka_unit_test(test_splits_share_the_rays),
        cmocka_unit_test(test_sphere_light_by_rays),
        cmocka_unit_test(test_sky_splits_share_the_directions),
        cmocka_unit_test(test_pane_beside_the_pyramid),
        cmocka_unit_test(test_lamp_cut_into_parts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
