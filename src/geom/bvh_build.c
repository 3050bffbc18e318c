/* Building the BVH backend's tree: a binary tree by binned SAH over the
 * layer's triangles and spheres, then collapsed into four-wide nodes (each
 * node takes the children of its largest inner children until it has
 * four) with the leaves' primitives packed into packets of four. */
#include "geom/bvh.h"
#include "render/prim.h"
#include "util/select_nth.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

enum {
    BINS = 16,
    LEAF_MAX = 8,     /* larger ranges are always split */
    SAH_DEPTH = 40    /* below this, split by count: depth <= 40 + log2(n) */
};

/* A leaf's primitives fill at most this many packets (triangles and
 * spheres apart), which its child reference must be able to count. */
_Static_assert(2 * ((LEAF_MAX + BVH_WIDTH - 1) / BVH_WIDTH) <= BVH_LEAF_MAX_PACKETS,
               "a leaf's packets fit its reference");

static inline float fmin2(float a, float b) { return a < b ? a : b; }
static inline float fmax2(float a, float b) { return a > b ? a : b; }

typedef struct box {
    float lo[3], hi[3];
} box;

/* A node of the binary tree: its box and, for leaves (count > 0), its
 * primitives refs[index, index + count); inner nodes have the left child
 * next and the right child at index. */
typedef struct bin_node {
    box b;
    int32_t index;
    int32_t count;
} bin_node;

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
    bin_node *nodes;
    int node_count;
} builder;

/* The SAH counts packets of primitives, which cost the same to test
 * whether they hold one primitive or four; a packet test costs about two
 * box tests (callgrind on the Cornell box: equal costs made a deeper tree
 * and 6% more instructions per path). */
#define PACKET_COST 2.0f
#define NODE_COST 1.0f

