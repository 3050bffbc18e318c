/* The BVH backend: per layer, a binary tree over the triangles and spheres,
 * built with binned SAH, stored depth first in 32-byte nodes and walked
 * iteratively, nearer child first.  The hit tests are those of shapes.h and
 * ties go to the lowest part index, so the answers are the brute-force
 * oracle's, bit for bit. */
#include "geom/accel_internal.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "geom/shapes.h"
#include "util/error.h"

enum {
    BINS = 16,
    LEAF_MAX = 8,     /* larger ranges are always split */
    SAH_DEPTH = 40,   /* below this, split by count: depth <= 40 + log2(n) */
    STACK_SIZE = 128
};

/* Box slabs are widened by this factor so rounding in the slab test never
 * loses a box the exact test would keep (Ize, "Robust BVH Ray Traversal"). */
#define SLAB_ROUND_UP 1.0000005f

typedef struct bvh_node {
    float bound[2][3]; /* [0] low corner, [1] high corner */
    int32_t index;     /* leaf: first primitive; inner: right child */
    int32_t count;     /* leaf: primitives (> 0); inner: 0, left child next */
} bvh_node;

_Static_assert(sizeof(bvh_node) == 32, "BVH nodes are 32 bytes");

/* What the hit tests read, packed in tree order. */
typedef struct bvh_prim {
    vec3f p0, e1, e2;  /* triangle; a sphere's centre is p0 */
    float radius;
    int32_t part;
    uint8_t shape, culled;
} bvh_prim;

typedef struct bvh_tree {
    bvh_node *nodes;
    bvh_prim *prims;
    int node_count;
} bvh_tree;

typedef struct bvh_accel {
    accel base;
    bvh_tree layer[2];
} bvh_accel;

/* ---- queries ---- */

typedef struct slab_ray {
    vec3f o, inv;
    int near[3];       /* per axis, which corner the ray enters by */
} slab_ray;

static inline float inverse(float d)
{
    /* Finite for zero components, so 0 * inv never makes a NaN. */
    return 1.0f / (fabsf(d) > 1e-20f ? d : copysignf(1e-20f, d));
}

static inline float fmin2(float a, float b) { return a < b ? a : b; }
static inline float fmax2(float a, float b) { return a > b ? a : b; }

/* Where the ray enters the node's box within (0, tmax), or INFINITY. */
static inline float box_entry(const bvh_node *n, const slab_ray *r, float tmax)
{
    float x0 = (n->bound[r->near[0]][0] - r->o.x) * r->inv.x;
    float x1 = (n->bound[1 - r->near[0]][0] - r->o.x) * r->inv.x;
    float y0 = (n->bound[r->near[1]][1] - r->o.y) * r->inv.y;
    float y1 = (n->bound[1 - r->near[1]][1] - r->o.y) * r->inv.y;
    float z0 = (n->bound[r->near[2]][2] - r->o.z) * r->inv.z;
    float z1 = (n->bound[1 - r->near[2]][2] - r->o.z) * r->inv.z;
    float t0 = fmax2(fmax2(x0, y0), fmax2(z0, 0.0f));
    float t1 = fmin2(fmin2(x1, y1), fmin2(z1, tmax)) * SLAB_ROUND_UP;
    return t0 <= t1 ? t0 : INFINITY;
}

static inline float prim_hit(const bvh_prim *q, vec3f o, vec3f d, float tmax)
{
    /* Only the fields the shape tests read are set. */
    rs_part p;
    p.p0 = q->p0;
    p.culled = q->culled;
    if (q->shape == SHAPE_TRIANGLE) {
        p.e1 = q->e1;
        p.e2 = q->e2;
        return shape_triangle_hit(&p, o, d, 0.0f, tmax);
    }
    p.radius = q->radius;
    return shape_sphere_hit(&p, o, d, 0.0f, tmax);
}

typedef struct stack_entry {
    int node;
    float entry;
} stack_entry;

