#define _POSIX_C_SOURCE 200809L /* setenv, strdup */
/* Node life (zone/phase_one/node_life.h): a model's vertices sunk behind a
 * wall are raised to where their triangles come out of it.  A smooth OBJ
 * sheet stands upright on the floor with its two lowest rows of vertices
 * below it; the zone tracer's own nodes for the scene are checked, and
 * again after its forest is written and read back.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"
#include "scene/mesh.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define COLS 10
#define ROWS 10
#define STEP 10.0
#define BOTTOM -15.0 /* rows at y = -15 and -5 lie below the floor */
#define SHEET_Z 50.0

/* Vertex (i, j) at x = STEP j, y = bottom + step_y i, facing -z. */
static const char *write_sheet(double step_y, double bottom)
{
    size_t cap = (ROWS + 1) * (COLS + 1) * 64 + ROWS * COLS * 64 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t len = (size_t)snprintf(text, cap, "vn 0 0 -1\n");
    for (int i = 0; i <= ROWS; i++)
        for (int j = 0; j <= COLS; j++)
            len += (size_t)snprintf(text + len, cap - len, "v %g %g %g\n", STEP * j,
                                    bottom + step_y * i, SHEET_Z);
    for (int i = 0; i < ROWS; i++)
        for (int j = 0; j < COLS; j++) {
            int a = i * (COLS + 1) + j + 1, b = a + 1, c = a + COLS + 1, d = c + 1;
            /* (up) x (along x) is -z. */
            len += (size_t)snprintf(text + len, cap - len,
                                    "f %d//1 %d//1 %d//1\nf %d//1 %d//1 %d//1\n", a, c, b, c, d,
                                    b);
        }
    const char *path = test_write_file("sunk_sheet.obj", text);
    free(text);
    return path;
}

/* The sheet on the floor under a light, with the zone tracer's forest of
 * depth 2.  A small triangle at (far, 0, far) sets the node spacing (the
 * scene's size / 40). */
static zt_renderer *render_sheet(double step_y, double bottom, double far, zt_scene **scene_out)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [50, 40, -150], \"lookat\": [50, 20, 50], "
             "\"up\": [0, 1, 0], \"fov\": 40, \"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"light\": {\"emission\": [20, 20, 20], \"backculled\": true, \"parts\": ["
             "{\"lighttriangle\": {\"points\": [[30, 150, 0], [70, 150, 30], [70, 150, 0]]}}]}},"
             "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.5) "}},"
             "{\"thing\": {" TEST_DIFFUSE(0.5) ", \"parts\": [{\"triangle\": {\"points\": "
             "[[%g, 0, %g], [%g, 0, %g], [%g, 1, %g]]}}]}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": true, \"backculled\": true, " TEST_DIFFUSE(
                 0.5) "}}]}",
             far, far, far + 1, far, far, far, write_sheet(step_y, bottom));
    zt_scene *scene = test_scene_text(text, "sunk_sheet.json");
    zt_renderer *r = test_zone_renderer(scene, 2, 2, zt_render_options_default().quality);
    *scene_out = scene;
    return r;
}

/* The vertices of the row just below the floor are live and lie a hair
 * above it, straight over where they were (the vertical edge reaches the
 * floor first); the row below them, with no live corner beside it, stays
 * dead; the rows above are where the model has them. */
