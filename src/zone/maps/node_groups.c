/* Nodes that share one cut (node_groups.h). */
#include "zone/maps/node_groups.h"

#include <stdlib.h>
#include <string.h>

#include "scene/mesh.h"
#include "zone/maps/mesh_sheet.h"

/* A member lies within FLAT x its distance of the leader's tangent plane
 * (as mesh_rounds' supports do). */
#define FLAT 0.35

/* One side of one mesh: nodes base .. base + count - 1. */
static int group_side(node_groups *ng, const surface_nodes *sn, const mesh *m, int32_t base,
                      double radius, double min_cos)
{
    int32_t count = m->vertex_count;
    const float *pos = sn->pos + 3 * (size_t)base, *nrm = sn->nrm + 3 * (size_t)base;
    mesh_adjacency adj;
    sheet_walk w;
    int ok = mesh_adjacency_build(&adj, m);
    ok = sheet_walk_init(&w, count) && ok;
    for (int32_t v = 0; v < count && ok; v++) {
        int32_t k = base + v;
        if (!sn->live[k] || ng->lead[k] >= 0)
            continue;
        /* Every node before k has a leader or is one: k leads the nodes
         * of its sheet near it that have none. */
        const float *p = pos + 3 * (size_t)v, *n = nrm + 3 * (size_t)v;
        int reached = mesh_sheet_walk(&adj, pos, nrm, v, radius, min_cos, NULL, &w);
        int have = 0;
        for (int i = 1; i < reached; i++) {
            int32_t u = w.queue[i], j = base + u;
            if (!sn->live[j] || ng->lead[j] >= 0)
                continue;
            const float *q = pos + 3 * (size_t)u;
            double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            double h = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            if (h * h > FLAT * FLAT * d2)
                continue;
            ng->lead[j] = k;
            ng->members++;
            have = 1;
        }
        if (have) {
            ng->lead[k] = k;
            ng->groups++;
        }
    }
    mesh_adjacency_free(&adj);
    sheet_walk_free(&w);
    return ok;
}

int node_groups_build(node_groups *ng, const surface_nodes *sn, const rscene *rs, double radius,
                      double min_cos)
{
    memset(ng, 0, sizeof *ng);
    int any = 0;
    for (int m = 0; m < sn->mesh_count; m++)
        any |= sn->vertex_first[m] >= 0;
    if (!any || !(radius > 0))
        return 1;
    size_t nc = (size_t)sn->node_count;
    ng->lead = malloc((nc + 1) * sizeof *ng->lead);
    ng->first = calloc(nc + 2, sizeof *ng->first);
    if (!ng->lead || !ng->first) {
        node_groups_free(ng);
        return 0;
    }
    for (size_t k = 0; k < nc; k++)
        ng->lead[k] = -1;
    for (int m = 0; m < sn->mesh_count; m++) {
        if (sn->vertex_first[m] < 0)
            continue;
        const rs_mesh *mm = &rs->meshes[m];
        int32_t vc = mm->m->vertex_count;
        for (int s = 0; s < (mm->culled ? 1 : 2); s++)
            if (!group_side(ng, sn, mm->m, sn->vertex_first[m] + s * vc, radius, min_cos)) {
                node_groups_free(ng);
                return 0;
            }
    }
    /* Members by leader, in node order. */
    for (size_t k = 0; k < nc; k++)
        if (ng->lead[k] >= 0 && (size_t)ng->lead[k] != k)
            ng->first[ng->lead[k] + 1]++;
    for (size_t k = 0; k < nc; k++)
        ng->first[k + 1] += ng->first[k];
    ng->member = malloc(((size_t)ng->members + 1) * sizeof *ng->member);
    int32_t *fill = malloc((nc + 1) * sizeof *fill);
    if (!ng->member || !fill) {
        free(fill);
        node_groups_free(ng);
        return 0;
    }
    memcpy(fill, ng->first, nc * sizeof *fill);
    for (size_t k = 0; k < nc; k++)
        if (ng->lead[k] >= 0 && (size_t)ng->lead[k] != k)
            ng->member[fill[ng->lead[k]]++] = (int32_t)k;
    free(fill);
    return 1;
}

void node_groups_free(node_groups *ng)
{
    free(ng->lead);
    free(ng->first);
    free(ng->member);
    memset(ng, 0, sizeof *ng);
}
