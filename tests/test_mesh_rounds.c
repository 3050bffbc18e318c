/* Mesh vertex rounds (zone/maps/mesh_rounds.h): which vertex nodes are read
 * from others, and how.  Two flat sheets of one smooth OBJ mesh lie one
 * unit apart (a fin over a plate, far closer than the node spacing); the
 * rounds are built over the zone tracer's own nodes for the scene.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"
#include "zone/maps/mesh_rounds.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define GRID 80
#define SIDE 100.0
#define GAP 1.0
#define RAMP_AT 41.3

/* Two (GRID + 1)^2-vertex sheets facing up, sharing no vertex: a plate at
 * y = 0 and over its half x < SIDE / 2 a fin at y = GAP (the plate is dead
 * under it, live beside it). */
static const char *write_sheets(void)
{
    size_t cap = 2 * (GRID + 1) * (GRID + 1) * 80 + 2 * GRID * GRID * 120 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t len = (size_t)snprintf(text, cap, "vn 0 1 0\n");
    for (int s = 0; s < 2; s++)
        for (int i = 0; i <= GRID; i++)
            for (int j = 0; j <= GRID; j++)
                len += (size_t)snprintf(text + len, cap - len, "v %.9g %.9g %.9g\n",
                                        (s ? 0.5 : 1.0) * SIDE * j / GRID, s * GAP,
                                        SIDE * i / GRID);
    for (int s = 0; s < 2; s++)
        for (int i = 0; i < GRID; i++)
            for (int j = 0; j < GRID; j++) {
                int a = s * (GRID + 1) * (GRID + 1) + i * (GRID + 1) + j + 1;
                int b = a + 1, c = a + GRID + 1, d = c + 1;
                /* Counter-clockwise seen from +y: x along j, z along i. */
                len += (size_t)snprintf(text + len, cap - len,
                                        "f %d//1 %d//1 %d//1\nf %d//1 %d//1 %d//1\n", a, c, d, a,
                                        d, b);
            }
    const char *path = test_write_file("sheets.obj", text);
    free(text);
    return path;
}

typedef struct fixture {
    zt_scene *scene;
    zt_renderer *r;
    mesh_rounds mr;
    int32_t first, count; /* the mesh's vertex nodes */
} fixture;

static void setup(fixture *fx)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [50, 80, -60], \"lookat\": [50, 0, 50], \"up\": [0, 1, 0], "
             "\"fov\": 40, \"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"light\": {\"emission\": [20, 20, 20], \"backculled\": true, \"parts\": ["
             "{\"lighttriangle\": {\"points\": [[40, 60, 40], [60, 60, 40], [60, 60, 60]]}}]}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": true, \"backculled\": true, " TEST_DIFFUSE(0.5)
             "}}]}",
             write_sheets());
    fx->scene = test_scene_text(text, "sheets.json");
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 2;
    o.threads = 2;
    zt_error err = {0};
    if (zt_renderer_create(fx->scene, &o, &fx->r, &err) != ZT_OK)
        fail_msg("renderer: %s", err.message);
    zt_image *img = zt_image_create(8, 8);
    assert_non_null(img);
    if (zt_renderer_accumulate(fx->r, 0, 1, img, NULL, &err) != ZT_OK)
        fail_msg("accumulate: %s", err.message);
    zt_image_release(img);
    const surface_nodes *sn = &fx->r->forest->sn;
    assert_int_equal(sn->mesh_count, 1);
    assert_true(sn->vertex_first[0] >= 0);
    fx->first = sn->vertex_first[0];
    fx->count = 2 * (GRID + 1) * (GRID + 1);
    /* The node spacing is several vertex steps, so rounds have room. */
    assert_true(sn->h > 2.0 * SIDE / GRID);
    assert_int_equal(mesh_rounds_build(&fx->mr, sn, &fx->r->rs, 2), 1);
}

static void teardown(fixture *fx)
{
    mesh_rounds_free(&fx->mr);
    zt_renderer_release(fx->r);
    zt_scene_release(fx->scene);
}

static const float *pos(const fixture *fx, int32_t k)
{
    return fx->r->forest->sn.pos + 3 * (size_t)k;
}

