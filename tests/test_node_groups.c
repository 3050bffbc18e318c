/* Node groups (zone/maps/node_groups.h) and the cuts their members start
 * from (zone/transfer/cut.h, cut_resume).  A smooth OBJ mesh of two fine
 * sheets facing down, the smaller a little below the larger's corner, hangs
 * over a floor that a light beside them lights; a small triangle far away
 * sets the node spacing (the scene's size / 40) well above the sheets'
 * vertex spacing.  Checked: the groups' rules (near the leader, on its
 * sheet, facing its way, never across the two stacked sheets), that every
 * node left alone has no free neighbour, that a member's cut started
 * from its leader's gives what its own cut gives, within stated bounds,
 * and that the forest is the same on any thread count.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"
#include "scene/mesh.h"
#include "zone/maps/mesh_sheet.h"
#include "zone/maps/node_groups.h"
#include "zone/transfer/transfer.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define STEP 0.5
#define BIG 40          /* squares a side of the upper sheet */
#define SMALL 12        /* ... of the lower one, under its corner */
#define HIGH 20.0
#define GAP 0.4         /* between the two sheets */
#define RADIUS 2.0      /* the groups the test makes itself */
#define MIN_COS 0.9

static const char *write_sheets(void)
{
    int vb = (BIG + 1) * (BIG + 1), vs = (SMALL + 1) * (SMALL + 1);
    size_t cap = (size_t)(vb + vs) * 48 + (size_t)(BIG * BIG + SMALL * SMALL) * 96 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t len = (size_t)snprintf(text, cap, "vn 0 -1 0\n");
    len = test_obj_sheet(text, len, cap, BIG, STEP, HIGH, 1);
    test_obj_sheet(text, len, cap, SMALL, STEP, HIGH - GAP, 1 + vb);
    const char *path = test_write_file("group_sheets.obj", text);
    free(text);
    return path;
}

static zt_renderer *render_sheets_on(int threads, zt_scene **scene_out)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [10, 5, -60], \"lookat\": [10, 10, 10], "
             "\"up\": [0, 1, 0], \"fov\": 50, \"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"light\": {\"emission\": [40, 40, 40], \"backculled\": false, \"parts\": ["
             "{\"lighttriangle\": {\"points\": [[30, 10, 0], [40, 10, 20], [40, 10, 0]]}}]}},"
             "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.7) "}},"
             "{\"thing\": {" TEST_DIFFUSE(0.5) ", \"parts\": [{\"triangle\": {\"points\": "
             "[[400, 0, 400], [401, 0, 400], [400, 1, 400]]}}]}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": true, \"backculled\": true, " TEST_DIFFUSE(
                 0.5) "}}]}",
             write_sheets());
    zt_scene *scene = test_scene_text(text, "group_sheets.json");
    zt_renderer *r = test_zone_renderer(scene, 2, threads, zt_render_options_default().quality);
    *scene_out = scene;
    return r;
}

static zt_renderer *render_sheets(zt_scene **scene_out)
{
    return render_sheets_on(2, scene_out);
}

static double dist(const surface_nodes *sn, int32_t a, int32_t b)
{
    double d2 = 0;
    for (int q = 0; q < 3; q++) {
        double d = (double)sn->pos[3 * a + q] - sn->pos[3 * b + q];
        d2 += d * d;
    }
    return sqrt(d2);
}

static int upper(const surface_nodes *sn, int32_t k)
{
    return sn->pos[3 * k + 1] > HIGH - GAP / 2;
}

