/* The occluder index (occluders.h): a binary tree of boxes, split at the
 * median of the longest axis, leaves of up to four primitives. */
#include "zone/light/occluders.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/prim.h"
#include "util/select_nth.h"

#define LEAF_SIZE 4

typedef struct ref {
    float lo[3], hi[3];
    float c[3];
    int32_t prim;
} ref;

static void prim_box(const rs_part *p, ref *r)
{
    if (p->shape == SHAPE_SPHERE) {
        for (int a = 0; a < 3; a++) {
            float c = a == 0 ? p->p0.x : a == 1 ? p->p0.y : p->p0.z;
            r->lo[a] = c - p->radius;
            r->hi[a] = c + p->radius;
        }
    } else {
        vec3f v[3] = {p->p0, f3_add(p->p0, p->e1), f3_add(p->p0, p->e2)};
        for (int a = 0; a < 3; a++) {
            float x0 = a == 0 ? v[0].x : a == 1 ? v[0].y : v[0].z;
            r->lo[a] = r->hi[a] = x0;
            for (int k = 1; k < 3; k++) {
                float x = a == 0 ? v[k].x : a == 1 ? v[k].y : v[k].z;
                r->lo[a] = fminf(r->lo[a], x);
                r->hi[a] = fmaxf(r->hi[a], x);
            }
        }
    }
    /* Padded a little: the exact tests work in double precision. */
    for (int a = 0; a < 3; a++) {
        float pad = 1e-5f * (fabsf(r->lo[a]) + fabsf(r->hi[a]) + (r->hi[a] - r->lo[a])) + 1e-30f;
        r->lo[a] -= pad;
        r->hi[a] += pad;
        r->c[a] = 0.5f * (r->lo[a] + r->hi[a]);
    }
}

static float ref_centre(const ref *r, int axis) { return r->c[axis]; }

DEFINE_SELECT_NTH(select_nth, ref, ref_centre)

typedef struct builder {
    occluder_index *ix;
    ref *refs;
} builder;

/* Fills node ni with refs [first, first + n); children are allocated as a
 * pair, so the right one follows the left. */
static void build(builder *b, int32_t ni, int first, int n, int depth)
{
    occluder_index *ix = b->ix;
    occ_node *node = &ix->nodes[ni];
    for (int a = 0; a < 3; a++) {
        node->lo[a] = INFINITY;
        node->hi[a] = -INFINITY;
    }
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = first; i < first + n; i++)
        for (int a = 0; a < 3; a++) {
            node->lo[a] = fminf(node->lo[a], b->refs[i].lo[a]);
            node->hi[a] = fmaxf(node->hi[a], b->refs[i].hi[a]);
            clo[a] = fminf(clo[a], b->refs[i].c[a]);
            chi[a] = fmaxf(chi[a], b->refs[i].c[a]);
        }
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[axis] - clo[axis])
            axis = a;
    if (n <= LEAF_SIZE || depth >= OCC_MAX_DEPTH || !(chi[axis] > clo[axis])) {
        node->left = -1 - first;
        node->count = n;
        return;
    }
    int half = n / 2;
    select_nth(b->refs + first, n, half, axis);
    int32_t l = ix->node_count;
    ix->node_count += 2;
    node->left = l;
    node->count = 0;
    build(b, l, first, half, depth + 1);
    build(b, l + 1, first + half, n - half, depth + 1);
}

int occluders_build(occluder_index *ix, const rscene *rs)
{
    memset(ix, 0, sizeof *ix);
    int n = 0;
    for (int i = 0; i < rs->prim_count; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, i, &tmp);
        n += p->shape == SHAPE_TRIANGLE || p->shape == SHAPE_SPHERE;
    }
    ref *refs = malloc(((size_t)n + 1) * sizeof *refs);
    ix->nodes = malloc((2 * (size_t)n + 1) * sizeof *ix->nodes);
    ix->prims = malloc(((size_t)n + 1) * sizeof *ix->prims);
    if (!refs || !ix->nodes || !ix->prims) {
        free(refs);
        occluders_free(ix);
        return 0;
    }
    int k = 0;
    for (int i = 0; i < rs->prim_count; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, i, &tmp);
        if (p->shape != SHAPE_TRIANGLE && p->shape != SHAPE_SPHERE)
            continue;
        prim_box(p, &refs[k]);
        refs[k++].prim = i;
    }
    ix->prim_count = n;
    if (n > 0) {
        builder b = {ix, refs};
        ix->node_count = 1;
        build(&b, 0, 0, n, 0);
        for (int i = 0; i < n; i++)
            ix->prims[i] = refs[i].prim;
    }
    free(refs);
    return 1;
}

void occluders_free(occluder_index *ix)
{
    free(ix->nodes);
    free(ix->prims);
    memset(ix, 0, sizeof *ix);
}

/* Whether box [lo, hi] may meet the region. */
static int box_meets(const occ_node *b, const occ_region *r)
{
    if (b->lo[0] > r->hi.x || b->hi[0] < r->lo.x || b->lo[1] > r->hi.y || b->hi[1] < r->lo.y ||
        b->lo[2] > r->hi.z || b->hi[2] < r->lo.z)
        return 0;
    for (int k = 0; k < r->planes; k++) {
        /* The box corner furthest along the plane's normal. */
        vec3 n = r->n[k];
        double x = n.x >= 0 ? b->hi[0] : b->lo[0];
        double y = n.y >= 0 ? b->hi[1] : b->lo[1];
        double z = n.z >= 0 ? b->hi[2] : b->lo[2];
        if (n.x * x + n.y * y + n.z * z + r->d[k] < 0)
            return 0;
    }
    return 1;
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

int occluders_query(const occluder_index *ix, const occ_region *r, int32_t *out, int max)
{
    if (ix->prim_count == 0)
        return 0;
    int32_t stack[OCC_STACK];
    int sp = 0, found = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const occ_node *node = &ix->nodes[stack[--sp]];
        if (!box_meets(node, r))
            continue;
        if (node->count > 0) {
            int first = -1 - node->left;
            for (int i = 0; i < node->count; i++) {
                /* Past max the caller needs only to know that: a point
                 * under a whole mesh would walk most of the index. */
                if (found == max)
                    return max + 1;
                out[found++] = ix->prims[first + i];
            }
        } else {
            stack[sp++] = node->left + 1;
            stack[sp++] = node->left;
        }
    }
    int kept = found < max ? found : max;
    qsort(out, (size_t)kept, sizeof *out, cmp_i32);
    return found;
}
