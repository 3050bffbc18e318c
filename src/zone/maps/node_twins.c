/* Nodes computed once for two triangles (node_twins.h). */
#include "zone/maps/node_twins.h"

#include <math.h>
#include <stdlib.h>

#include "render/prim.h"

/* Twins agree to rounding: positions within this share of the edge's
 * length, normals within this cosine.  A pair that does not (a mesh whose
 * two triangles disagree about a vertex) is computed twice. */
#define SAME_POINT 1e-5
#define SAME_NORMAL 0.99999

/* One edge node: the edge by its vertices (lower index first) and the
 * node's place on it as a reduced fraction from the lower vertex. */
typedef struct edge_node {
    int32_t mesh, side;
    uint32_t v0, v1;
    int32_t num, den;
    int32_t node;
} edge_node;

static int gcd(int a, int b)
{
    while (b) {
        int t = a % b;
        a = b;
        b = t;
    }
    return a;
}

static int cmp_u(uint32_t a, uint32_t b) { return (a > b) - (a < b); }
static int cmp_i(int32_t a, int32_t b) { return (a > b) - (a < b); }

/* Key order, then node order: a group's first record is its lowest node. */
static int cmp_edge_node(const void *pa, const void *pb)
{
    const edge_node *a = pa, *b = pb;
    int c;
    if ((c = cmp_i(a->mesh, b->mesh)) || (c = cmp_i(a->side, b->side)) ||
        (c = cmp_u(a->v0, b->v0)) || (c = cmp_u(a->v1, b->v1)) || (c = cmp_i(a->num, b->num)) ||
        (c = cmp_i(a->den, b->den)))
        return c;
    return cmp_i(a->node, b->node);
}

static int same_key(const edge_node *a, const edge_node *b)
{
    return a->mesh == b->mesh && a->side == b->side && a->v0 == b->v0 && a->v1 == b->v1 &&
           a->num == b->num && a->den == b->den;
}

static int coincide(const surface_nodes *sn, int32_t a, int32_t b, double length)
{
    double d2 = 0, dot = 0;
    for (int q = 0; q < 3; q++) {
        double d = (double)sn->pos[3 * (size_t)a + q] - sn->pos[3 * (size_t)b + q];
        d2 += d * d;
        dot += (double)sn->nrm[3 * (size_t)a + q] * sn->nrm[3 * (size_t)b + q];
    }
    return sqrt(d2) <= SAME_POINT * length && dot >= SAME_NORMAL;
}

int node_twins_build(node_twins *tw, const surface_nodes *sn, const rscene *rs)
{
    tw->of = NULL;
    tw->count = 0;
    size_t count = 0;
    for (int prim = rs->part_count; prim < sn->prim_count; prim++) {
        const node_prim *np = &sn->prim[prim];
        if (np->kind == NODE_TRIANGLE && np->shared && np->n >= 2)
            count += (size_t)3 * (np->n - 1) * np->sides;
    }
    if (count == 0)
        return 1;
    edge_node *e = malloc(count * sizeof *e);
    if (!e)
        return 0;
    size_t m = 0;
    for (int prim = rs->part_count; prim < sn->prim_count; prim++) {
        const node_prim *np = &sn->prim[prim];
        if (np->kind != NODE_TRIANGLE || !np->shared || np->n < 2)
            continue;
        const rs_mesh *mm = rs_mesh_of(rs, prim);
        const uint32_t *v = rs_mesh_tri(mm, prim);
        int n = np->n;
        /* Edge c runs from corner a[c] to b[c]; step s of it is grid point
         * (i, j). */
        static const int ca[3] = {0, 0, 1}, cb[3] = {1, 2, 2};
        for (int side = 0; side < np->sides; side++)
            for (int c = 0; c < 3; c++)
                for (int s = 1; s < n; s++) {
                    int i = c == 0 ? s : c == 1 ? 0 : n - s, j = c == 0 ? 0 : s;
                    int32_t k = surface_tri_node(sn, rs, prim, side, i, j);
                    if (!sn->live[k])
                        continue;
                    uint32_t va = v[ca[c]], vb = v[cb[c]];
                    int from = va < vb ? s : n - s, g = gcd(from, n);
                    e[m++] = (edge_node){(int32_t)(mm - rs->meshes), side, va < vb ? va : vb,
                                         va < vb ? vb : va, from / g, n / g, k};
                }
    }
    qsort(e, m, sizeof *e, cmp_edge_node);
    tw->of = malloc(((size_t)sn->node_count + 1) * sizeof *tw->of);
    if (!tw->of) {
        free(e);
        return 0;
    }
    for (int k = 0; k < sn->node_count; k++)
        tw->of[k] = -1;
    for (size_t a = 0; a < m;) {
        size_t b = a + 1;
        while (b < m && same_key(&e[a], &e[b]))
            b++;
        const rs_mesh *mm = &rs->meshes[e[a].mesh];
        vec3f p0 = rs_mesh_vertex(mm, e[a].v0), p1 = rs_mesh_vertex(mm, e[a].v1);
        double length = f3_length(f3_sub(p1, p0));
        for (size_t q = a + 1; q < b; q++)
            if (coincide(sn, e[a].node, e[q].node, length)) {
                tw->of[e[q].node] = e[a].node;
                tw->count++;
            }
        a = b;
    }
    free(e);
    return 1;
}

void node_twins_free(node_twins *tw)
{
    free(tw->of);
    tw->of = NULL;
    tw->count = 0;
}