/* Nearest hit below h->t (any = 0), or whether there is one (any = 1). */
static inline int traverse(const bvh_tree *tr, vec3f o, vec3f d, hit *h,
                           int any)
{
    const bvh_node *nodes = tr->nodes;
    if (tr->node_count == 0)
        return 0;
    slab_ray r = {o, f3(inverse(d.x), inverse(d.y), inverse(d.z)), {0}};
    r.near[0] = r.inv.x < 0.0f;
    r.near[1] = r.inv.y < 0.0f;
    r.near[2] = r.inv.z < 0.0f;
    float tmax = h->t;
    /* After a hit, equal distances are let through so the lower part index
     * can win a tie, as it does in the oracle's loop. */
    float limit = tmax;
    int found = 0;
    if (box_entry(&nodes[0], &r, tmax) == INFINITY)
        return 0;
    stack_entry stack[STACK_SIZE];
    int sp = 0, ni = 0;
    for (;;) {
        const bvh_node *n = &nodes[ni];
        if (n->count > 0) {
            for (int k = n->index; k < n->index + n->count; k++) {
                const bvh_prim *q = &tr->prims[k];
                float t = prim_hit(q, o, d, limit);
                if (t > 0.0f && (t < tmax || q->part < h->part)) {
                    if (any)
                        return 1;
                    tmax = t;
                    limit = nextafterf(t, INFINITY);
                    h->t = t;
                    h->part = q->part;
                    found = 1;
                }
            }
        } else {
            int l = ni + 1, rc = n->index;
            float tl = box_entry(&nodes[l], &r, limit);
            float tr_ = box_entry(&nodes[rc], &r, limit);
            int near = tl <= tr_ ? l : rc, far = tl <= tr_ ? rc : l;
            float tnear = fmin2(tl, tr_), tfar = fmax2(tl, tr_);
            if (tnear != INFINITY) {
                if (tfar != INFINITY)
                    stack[sp++] = (stack_entry){far, tfar};
                ni = near;
                continue;
            }
        }
        /* Pop the next box that may still hold something nearer. */
        for (;;) {
            if (sp == 0)
                return found;
            sp--;
            if (stack[sp].entry <= limit * SLAB_ROUND_UP) {
                ni = stack[sp].node;
                break;
            }
        }
    }
}

static void bvh_nearest(const accel *a, int layer, vec3f o, vec3f d, hit *h)
{
    traverse(&((const bvh_accel *)a)->layer[layer], o, d, h, 0);
}

static int bvh_any(const accel *a, int layer, vec3f o, vec3f d, float tmax)
{
    hit h = {tmax, -1};
    return traverse(&((const bvh_accel *)a)->layer[layer], o, d, &h, 1);
}

static void bvh_destroy(accel *a)
{
    bvh_accel *b = (bvh_accel *)a;
    for (int l = 0; l < 2; l++) {
        free(b->layer[l].nodes);
        free(b->layer[l].prims);
    }
    free(b);
}

/* ---- construction ---- */

typedef struct box {
    float lo[3], hi[3];
} box;

/* A primitive during the build: its padded bounds and its part.  The
 * references are partitioned in place, so every pass reads memory in order. */
typedef struct prim_ref {
    box b;
    int part;
} prim_ref;

static box box_empty(void)
{
    box b = {{FLT_MAX, FLT_MAX, FLT_MAX}, {-FLT_MAX, -FLT_MAX, -FLT_MAX}};
    return b;
}

static void box_grow(box *b, const box *x)
{
    for (int a = 0; a < 3; a++) {
        b->lo[a] = fmin2(b->lo[a], x->lo[a]);
        b->hi[a] = fmax2(b->hi[a], x->hi[a]);
    }
}

static void box_add_point(box *b, const float p[3])
{
    for (int a = 0; a < 3; a++) {
        b->lo[a] = fmin2(b->lo[a], p[a]);
        b->hi[a] = fmax2(b->hi[a], p[a]);
    }
}

static float half_area(const box *b)
{
    float x = b->hi[0] - b->lo[0], y = b->hi[1] - b->lo[1],
          z = b->hi[2] - b->lo[2];
    return x < 0.0f ? 0.0f : x * y + y * z + z * x;
}

static float centre(const prim_ref *r, int axis)
{
    return 0.5f * (r->b.lo[axis] + r->b.hi[axis]);
}

/* The part's bounds, padded by a few units in the last place: the shape
 * tests round, and may accept a hit a hair outside the exact bounds. */