static float packets(int n)
{
    return (float)((n + BVH_WIDTH - 1) / BVH_WIDTH);
}

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
            right_cost[k] = n ? half_area(&acc) * packets(n) : -1.0f;
        }
        acc = box_empty();
        n = 0;
        for (int k = 1; k < BINS; k++) {
            box_grow(&acc, &bins[a][k - 1]);
            n += count[a][k - 1];
            if (n == 0 || right_cost[k] < 0.0f)
                continue;
            float cost = half_area(&acc) * packets(n) + right_cost[k];
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

DEFINE_SELECT_NTH(select_nth, prim_ref, centre)

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
        float leaf = half_area(nb) * packets(n) * PACKET_COST;
        if (n <= LEAF_MAX && leaf <= cost * PACKET_COST + half_area(nb) * NODE_COST)
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
    select_nth(b->refs + begin, end - begin, mid - begin, axis);
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
    bin_node *n = &b->nodes[ni];
    for (int a = 0; a < 3; a++) {
        n->b.lo[a] = nb.lo[a];
        n->b.hi[a] = nb.hi[a];
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

/* ---- collapsing into four-wide nodes ---- */

typedef struct collapser {
    const bin_node *bin;
    const prim_ref *refs;
    const rscene *rs;
    bvh_tree *tr;
} collapser;

static void packet_init(bvh_packet *q, int shape)
{
    for (int i = 0; i < BVH_WIDTH; i++) {
        for (int a = 0; a < 3; a++)
            q->p0[a][i] = q->e1[a][i] = q->e2[a][i] = q->n[a][i] = 0.0f;
        q->radius[i] = 0.0f;
        q->culled[i] = 0;
        q->part[i] = -1;
    }
    q->shape = shape;
}

static void lane_put(f4 dst[3], int lane, vec3f v)
{
    dst[0][lane] = v.x;
    dst[1][lane] = v.y;
    dst[2][lane] = v.z;
}

static void packet_set(bvh_packet *q, int lane, const rs_part *p, int part)
{
    lane_put(q->p0, lane, p->p0);
    if (p->shape == SHAPE_SPHERE) {
        lane_put(q->e1, lane, p->c_lo);
        q->e2[0][lane] = p->r_lo;
    } else {
        lane_put(q->e1, lane, p->e1);
        lane_put(q->e2, lane, p->e2);
    }
    lane_put(q->n, lane, p->n);
    q->radius[lane] = p->radius;
    q->culled[lane] = p->culled ? -1 : 0;
    q->part[lane] = part;
}

/* Packs the binary leaf's primitives (triangles, then spheres) into new
 * packets and returns the leaf's child reference. */
static int32_t pack_leaf(collapser *c, const bin_node *leaf)
{
    bvh_tree *tr = c->tr;
    int first = tr->packet_count;
    static const int shapes[2] = {SHAPE_TRIANGLE, SHAPE_SPHERE};
    for (int s = 0; s < 2; s++) {
        int lane = BVH_WIDTH;
        for (int k = leaf->index; k < leaf->index + leaf->count; k++) {
            int part = c->refs[k].part;
            rs_part tmp;
            const rs_part *p = rs_prim(c->rs, part, &tmp);
            if (p->shape != shapes[s])
                continue;
            if (lane == BVH_WIDTH) {
                packet_init(&tr->packets[tr->packet_count++], shapes[s]);
                lane = 0;
            }
            packet_set(&tr->packets[tr->packet_count - 1], lane++, p, part);
        }
    }
    return ~(int32_t)((first << BVH_LEAF_BITS) | (tr->packet_count - first));
}

static float bin_area(const bin_node *n)
{
    const box *b = &n->b;
    float x = b->hi[0] - b->lo[0], y = b->hi[1] - b->lo[1], z = b->hi[2] - b->lo[2];
    return x * y + y * z + z * x;
}

/* The four-wide node for binary node bi (or, for a binary leaf, a node
 * with that leaf as its only child); returns its index. */
static int collapse(collapser *c, int bi)
{
    const bin_node *bin = c->bin;
    int kids[BVH_WIDTH], n = 0;
    if (bin[bi].count > 0) {
        kids[n++] = bi;
    } else {
        kids[n++] = bi + 1;
        kids[n++] = bin[bi].index;
    }
    /* Open the largest inner child while there is room: the big boxes are
     * the ones most rays enter. */
    while (n < BVH_WIDTH) {
        int open = -1;
        float area = -1.0f;
        for (int k = 0; k < n; k++)
            if (bin[kids[k]].count == 0 && bin_area(&bin[kids[k]]) > area) {
                area = bin_area(&bin[kids[k]]);
                open = k;
            }
        if (open < 0)
            break;
        int o = kids[open];
        kids[open] = o + 1;
        kids[n++] = bin[o].index;
    }
    int ni = c->tr->node_count++;
    for (int k = 0; k < BVH_WIDTH; k++) {
        bvh4_node *node = &c->tr->nodes[ni];
        if (k >= n) {
            /* An empty box: every ray misses it. */
            for (int a = 0; a < 3; a++) {
                node->bound[0][a][k] = INFINITY;
                node->bound[1][a][k] = -INFINITY;
            }
            node->child[k] = 0;
            continue;
        }
        const bin_node *kid = &bin[kids[k]];
        for (int a = 0; a < 3; a++) {
            node->bound[0][a][k] = kid->b.lo[a];
            node->bound[1][a][k] = kid->b.hi[a];
        }
        int32_t ref = kid->count > 0 ? pack_leaf(c, kid) : collapse(c, kids[k]);
        c->tr->nodes[ni].child[k] = ref;
    }
    return ni;
}

int bvh_build(bvh_tree *tr, const rscene *rs, int layer)
{
    tr->nodes = NULL;
    tr->packets = NULL;
    tr->node_count = tr->packet_count = 0;
    int count = 0;
    for (int i = 0; i < rs->prim_count; i++) {
        rs_part tmp;
        count += in_layer(rs_prim(rs, i, &tmp), layer);
    }
    if (count == 0)
        return 1;
    prim_ref *refs = malloc((size_t)count * sizeof *refs);
    bin_node *bin = malloc((size_t)(2 * count - 1) * sizeof *bin);
    /* At most one four-wide node per binary inner node (and one for a
     * lone leaf), and at most one packet per primitive. */
    tr->nodes = malloc((size_t)count * sizeof *tr->nodes);
    tr->packets = malloc((size_t)count * sizeof *tr->packets);
    if (!refs || !bin || !tr->nodes || !tr->packets) {
        free(refs);
        free(bin);
        bvh_tree_free(tr);
        return 0;
    }
    int k = 0;
    for (int i = 0; i < rs->prim_count; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, i, &tmp);
        if (in_layer(p, layer)) {
            refs[k].b = part_box(p);
            refs[k++].part = i;
        }
    }
    builder b = {refs, bin, 0};
    build_node(&b, 0, count, 0);
    collapser c = {bin, refs, rs, tr};
    collapse(&c, 0);
    free(refs);
    free(bin);
    return 1;
}

void bvh_tree_free(bvh_tree *tr)
{
    free(tr->nodes);
    free(tr->packets);
    tr->nodes = NULL;
    tr->packets = NULL;
    tr->node_count = tr->packet_count = 0;
}
