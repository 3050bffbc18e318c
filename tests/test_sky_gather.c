/* A mesh node's sky (zone/light/sky_gather.h): each takes a quarter of
 * the sky's directions, set apart from its neighbours', so that their
 * errors average out where the camera's gathers read many of them.
 *
 * A floor of one smooth mesh faces a sphere, the sky of one radiance
 * L all around.  The sphere is wholly above the floor's horizon, so a
 * floor point sees L everywhere but at the sphere, whose view factor is
 * (R / D)^2 cos(theta) (D the distance to its centre, theta that
 * direction's angle from the normal): the point's irradiance is
 * pi L (1 - R^2 h / D^3), h the centre's distance from the floor.  The vertex
 * nodes (every one computed at E_0) are checked against it, under a sky
 * of one colour (the nodes' sets turned about the normal) and under a
 * map of one colour (the nodes' shifted sets drawn from the map):
 * - over the whole floor the nodes are unbiased (their mean error within
 *   0.3% of L);
 * - the mean over a block of 4 x 4 neighbouring nodes errs less than a
 *   node alone, by at least a factor of 3 (independent errors would give
 *   4; 3.8 and 4.2 were measured when this was written).  With one set at
 *   every node (the key made a constant), neighbours err alike: the
 *   factors were 2.0 and 1.6, and both tests fail.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846
/* The floor: SQUARES x SQUARES squares over [0, 2 HALF]^2 at y = 0. */
#define SQUARES 48
#define HALF 4.0
#define BLOCK 4
/* The sphere: radius R, its centre at height H over the origin. */
#define R 1.0
#define H 2.0

/* The floor, facing down (test_obj_sheet): the sky is the same all
 * around, so the scene is the text's upside down. */
static const char *write_floor(void)
{
    size_t cap = (size_t)(SQUARES + 1) * (SQUARES + 1) * 48 + (size_t)SQUARES * SQUARES * 80 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t len = (size_t)snprintf(text, cap, "vn 0 -1 0\n");
    test_obj_sheet(text, len, cap, SQUARES, 2 * HALF / SQUARES, 0.0, 1);
    const char *path = test_write_file("sky_floor.obj", text);
    free(text);
    return path;
}

/* A 16 x 8 map of radiance 1 (PFM, bottom row first). */
static const char *write_white_map(void)
{
    const char *path = test_tmp_path("white_sky.pfm");
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fprintf(fp, "PF\n16 8\n-1.0\n");
    float one = 1.0f;
    for (int i = 0; i < 16 * 8 * 3; i++)
        assert_int_equal(fwrite(&one, sizeof one, 1, fp), 1);
    assert_int_equal(fclose(fp), 0);
    return path;
}

static double open_share(const float *x)
{
    double dx = x[0] - HALF, dz = x[2] - HALF, d2 = dx * dx + H * H + dz * dz, d = sqrt(d2);
    return 1.0 - R * R * H / (d2 * d);
}

static void check_floor(const char *sky)
{
    char text[4096];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [4, -6, -5], \"lookat\": [4, 0, 4], "
             "\"up\": [0, 1, 0], \"fov\": 50, \"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"sky\": %s},"
             "{\"sphere\": {\"center\": [%g, %g, %g], \"radius\": %g, " TEST_DIFFUSE(0.5) "}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": true, \"backculled\": true, "
             TEST_DIFFUSE(0.5) "}}]}",
             sky, HALF, -H, HALF, R, write_floor());
    zt_scene *scene = test_scene_text(text, "sky_floor.json");
    zt_renderer *r = test_zone_renderer(scene, 2, 2, zt_render_options_default().quality);
    const zone_forest *f = r->forest;
    const surface_nodes *sn = &f->sn;
    assert_int_equal(r->rs.mesh_count, 1);
    int32_t first = sn->vertex_first[0];
    assert_true(first >= 0);

    /* Each vertex node's error, as a share of L (E_0 / pi against the
     * open share). */
    int side = SQUARES + 1;
    double *err = calloc((size_t)side * side, sizeof *err);
    assert_non_null(err);
    double sum = 0, sq = 0;
    for (int v = 0; v < side * side; v++) {
        int32_t k = first + v;
        assert_true(sn->live[k]);
        err[v] = zone_e(f, 0, k)[1] / PI - open_share(&sn->pos[3 * (size_t)k]);
        sum += err[v];
        sq += err[v] * err[v];
    }
    double mean = sum / (side * side), node_rms = sqrt(sq / (side * side));
    /* The blocks of BLOCK x BLOCK neighbouring vertices. */
    double block_sq = 0;
    int blocks = 0;
    for (int bi = 0; bi + BLOCK <= side; bi += BLOCK)
        for (int bj = 0; bj + BLOCK <= side; bj += BLOCK) {
            double s = 0;
            for (int i = 0; i < BLOCK; i++)
                for (int j = 0; j < BLOCK; j++)
                    s += err[(bi + i) * side + bj + j];
            s /= BLOCK * BLOCK;
            block_sq += s * s;
            blocks++;
        }
    double block_rms = sqrt(block_sq / blocks);
    printf("sky %s: mean error %.5f, a node's %.5f, a block's mean %.5f (%.2f times less)\n",
           sky, mean, node_rms, block_rms, node_rms / block_rms);
    assert_true(fabs(mean) < 0.003);
    assert_true(node_rms > 0.0);
    assert_true(block_rms * 3.0 < node_rms);
    free(err);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

static void test_colour_sky_nodes_err_apart(void **state)
{
    (void)state;
    check_floor("{\"color\": [1, 1, 1]}");
}

static void test_map_sky_nodes_err_apart(void **state)
{
    (void)state;
    char sky[1024];
    snprintf(sky, sizeof sky, "{\"file\": \"%s\"}", write_white_map());
    check_floor(sky);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_colour_sky_nodes_err_apart),
        cmocka_unit_test(test_map_sky_nodes_err_apart),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