static box part_box(const rs_part *p)
{
    box b = box_empty();
    vec3f v[3] = {p->p0, f3_add(p->p0, p->e1), f3_add(p->p0, p->e2)};
    int corners = 3;
    if (p->shape == SHAPE_SPHERE) {
        float r = fabsf(p->radius);
        v[0] = f3_sub(p->p0, f3_splat(r));
        v[1] = f3_add(p->p0, f3_splat(r));
        corners = 2;
    }
    for (int k = 0; k < corners; k++)
        box_add_point(&b, (const float[3]){v[k].x, v[k].y, v[k].z});
    float m = 0.0f;
    for (int a = 0; a < 3; a++)
        m = fmax2(m, fmax2(fmax2(fabsf(b.lo[a]), fabsf(b.hi[a])),
                           b.hi[a] - b.lo[a]));
    float pad = 4e-6f * m + FLT_MIN;
    for (int a = 0; a < 3; a++) {
        b.lo[a] -= pad;
        b.hi[a] += pad;
    }
    return b;
}

typedef struct builder {
    prim_ref *refs;
    bvh_node *nodes;
    int node_count;
} builder;

/* Bins of the centroid bounds cb along one axis. */
typedef struct binning {
    float lo, scale;
} binning;

static binning binning_of(const box *cb, int axis)
{
    binning g = {cb->lo[axis], (float)BINS / (cb->hi[axis] - cb->lo[axis])};
    return g;
}

static int bin_of(binning g, float c)
{
    float f = (c - g.lo) * g.scale;
    if (!(f > 0.0f))
        return 0; /* also NaN, from a zero-width axis */
    return f < (float)BINS ? (int)f : BINS - 1;
}

/* The best binned SAH split of refs[begin, end), as axis and first bin of
 * the right side; its cost in half-area units, or FLT_MAX if none.  All
 * three axes are binned in one pass. */
static float sah_best(const builder *b, int begin, int end, const box *cb,
                      int *best_axis, int *best_bin)
{
    int count[3][BINS] = {{0}};
    box bins[3][BINS];
    binning g[3];
    for (int a = 0; a < 3; a++) {
        g[a] = binning_of(cb, a);
        for (int k = 0; k < BINS; k++)
            bins[a][k] = box_empty();
    }
    for (int i = begin; i < end; i++) {
        const prim_ref *r = &b->refs[i];
        for (int a = 0; a < 3; a++) {
            int k = bin_of(g[a], centre(r, a));
            count[a][k]++;
            box_grow(&bins[a][k], &r->b);
        }
    }
    float best = FLT_MAX;
    for (int a = 0; a < 3; a++) {
        if (!(cb->hi[a] > cb->lo[a]))
            continue;
        /* right_cost[k]: area times count of bins k.. */
        float right_cost[BINS];
        box acc = box_empty();
        int n = 0;
        for (int k = BINS - 1; k > 0; k--) {
            box_grow(&acc, &bins[a][k]);
            n += count[a][k];
            right_cost[k] = n ? half_area(&acc) * (float)n : -1.0f;
        }
        acc = box_empty();
        n = 0;
        for (int k = 1; k < BINS; k++) {
            box_grow(&acc, &bins[a][k - 1]);
            n += count[a][k - 1];
            if (n == 0 || right_cost[k] < 0.0f)
                continue;
            float cost = half_area(&acc) * (float)n + right_cost[k];
            if (cost < best) {
                best = cost;
                *best_axis = a;
                *best_bin = k;
            }
        }
    }
    return best;
}

static void swap_refs(prim_ref *a, prim_ref *b)
{
    prim_ref t = *a;
    *a = *b;
    *b = t;
}

/* Reorders refs[lo, hi) so that refs[nth] has the nth centre on axis. */
static void select_nth(prim_ref *refs, int lo, int hi, int nth, int axis)
{
    while (hi - lo > 1) {
        float pivot = centre(&refs[lo + (hi - lo) / 2], axis);
        int i = lo, j = hi - 1;
        while (i <= j) {
            while (centre(&refs[i], axis) < pivot)
                i++;
            while (centre(&refs[j], axis) > pivot)
                j--;
            if (i <= j)
                swap_refs(&refs[i++], &refs[j--]);
        }
        if (nth <= j)
            hi = j + 1;
        else if (nth >= i)
            lo = i;
        else
            return;
    }
}

/* Where to split refs[begin, end) (node bounds nb, centroid bounds cb), or
 * 0 for a leaf. */