static void test_groups_follow_their_rules(void **state)
{
    (void)state;
    zt_scene *scene;
    zt_renderer *r = render_sheets(&scene);
    const surface_nodes *sn = &r->forest->sn;
    const rscene *rs = &r->rs;
    assert_true(RADIUS < sn->h); /* the vertices lie far closer than h */
    int32_t base = sn->vertex_first[0];
    int count = rs->meshes[0].m->vertex_count;
    assert_true(base >= 0);

    node_groups ng;
    assert_true(node_groups_build(&ng, sn, rs, RADIUS, MIN_COS));
    printf("h %g: %d groups, %d members over %d vertex nodes\n", sn->h, ng.groups, ng.members,
           count);
    assert_true(ng.groups > 0 && ng.members > 4 * ng.groups);
    int members = 0;
    for (int32_t k = 0; k < sn->node_count; k++) {
        int32_t lead = node_group_lead(&ng, k);
        int vertex = k >= base && k < base + count;
        if (!vertex || !sn->live[k]) {
            assert_int_equal(lead, -1);
            continue;
        }
        if (lead < 0) {
            /* Left alone: no node near it on its sheet was free. */
            for (int32_t j = base; j < base + count; j++)
                if (j != k && sn->live[j] && node_group_lead(&ng, j) < 0 &&
                    upper(sn, j) == upper(sn, k))
                    assert_true(dist(sn, j, k) > RADIUS);
            continue;
        }
        assert_int_equal(node_group_lead(&ng, lead), lead);
        if (lead == k) {
            assert_true(ng.first[k + 1] > ng.first[k]);
            continue;
        }
        members++;
        assert_true(lead < k);
        assert_true(dist(sn, k, lead) <= RADIUS * (1 + 1e-6));
        /* Never across the two sheets, though many pairs lie within RADIUS
         * of each other. */
        assert_int_equal(upper(sn, k), upper(sn, lead));
        double dot = 0;
        for (int q = 0; q < 3; q++)
            dot += (double)sn->nrm[3 * k + q] * sn->nrm[3 * lead + q];
        assert_true(dot >= MIN_COS);
        int listed = 0;
        for (int32_t i = ng.first[lead]; i < ng.first[lead + 1]; i++)
            listed += ng.member[i] == k;
        assert_int_equal(listed, 1);
    }
    assert_int_equal(members, ng.members);
    node_groups_free(&ng);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

static double lum(vec3 v)
{
    return (v.x + v.y + v.z) / 3;
}

/* The first bounce at each member, from its leader's cut and from its own;
 * and at each leader from its own record. */
static void test_members_start_from_the_leaders_cut(void **state)
{
    (void)state;
    zt_scene *scene;
    zt_renderer *r = render_sheets(&scene);
    zone_forest *f = r->forest;
    const surface_nodes *sn = &f->sn;
    const rscene *rs = &r->rs;
    /* The renderer's own groups shared cuts. */
    assert_true(f->cuts_shared > 0);

    node_groups ng;
    assert_true(node_groups_build(&ng, sn, rs, RADIUS, MIN_COS));
    sender_tree tree;
    assert_true(sender_tree_build(&tree, sn, rs));
    sender_tree_fill(&tree, sn, rs, zone_e(f, 0, 0));
    transfer_ctx tc = {.tree = &tree, .sn = sn, .rs = rs, .e = zone_e(f, 0, 0),
                       .eps = f->q.eps, .theta = f->q.theta, .max_cut = 1024};
    cut_record rec = {0};
    double sum_own = 0, sum_diff = 0, sum_signed = 0, worst = 0, sum_lead = 0;
    int n = 0;
    for (int32_t k = 0; k < sn->node_count; k++) {
        if (node_group_lead(&ng, k) != k)
            continue;
        vec3 kx = v3(sn->pos[3 * k], sn->pos[3 * k + 1], sn->pos[3 * k + 2]);
        vec3 kn = v3(sn->nrm[3 * k], sn->nrm[3 * k + 1], sn->nrm[3 * k + 2]);
        transfer_stats st = {0};
        vec3 lead = transfer_irradiance(&tc, kx, kn, sn->prim_of[k], &st, &rec);
        assert_false(rec.failed);
        /* From its own cut, opening nothing more: the same light. */
        vec3 again = transfer_irradiance_near(&tc, kx, kn, &rec, 0, &st);
        assert_true(fabs(lum(again) - lum(lead)) <= 1e-5 * lum(lead) + 1e-12);
        for (int32_t i = ng.first[k]; i < ng.first[k + 1]; i++) {
            int32_t m = ng.member[i];
            vec3 x = v3(sn->pos[3 * m], sn->pos[3 * m + 1], sn->pos[3 * m + 2]);
            vec3 nm = v3(sn->nrm[3 * m], sn->nrm[3 * m + 1], sn->nrm[3 * m + 2]);
            double own = lum(transfer_irradiance(&tc, x, nm, sn->prim_of[m], &st, NULL));
            double near = lum(transfer_irradiance_near(&tc, x, nm, &rec, 64, &st));
            sum_own += own;
            sum_lead += fabs(lum(lead) - own);
            sum_diff += fabs(near - own);
            sum_signed += near - own;
            worst = fmax(worst, fabs(near - own));
            n++;
        }
    }
    double mean = sum_own / n;
    printf("%d members: mean %g, |started - own| mean %.4f, signed %.4f, worst %.4f of it; "
           "|leader's - own| mean %.4f\n",
           n, mean, sum_diff / n / mean, sum_signed / n / mean, worst / mean,
           sum_lead / n / mean);
    assert_true(n > 100 && mean > 0);
    /* Within 0.03% on average (worst 0.4%, beside the lower sheet's rim):
     * the bounds leave room for other trees and rounding. */
    assert_true(sum_diff / n <= 0.003 * mean);
    assert_true(fabs(sum_signed) / n <= 0.001 * mean);
    assert_true(worst <= 0.03 * mean);
    /* The members' own positions and normals count: the leader's value
     * itself is further from theirs. */
    assert_true(sum_lead > 3 * sum_diff);
    free(rec.e);
    sender_tree_free(&tree);
    node_groups_free(&ng);
    zt_renderer_release(r);
    zt_scene_release(scene);
}

/* Members are computed by their leader's thread, in its pass: the forest
 * is the same on one thread as on three. */
static void test_forest_the_same_on_any_thread_count(void **state)
{
    (void)state;
    zt_scene *s1, *s3;
    zt_renderer *r1 = render_sheets_on(1, &s1), *r3 = render_sheets_on(3, &s3);
    const zone_forest *a = r1->forest, *b = r3->forest;
    assert_true(a->cuts_shared > 0);
    assert_int_equal(a->cuts_shared, b->cuts_shared);
    assert_int_equal(a->sn.node_count, b->sn.node_count);
    assert_int_equal(a->map_levels, b->map_levels);
    size_t n = (size_t)a->map_levels * (size_t)a->sn.node_count * 3;
    assert_memory_equal(a->e, b->e, n * sizeof *a->e);
    zt_renderer_release(r1);
    zt_renderer_release(r3);
    zt_scene_release(s1);
    zt_scene_release(s3);
}

/* A faceted sheet, as a file with a normal per face gives it: every
 * triangle has its own three vertices (4 x 4 squares of side 1 on y = 0),
 * and the last column of squares is folded up by 60 degrees (its normals
 * say so; its positions stay, which the walk does not look at).  Copies at
 * one position are one point of the surface: a walk crosses from facet to
 * facet through them, and stops at the fold. */
#define FACETS 4
static void test_sheet_walk_crosses_split_vertices(void **state)
{
    (void)state;
    enum { TRIS = 2 * FACETS * FACETS, VERTS = 3 * TRIS };
    float pos[3 * VERTS + 1], nrm[3 * VERTS];
    uint32_t index[3 * TRIS];
    int folded[VERTS];
    int v = 0;
    for (int i = 0; i < FACETS; i++)
        for (int j = 0; j < FACETS; j++) {
            const int corner[2][3][2] = {{{0, 0}, {0, 1}, {1, 1}}, {{0, 0}, {1, 1}, {1, 0}}};
            for (int t = 0; t < 2; t++)
                for (int c = 0; c < 3; c++, v++) {
                    pos[3 * v] = (float)(i + corner[t][c][0]);
                    pos[3 * v + 1] = 0.0f;
                    pos[3 * v + 2] = (float)(j + corner[t][c][1]);
                    folded[v] = i == FACETS - 1;
                    nrm[3 * v] = folded[v] ? -0.8660254f : 0.0f;
                    nrm[3 * v + 1] = folded[v] ? 0.5f : 1.0f;
                    nrm[3 * v + 2] = 0.0f;
                    index[v] = (uint32_t)v;
                }
        }
    pos[3 * VERTS] = 0.0f;
    mesh m = {.vertex_count = VERTS, .triangle_count = TRIS, .position = pos, .index = index};
    mesh_adjacency adj;
    sheet_walk w;
    assert_true(mesh_adjacency_build(&adj, &m));
    assert_true(sheet_walk_init(&w, VERTS));
    /* From a corner of the first facet: every unfolded copy, and no other. */
    int reached = mesh_sheet_walk(&adj, pos, nrm, 0, 100.0, MIN_COS, NULL, &w);
    int flat = 0;
    for (int k = 0; k < VERTS; k++)
        flat += !folded[k];
    assert_int_equal(reached, flat);
    for (int i = 0; i < reached; i++)
        assert_false(folded[w.queue[i]]);
    /* Within a reach of 1.1 of the origin: the copies of (0,0,0), (1,0,0),
     * (0,0,1) and (1,0,1) only (the walk goes on only through vertices
     * within reach). */
    reached = mesh_sheet_walk(&adj, pos, nrm, 0, 1.5, MIN_COS, NULL, &w);
    int near = 0;
    for (int k = 0; k < VERTS; k++)
        near += pos[3 * k] <= 1.0f && pos[3 * k + 2] <= 1.0f;
    assert_int_equal(reached, near);
    /* A copy marked as taken stops the walk, as any vertex does. */
    uint8_t taken[VERTS];
    memset(taken, 0xff, sizeof taken);
    for (int k = 1; k < VERTS; k++)
        if (pos[3 * k] == 0.0f && pos[3 * k + 2] == 0.0f) {
            taken[k] = 0;
            break;
        }
    assert_int_equal(mesh_sheet_walk(&adj, pos, nrm, 0, 100.0, MIN_COS, taken, &w), -1);
    sheet_walk_free(&w);
    mesh_adjacency_free(&adj);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sheet_walk_crosses_split_vertices),
        cmocka_unit_test(test_groups_follow_their_rules),
        cmocka_unit_test(test_members_start_from_the_leaders_cut),
        cmocka_unit_test(test_forest_the_same_on_any_thread_count),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