/* Most vertex nodes are read from others, and never across the gap: the
 * sheets are one unit apart, under a hundredth of the spacing, but share
 * no edge. */
static void test_rounds_stay_on_their_sheet(void **state)
{
    (void)state;
    fixture fx;
    setup(&fx);
    int read = 0, live = 0;
    for (int32_t k = fx.first; k < fx.first + fx.count; k++) {
        live += fx.r->forest->sn.live[k];
        if (!mesh_round(&fx.mr, k))
            continue;
        read++;
        int32_t n = fx.mr.first[k + 1] - fx.mr.first[k];
        assert_true(n >= 3 && n <= 8);
        for (int32_t i = fx.mr.first[k]; i < fx.mr.first[k + 1]; i++) {
            int32_t s = fx.mr.support[i];
            assert_true(fx.mr.first[s] >= 0);
            assert_true(mesh_round(&fx.mr, s) < mesh_round(&fx.mr, k));
            assert_true(fabsf(pos(&fx, s)[1] - pos(&fx, k)[1]) < 1e-4f);
        }
    }
    printf("%d of %d live vertex nodes are read from supports\n", read, live);
    assert_true(live > fx.count / 2);
    assert_true(read > 0.75 * live);
    teardown(&fx);
}

/* A plane through the supports' values is read exactly; a ramp that
 * starts between them (a shadow's edge) is either refused or read within
 * 5% of the largest value there (the fit tolerance is 1%; a line through
 * the ramp's foot would be off by up to half). */
static void test_reads_planes_and_refuses_kinks(void **state)
{
    (void)state;
    fixture fx;
    setup(&fx);
    const surface_nodes *sn = &fx.r->forest->sn;
    float *v = calloc(3 * (size_t)sn->node_count + 3, sizeof *v);
    assert_non_null(v);
    for (int32_t k = 0; k < sn->node_count; k++) {
        const float *p = sn->pos + 3 * (size_t)k;
        for (int ch = 0; ch < 3; ch++)
            v[3 * k + ch] = (float)((ch + 1) * (2.0 + 0.01 * p[0] - 0.005 * p[2]));
    }
    int planes = 0;
    for (int32_t k = fx.first; k < fx.first + fx.count; k++) {
        if (!mesh_round(&fx.mr, k))
            continue;
        float out[3];
        assert_int_equal(mesh_rounds_read(&fx.mr, sn, v, k, 0.01, out), 1);
        for (int ch = 0; ch < 3; ch++)
            assert_float_equal(out[ch], v[3 * k + ch], 1e-4 * v[3 * k + ch]);
        planes++;
    }
    assert_true(planes > 0);

    for (int32_t k = 0; k < sn->node_count; k++) {
        double x = sn->pos[3 * (size_t)k];
        for (int ch = 0; ch < 3; ch++)
            v[3 * k + ch] = (float)(x > RAMP_AT ? x - RAMP_AT : 0.0);
    }
    int straddle = 0, refused = 0;
    for (int32_t k = fx.first; k < fx.first + fx.count; k++) {
        if (!mesh_round(&fx.mr, k))
            continue;
        double lo = INFINITY, hi = -INFINITY, top = 0;
        for (int32_t i = fx.mr.first[k]; i < fx.mr.first[k + 1]; i++) {
            int32_t s = fx.mr.support[i];
            lo = fmin(lo, sn->pos[3 * (size_t)s]);
            hi = fmax(hi, sn->pos[3 * (size_t)s]);
            top = fmax(top, v[3 * (size_t)s]);
        }
        if (!(lo < RAMP_AT && hi > RAMP_AT))
            continue;
        straddle++;
        float out[3];
        if (!mesh_rounds_read(&fx.mr, sn, v, k, 0.01, out)) {
            refused++;
            continue;
        }
        assert_true(fabs(out[0] - v[3 * k]) <= 0.05 * top);
    }
    printf("ramp: %d nodes' supports straddle its foot, %d refused\n", straddle, refused);
    assert_true(straddle > 10);
    assert_true(refused > straddle / 2);
    free(v);
    teardown(&fx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rounds_stay_on_their_sheet),
        cmocka_unit_test(test_reads_planes_and_refuses_kinks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
