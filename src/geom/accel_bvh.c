/* The BVH backend's queries: the four-wide tree of bvh.h walked
 * iteratively, nearer children first.  The hit tests are those of shapes.h
 * (the triangle test lane by lane, with the same operations) and ties go
 * to the lowest part index, so the answers are the brute-force oracle's,
 * bit for bit. */
#include "geom/accel_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "geom/bvh.h"
#include "geom/shapes.h"
#include "util/error.h"

/* A tree is at most 40 + log2(n) + 1 levels deep (bvh_build.c) and each
 * level leaves at most BVH_WIDTH - 1 boxes on the stack. */
enum { STACK_SIZE = 256 };

/* Box slabs are widened by this factor so rounding in the slab test never
 * loses a box the exact test would keep (Ize, "Robust BVH Ray Traversal"). */
#define SLAB_ROUND_UP 1.0000005f

typedef struct bvh_accel {
    accel base;
    bvh_tree layer[2];
} bvh_accel;

typedef struct slab_ray {
    vec3f o, inv;
    int near[3];       /* per axis, which corner the ray enters by */
} slab_ray;

/* 1/d per component, in one vector division.  Finite for zero
 * components, so 0 * inv never makes a NaN. */
static inline vec3f inverse(vec3f d)
{
    f4 v = {d.x, d.y, d.z, 1.0f};
    f4 sign = (f4)((i4)v & (i4)f4_splat(-0.0f));
    f4 tiny = (f4)((i4)f4_splat(1e-20f) | (i4)sign);
    f4 mag = (f4)((i4)v & ~(i4)f4_splat(-0.0f));
    f4 inv = f4_splat(1.0f) / f4_select(mag > f4_splat(1e-20f), v, tiny);
    return f3(inv[0], inv[1], inv[2]);
}

static inline float fmin2(float a, float b) { return a < b ? a : b; }
static inline float fmax2(float a, float b) { return a > b ? a : b; }

/* The next float up from a positive finite t (nextafterf without the
 * library call). */
static inline float next_up(float t)
{
    uint32_t bits;
    memcpy(&bits, &t, sizeof bits);
    bits++;
    memcpy(&t, &bits, sizeof t);
    return t;
}

/* Where the ray enters each of the node's boxes within (0, tmax), or
 * INFINITY. */
static inline f4 node_entries(const bvh4_node *n, const slab_ray *r, float tmax)
{
    f4 ox = f4_splat(r->o.x), oy = f4_splat(r->o.y), oz = f4_splat(r->o.z);
    f4 ix = f4_splat(r->inv.x), iy = f4_splat(r->inv.y), iz = f4_splat(r->inv.z);
    f4 x0 = (n->bound[r->near[0]][0] - ox) * ix, x1 = (n->bound[1 - r->near[0]][0] - ox) * ix;
    f4 y0 = (n->bound[r->near[1]][1] - oy) * iy, y1 = (n->bound[1 - r->near[1]][1] - oy) * iy;
    f4 z0 = (n->bound[r->near[2]][2] - oz) * iz, z1 = (n->bound[1 - r->near[2]][2] - oz) * iz;
    f4 t0 = f4_max(f4_max(x0, y0), f4_max(z0, f4_splat(0.0f)));
    f4 t1 = f4_min(f4_min(x1, y1), f4_min(z1, f4_splat(tmax))) * f4_splat(SLAB_ROUND_UP);
    return f4_select(t0 <= t1, t0, f4_splat(INFINITY));
}

/* shape_triangle_hit on each lane, operation for operation: the lanes
 * with a hit in (0, tmax) as bits, their distances in *t. */
static inline int triangle_packet(const bvh_packet *q, vec3f o, vec3f d,
                                  float tmax, f4 *t)
{
    f4 dx = f4_splat(d.x), dy = f4_splat(d.y), dz = f4_splat(d.z);
    const f4 *e1 = q->e1, *e2 = q->e2;
    f4 pvx = dy * e2[2] - dz * e2[1];
    f4 pvy = dz * e2[0] - dx * e2[2];
    f4 pvz = dx * e2[1] - dy * e2[0];
    f4 det = e1[0] * pvx + e1[1] * pvy + e1[2] * pvz;
    f4 inv = f4_splat(1.0f) / det;
    f4 tvx = f4_splat(o.x) - q->p0[0], tvy = f4_splat(o.y) - q->p0[1],
       tvz = f4_splat(o.z) - q->p0[2];
    f4 u = (tvx * pvx + tvy * pvy + tvz * pvz) * inv;
    f4 qvx = tvy * e1[2] - tvz * e1[1];
    f4 qvy = tvz * e1[0] - tvx * e1[2];
    f4 qvz = tvx * e1[1] - tvy * e1[0];
    f4 v = (dx * qvx + dy * qvy + dz * qvz) * inv;
    *t = (e2[0] * qvx + e2[1] * qvy + e2[2] * qvz) * inv;
    f4 zero = f4_splat(0.0f), one = f4_splat(1.0f);
    i4 miss = (q->culled & (det <= zero)) | (~q->culled & (det == zero)) |
              (u < zero) | (u > one) | (v < zero) | (u + v > one);
    i4 hit = ~miss & (*t > zero) & (*t < f4_splat(tmax));
    return i4_bits(hit);
}