static void test_sunk_vertices_are_raised(void **state)
{
    (void)state;
    zt_scene *scene;
    /* The spacing leaves the sheet's triangles their corners alone. */
    zt_renderer *r = render_sheet(STEP, BOTTOM, 1000, &scene);
    const surface_nodes *sn = &r->forest->sn;
    assert_int_equal(sn->mesh_count, 1);
    assert_true(sn->vertex_first[0] >= 0);
    assert_true(0.5 * sn->h > STEP * sqrt(2.0));
    const rs_mesh *mm = &r->rs.meshes[0];
    assert_int_equal(mm->m->vertex_count, (ROWS + 1) * (COLS + 1));
    int raised = 0, dead = 0, kept = 0;
    for (int v = 0; v < mm->m->vertex_count; v++) {
        const float *was = mm->m->position + 3 * (size_t)v;
        int32_t k = sn->vertex_first[0] + v;
        const float *now = sn->pos + 3 * (size_t)k;
        if (was[1] < BOTTOM + 0.5 * STEP) {
            assert_int_equal(sn->live[k], 0);
            dead++;
            continue;
        }
        assert_int_equal(sn->live[k], 1);
        assert_true(fabsf(now[0] - was[0]) < 1e-3f);
        assert_true(fabsf(now[2] - was[2]) < 1e-2f);
        if (was[1] < 0) {
            /* 1% of the 5 units from the floor to the live vertex above. */
            assert_true(now[1] > 0.0f && now[1] < 0.1f);
            raised++;
        } else {
            assert_true(fabsf(now[1] - was[1]) < 1e-4f);
            kept++;
        }
    }
    printf("%d vertices raised to the floor, %d left dead below it, %d kept\n", raised, dead,
           kept);
    assert_int_equal(raised, COLS + 1);
    assert_int_equal(dead, COLS + 1);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

/* A forest keeps its raised vertices: written and read back, its nodes are
 * where they were raised to.  Rows 20 apart, the lowest 8 below the floor,
 * and a spacing of about 24 (the triangles split in two along each edge):
 * the lowest vertices are raised by about 8, farther than the quarter
 * cell node life moves any other node, which the file's check once allowed
 * alone. */
static void test_raised_vertices_survive_the_forest_file(void **state)
{
    (void)state;
    zt_scene *scene;
    zt_renderer *r = render_sheet(20, -8, 680, &scene);
    const surface_nodes *sn = &r->forest->sn;
    const rs_mesh *mm = &r->rs.meshes[0];
    float moved = 0;
    for (int v = 0; v < mm->m->vertex_count; v++) {
        int32_t k = sn->vertex_first[0] + v;
        moved = fmaxf(moved, fabsf(sn->pos[3 * k + 1] - mm->m->position[3 * (size_t)v + 1]));
    }
    printf("a vertex raised by %.2f, node spacing %.2f\n", moved, sn->h);
    assert_true(moved > 0.3 * sn->h);

    zt_error err = {0};
    const char *forest = test_tmp_path("sunk_sheet.forest");
    if (zt_renderer_save_forest(r, forest, &err) != ZT_OK)
        fail_msg("save forest: %s", err.message);
    zt_render_options o = r->options;
    o.forest_file = forest;
    zt_renderer *back = NULL;
    if (zt_renderer_create(scene, &o, &back, &err) != ZT_OK)
        fail_msg("load forest: %s", err.message);
    const surface_nodes *bn = &back->forest->sn;
    assert_int_equal(bn->node_count, sn->node_count);
    assert_memory_equal(bn->live, sn->live, (size_t)sn->node_count);
    assert_memory_equal(bn->pos, sn->pos, 3 * (size_t)sn->node_count * sizeof *sn->pos);
    zt_renderer_release(back);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

/* A box of 12 two-sided triangles standing on the floor, or the same box
 * without its lid (open: a sheet light may reach under, like a roof seen
 * from below).  The floor's nodes under the closed box see its faces from
 * behind in every direction: dead, so the floor around its foot is read
 * from the lit nodes outside (else it was darkened there, half way to the
 * nodes under the box).  Under the open one they stay live, as before. */
static int floor_nodes_under_box(int lid, int culled, int *under)
{
    static const double q[8][3] = {{0.5, 0, -1.5}, {2, 0, -1.5}, {2, 0, 0},   {0.5, 0, 0},
                                   {0.5, 1.2, -1.5}, {2, 1.2, -1.5}, {2, 1.2, 0}, {0.5, 1.2, 0}};
    /* Quads wound counter-clockwise seen from outside. */
    static const int quad[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1},
                                   {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 5, 6, 2}};
    char parts[4096];
    size_t len = 0;
    for (int f = 0; f < 6; f++) {
        if (!lid && f == 1)
            continue;
        const int *c = quad[f];
        for (int t = 0; t < 2; t++) {
            int a = c[0], b = c[t + 1], d = c[t + 2];
            len += (size_t)snprintf(parts + len, sizeof parts - len,
                                    "%s{\"triangle\": {\"points\": [[%g, %g, %g], [%g, %g, %g], "
                                    "[%g, %g, %g]]}}",
                                    len ? "," : "", q[a][0], q[a][1], q[a][2], q[b][0], q[b][1],
                                    q[b][2], q[d][0], q[d][1], q[d][2]);
        }
    }
    char text[8192];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [6, 4, 7], \"lookat\": [0, 0.6, 0], \"fov\": 40, "
             "\"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"sky\": {\"color\": [1, 1, 1]}},"
             "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.5) "}},"
             "{\"thing\": {" TEST_DIFFUSE(0.6) ", \"backculled\": %s, \"parts\": [%s]}}]}",
             culled ? "true" : "false", parts);
    zt_scene *scene = test_scene_text(text, "box_on_floor.json");
    zt_renderer *r = test_zone_renderer(scene, 2, 2, zt_render_options_default().quality);
    const surface_nodes *sn = &r->forest->sn;
    int live = 0;
    *under = 0;
    for (int32_t k = 0; k < sn->node_count; k++) {
        const float *x = sn->pos + 3 * (size_t)k;
        /* The plane is part 0: its nodes, well inside the box's foot. */
        if (sn->prim_of[k] != 0 || !(sn->nrm[3 * k + 1] > 0.5f) || !(x[0] > 0.6f) ||
            !(x[0] < 1.9f) || !(x[2] > -1.4f) || !(x[2] < -0.1f))
            continue;
        (*under)++;
        live += sn->live[k];
    }
    zt_renderer_release(r);
    zt_scene_release(scene);
    return live;
}

