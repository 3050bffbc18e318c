/* Node twins (zone/maps/node_twins.h): a smooth mesh's triangles each keep
 * their own nodes along their edges, and where two triangles across an
 * edge put nodes at the same points, one of each pair is computed.  A
 * smooth OBJ sheet of squares cut along their diagonals lies under a
 * light; every triangle takes the same grid, so every node inside an edge
 * the sheet's triangles share has exactly one twin, and none on its border
 * has.  The zone tracer's own nodes for the scene are checked.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"
#include "zone/maps/node_twins.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define SQUARES 3
#define STEP 20.0

/* Vertex (i, j) at x = STEP j, z = STEP i, facing up. */
static const char *write_sheet(void)
{
    size_t cap = (SQUARES + 1) * (SQUARES + 1) * 64 + SQUARES * SQUARES * 64 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t len = (size_t)snprintf(text, cap, "vn 0 1 0\n");
    for (int i = 0; i <= SQUARES; i++)
        for (int j = 0; j <= SQUARES; j++)
            len += (size_t)snprintf(text + len, cap - len, "v %g 0 %g\n", STEP * j, STEP * i);
    for (int i = 0; i < SQUARES; i++)
        for (int j = 0; j < SQUARES; j++) {
            int a = i * (SQUARES + 1) + j + 1, b = a + 1, c = a + SQUARES + 1, d = c + 1;
            /* Counter-clockwise seen from +y: x along j, z along i. */
            len += (size_t)snprintf(text + len, cap - len,
                                    "f %d//1 %d//1 %d//1\nf %d//1 %d//1 %d//1\n", a, c, d, a, d,
                                    b);
        }
    const char *path = test_write_file("twin_sheet.obj", text);
    free(text);
    return path;
}

static void test_edge_nodes_are_paired(void **state)
{
    (void)state;
    char text[2048];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [30, 80, -60], \"lookat\": [30, 0, 30], "
             "\"up\": [0, 1, 0], \"fov\": 50, \"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"light\": {\"emission\": [20, 20, 20], \"backculled\": true, \"parts\": ["
             "{\"lighttriangle\": {\"points\": [[20, 50, 20], [40, 50, 20], [20, 50, 40]]}}]}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": true, \"backculled\": true, " TEST_DIFFUSE(
                 0.5) "}}]}",
             write_sheet());
    zt_scene *scene = test_scene_text(text, "twin_sheet.json");
    zt_renderer *r = test_zone_renderer(scene, 2, 2, zt_render_options_default().quality);

    const surface_nodes *sn = &r->forest->sn;
    const rscene *rs = &r->rs;
    assert_int_equal(rs->mesh_count, 1);
    int first = rs->meshes[0].prim_base, tris = 2 * SQUARES * SQUARES;
    int n = sn->prim[first].n;
    for (int t = 0; t < tris; t++) {
        assert_true(sn->prim[first + t].shared);
        assert_int_equal(sn->prim[first + t].n, n);
    }
    assert_true(n >= 3); /* several nodes along each edge */

    node_twins tw;
    assert_true(node_twins_build(&tw, sn, rs));
    /* Edges shared by two triangles: the diagonals and the inner rows and
     * columns. */
    int shared = SQUARES * SQUARES + 2 * SQUARES * (SQUARES - 1);
    printf("%d steps a triangle, %d node twins over %d shared edges\n", n, tw.count, shared);
    assert_int_equal(tw.count, shared * (n - 1));
    int taken = 0;
    for (int k = 0; k < sn->node_count; k++) {
        int32_t c = node_twin(&tw, k);
        if (c < 0)
            continue;
        taken++;
        assert_true(c < k);
        assert_int_equal(node_twin(&tw, c), -1);
        assert_true(sn->live[k] && sn->live[c]);
        for (int q = 0; q < 3; q++) {
            assert_true(fabsf(sn->pos[3 * k + q] - sn->pos[3 * c + q]) < 1e-4f);
            assert_true(fabsf(sn->nrm[3 * k + q] - sn->nrm[3 * c + q]) < 1e-6f);
        }
        /* On a shared edge: not on the sheet's border. */
        const float *x = &sn->pos[3 * k];
        assert_true(x[0] > 1e-3f && x[0] < SQUARES * STEP - 1e-3f);
        assert_true(x[2] > 1e-3f && x[2] < SQUARES * STEP - 1e-3f);
        /* The forest holds the same light at both. */
        for (int level = 0; level < r->forest->map_levels; level++)
            for (int ch = 0; ch < 3; ch++)
                assert_true(zone_e(r->forest, level, k)[ch] == zone_e(r->forest, level, c)[ch]);
    }
    assert_int_equal(taken, tw.count);
    node_twins_free(&tw);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edge_nodes_are_paired),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