static inline int sphere_packet(const bvh_packet *q, vec3f o, vec3f d,
                                float tmax, f4 *t)
{
    int bits = 0;
    for (int i = 0; i < BVH_WIDTH; i++) {
        if (q->part[i] < 0)
            continue;
        /* Only the fields the sphere test reads are set. */
        rs_part p;
        p.p0 = f3(q->p0[0][i], q->p0[1][i], q->p0[2][i]);
        p.radius = q->radius[i];
        p.culled = q->culled[i] != 0;
        (*t)[i] = shape_sphere_hit(&p, o, d, 0.0f, tmax);
        if ((*t)[i] > 0.0f)
            bits |= 1 << i;
    }
    return bits;
}

typedef struct stack_entry {
    int32_t ref;
    float entry;
} stack_entry;

/* Nearest hit below h->t (any = 0), or whether there is one (any = 1).
 * Always inlined, so each query gets its own copy with `any` a constant
 * (GCC otherwise kept one copy testing it at run time). */
__attribute__((always_inline))
static inline int traverse(const bvh_tree *tr, vec3f o, vec3f d, hit *h,
                           int any)
{
    if (tr->node_count == 0)
        return 0;
    slab_ray r = {o, inverse(d), {0}};
    r.near[0] = r.inv.x < 0.0f;
    r.near[1] = r.inv.y < 0.0f;
    r.near[2] = r.inv.z < 0.0f;
    float best = h->t;
    /* After a hit, equal distances are let through so the lower part index
     * can win a tie, as it does in the oracle's loop. */
    float limit = best;
    int found = 0;
    stack_entry stack[STACK_SIZE];
    int sp = 0;
    int32_t ref = 0;
    for (;;) {
        if (ref >= 0) {
            const bvh4_node *n = &tr->nodes[ref];
            f4 e = node_entries(n, &r, limit);
            int bits = i4_bits(e != f4_splat(INFINITY));
            /* The boxes entered, nearest first (any order will do for
             * visibility). */
            stack_entry in[BVH_WIDTH];
            int m = 0;
            for (; bits; bits &= bits - 1) {
                int i = __builtin_ctz((unsigned)bits);
                int j = m++;
                while (!any && j > 0 && in[j - 1].entry > e[i]) {
                    in[j] = in[j - 1];
                    j--;
                }
                in[j] = (stack_entry){n->child[i], e[i]};
            }
            if (m > 0) {
                for (int j = m - 1; j > 0; j--)
                    stack[sp++] = in[j];
                ref = in[0].ref;
                continue;
            }
        } else {
            int32_t leaf = ~ref;
            int first = leaf >> BVH_LEAF_BITS;
            int end = first + (leaf & BVH_LEAF_MAX_PACKETS);
            for (int k = first; k < end; k++) {
                const bvh_packet *q = &tr->packets[k];
                f4 t;
                int bits = q->shape == SHAPE_TRIANGLE
                               ? triangle_packet(q, o, d, limit, &t)
                               : sphere_packet(q, o, d, limit, &t);
                for (; bits; bits &= bits - 1) {
                    int i = __builtin_ctz((unsigned)bits);
                    if (!(t[i] < limit && (t[i] < best || q->part[i] < h->part)))
                        continue;
                    if (any)
                        return 1;
                    best = t[i];
                    limit = next_up(best);
                    h->t = best;
                    h->part = q->part[i];
                    found = 1;
                }
            }
        }
        /* Pop the next box that may still hold something nearer. */
        for (;;) {
            if (sp == 0)
                return found;
            sp--;
            if (stack[sp].entry <= limit * SLAB_ROUND_UP) {
                ref = stack[sp].ref;
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
    for (int l = 0; l < 2; l++)
        bvh_tree_free(&b->layer[l]);
    free(b);
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
        if (!bvh_build(&b->layer[l], rs, l)) {
            bvh_destroy(&b->base);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory building the BVH");
        }
    rs->accel = &b->base;
    return ZT_OK;
}