static int choose_split(builder *b, int begin, int end, const box *nb,
                        const box *cb, int depth)
{
    int n = end - begin;
    if (n <= 1)
        return 0;
    int axis = 0, bin = 0;
    if (depth < SAH_DEPTH) {
        float cost = sah_best(b, begin, end, cb, &axis, &bin);
        /* Traversal and a primitive test are taken to cost the same. */
        float leaf = half_area(nb) * (float)n;
        if (n <= LEAF_MAX && leaf <= cost + half_area(nb))
            return 0;
        if (cost < FLT_MAX) {
            binning g = binning_of(cb, axis);
            int i = begin, j = end;
            while (i < j) {
                if (bin_of(g, centre(&b->refs[i], axis)) < bin)
                    i++;
                else
                    swap_refs(&b->refs[i], &b->refs[--j]);
            }
            return i;
        }
    } else if (n <= LEAF_MAX) {
        return 0;
    }
    /* No useful SAH split (or too deep): halve by count on the widest axis. */
    for (int a = 1; a < 3; a++)
        if (cb->hi[a] - cb->lo[a] > cb->hi[axis] - cb->lo[axis])
            axis = a;
    int mid = begin + n / 2;
    select_nth(b->refs, begin, end, mid, axis);
    return mid;
}

/* Builds the subtree of refs[begin, end) at the next free node, depth
 * first, and returns its index. */
static int build_node(builder *b, int begin, int end, int depth)
{
    int ni = b->node_count++;
    box nb = box_empty(), cb = box_empty();
    for (int i = begin; i < end; i++) {
        const prim_ref *r = &b->refs[i];
        box_grow(&nb, &r->b);
        box_add_point(&cb, (const float[3]){centre(r, 0), centre(r, 1), centre(r, 2)});
    }
    int mid = choose_split(b, begin, end, &nb, &cb, depth);
    bvh_node *n = &b->nodes[ni];
    for (int a = 0; a < 3; a++) {
        n->bound[0][a] = nb.lo[a];
        n->bound[1][a] = nb.hi[a];
    }
    if (mid == 0) {
        n->index = begin;
        n->count = end - begin;
    } else {
        n->count = 0;
        build_node(b, begin, mid, depth + 1);
        int right = build_node(b, mid, end, depth + 1);
        b->nodes[ni].index = right;
    }
    return ni;
}

static int in_layer(const rs_part *p, int layer)
{
    return p->background == layer &&
           (p->shape == SHAPE_TRIANGLE || p->shape == SHAPE_SPHERE);
}

static int build_tree(bvh_tree *tr, const rscene *rs, int layer)
{
    int count = 0;
    for (int i = 0; i < rs->part_count; i++)
        count += in_layer(&rs->parts[i], layer);
    if (count == 0)
        return 1;
    prim_ref *refs = malloc((size_t)count * sizeof *refs);
    tr->nodes = malloc((size_t)(2 * count - 1) * sizeof *tr->nodes);
    tr->prims = malloc((size_t)count * sizeof *tr->prims);
    if (!refs || !tr->nodes || !tr->prims) {
        free(refs);
        return 0;
    }
    int k = 0;
    for (int i = 0; i < rs->part_count; i++)
        if (in_layer(&rs->parts[i], layer)) {
            refs[k].b = part_box(&rs->parts[i]);
            refs[k++].part = i;
        }
    builder b = {refs, tr->nodes, 0};
    build_node(&b, 0, count, 0);
    tr->node_count = b.node_count;
    for (int i = 0; i < count; i++) {
        const rs_part *p = &rs->parts[refs[i].part];
        bvh_prim *q = &tr->prims[i];
        q->p0 = p->p0;
        q->e1 = p->e1;
        q->e2 = p->e2;
        q->radius = p->radius;
        q->part = refs[i].part;
        q->shape = p->shape;
        q->culled = p->culled;
    }
    free(refs);
    return 1;
}

zt_status accel_build_bvh(rscene *rs, zt_error *err)
{
    bvh_accel *b = calloc(1, sizeof *b);
    if (!b)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    b->base.nearest = bvh_nearest;
    b->base.any = bvh_any;
    b->base.destroy = bvh_destroy;
    for (int l = 0; l < 2; l++)
        if (!build_tree(&b->layer[l], rs, l)) {
            bvh_destroy(&b->base);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory building the BVH");
        }
    rs->accel = &b->base;
    return ZT_OK;
}