/* On every backend: Embree's probes go through its own structure with
 * culling taken off (accel_nearest_all_sides), the others' through the
 * occluder index; a back-culled box must hide the floor on each (with
 * culling left on, the probes would pass through its faces' backs).  An
 * open back-culled box's walls are walls too (the back of a culled
 * surface is one): every backend must find the same nodes live. */
static void test_closed_box_hides_the_floor(void **state)
{
    (void)state;
    const char *backends[] = {"embree", "bvh", "brute"};
    const char *old = getenv("ZT_ACCEL");
    char *saved = old ? strdup(old) : NULL;
    int open_culled = -1;
    for (int b = 0; b < 3; b++) {
        setenv("ZT_ACCEL", backends[b], 1);
        for (int culled = 0; culled < 2; culled++) {
            int under, live = floor_nodes_under_box(1, culled, &under);
            printf("%s, %s closed box: %d of the %d floor nodes under it live\n", backends[b],
                   culled ? "culled" : "two-sided", live, under);
            assert_true(under > 0);
            assert_int_equal(live, 0);
            live = floor_nodes_under_box(0, culled, &under);
            printf("%s, %s open box: %d of the %d floor nodes under it live\n", backends[b],
                   culled ? "culled" : "two-sided", live, under);
            if (!culled)
                assert_int_equal(live, under);
            else if (open_culled < 0)
                open_culled = live;
            else
                assert_int_equal(live, open_culled);
        }
    }
    if (saved)
        setenv("ZT_ACCEL", saved, 1);
    else
        unsetenv("ZT_ACCEL");
    free(saved);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sunk_vertices_are_raised),
        cmocka_unit_test(test_raised_vertices_survive_the_forest_file),
        cmocka_unit_test(test_closed_box_hides_the_floor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
