/* Node life (zone/phase_one/node_life.h): a model's vertices sunk behind a
 * wall are raised to where their triangles come out of it.  A smooth OBJ
 * sheet stands upright on the floor with its two lowest rows of vertices
 * below it; the zone tracer's own nodes for the scene are checked.
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

/* Vertex (i, j) at x = STEP j, y = BOTTOM + STEP i, facing -z. */
static const char *write_sheet(void)
{
    size_t cap = (ROWS + 1) * (COLS + 1) * 64 + ROWS * COLS * 64 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t len = (size_t)snprintf(text, cap, "vn 0 0 -1\n");
    for (int i = 0; i <= ROWS; i++)
        for (int j = 0; j <= COLS; j++)
            len += (size_t)snprintf(text + len, cap - len, "v %g %g %g\n", STEP * j,
                                    BOTTOM + STEP * i, SHEET_Z);
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

/* The vertices of the row just below the floor are live and lie a hair
 * above it, straight over where they were (the vertical edge reaches the
 * floor first); the row below them, with no live corner beside it, stays
 * dead; the rows above are where the model has them. */
static void test_sunk_vertices_are_raised(void **state)
{
    (void)state;
    char text[2048];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [50, 40, -150], \"lookat\": [50, 20, 50], "
             "\"up\": [0, 1, 0], \"fov\": 40, \"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"light\": {\"emission\": [20, 20, 20], \"backculled\": true, \"parts\": ["
             "{\"lighttriangle\": {\"points\": [[30, 150, 0], [70, 150, 30], [70, 150, 0]]}}]}},"
             "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.5) "}},"
             /* Far off, so that the node spacing (the scene's size / 40)
              * leaves the sheet's triangles their corners alone. */
             "{\"thing\": {" TEST_DIFFUSE(0.5) ", \"parts\": [{\"triangle\": {\"points\": "
             "[[1000, 0, 1000], [1001, 0, 1000], [1000, 1, 1000]]}}]}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": true, \"backculled\": true, " TEST_DIFFUSE(
                 0.5) "}}]}",
             write_sheet());
    zt_scene *scene = test_scene_text(text, "sunk_sheet.json");
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 2;
    o.threads = 2;
    zt_renderer *r = NULL;
    zt_error err = {0};
    if (zt_renderer_create(scene, &o, &r, &err) != ZT_OK)
        fail_msg("renderer: %s", err.message);
    zt_image *img = zt_image_create(8, 8);
    assert_non_null(img);
    if (zt_renderer_accumulate(r, 0, 1, img, NULL, &err) != ZT_OK)
        fail_msg("accumulate: %s", err.message);
    zt_image_release(img);

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sunk_vertices_are_raised),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
