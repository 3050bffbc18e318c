/* The BVH backend's queries: the four-wide tree of bvh.h walked
 * iteratively, nearer children first.  The hit tests are those of shapes.h
 * (the triangle test lane by lane, with the same operations) and ties go
 * to the lowest part index, so the answers are the brute-force oracle's,
 * bit for bit.
 *
 * Inline in a header so that accel_query.c can call it directly, without
 * the backend's function pointer: the call, the spills around it and the
 * ray's set-up were a fifth of a query on the Cornell box. */
#ifndef ZT_GEOM_BVH_TRAVERSE_H
#define ZT_GEOM_BVH_TRAVERSE_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "geom/bvh.h"
#include "geom/hit.h"
#include "geom/ray4.h"
#include "geom/shapes.h"

/* A tree is at most 40 + log2(n) + 1 levels deep (bvh_build.c) and each
 * level leaves at most BVH_WIDTH - 1 boxes on the stack. */
enum { BVH_STACK_SIZE = 256 };

/* Box slabs are widened by this factor so rounding in the slab test never
 * loses a box the exact test would keep (Ize, "Robust BVH Ray Traversal"). */
#define BVH_SLAB_ROUND_UP 1.0000005f

/* What the walk needs of a ray, computed once per query: the splatted
 * origin and direction, 1/d, and per axis the byte offsets into a node's
 * bounds of the corner the ray enters by and the one it leaves by (a row
 * of a constant table: copying it cost a dozen instructions a ray). */
typedef struct bvh_ray {
    ray4 r;
    f4 ix, iy, iz;
    vec3f o, d;
    const uint32_t *corner; /* enter x, y, z, then leave x, y, z */
} bvh_ray;

/* 1/d per component, in one vector division.  Finite for zero
 * components, so 0 * inv never makes a NaN. */
static inline f4 bvh_inverse(vec3f d)
{
    f4 v = {d.x, d.y, d.z, 1.0f};
    f4 sign = (f4)((i4)v & (i4)f4_splat(-0.0f));
    f4 tiny = (f4)((i4)f4_splat(1e-20f) | (i4)sign);
    f4 mag = (f4)((i4)v & ~(i4)f4_splat(-0.0f));
    return f4_splat(1.0f) / f4_select(mag > f4_splat(1e-20f), v, tiny);
}

static inline void bvh_ray_init(bvh_ray *b, const ray4 *r, vec3f o, vec3f d)
{
    f4 inv = bvh_inverse(d);
    /* 1/d keeps d's sign bit (a zero becomes +-1e20), so the corners are
     * chosen by d's own sign bits: the first node's loads then need not
     * wait for the division. */
    f4 dv = {d.x, d.y, d.z, 1.0f};
    int negative = i4_bits((i4)dv < i4_splat(0));
    b->r = *r;
    b->ix = f4_splat(inv[0]);
    b->iy = f4_splat(inv[1]);
    b->iz = f4_splat(inv[2]);
    b->o = o;
    b->d = d;
    /* By the signs of 1/d, the offsets of the entry and exit corners:
     * bound[c][a] sits at (3c + a) * 16 bytes.  A table, because GCC
     * computed them with about 30 instructions. */
    static const uint32_t corners[8][6] = {
        {0, 16, 32, 48, 64, 80}, {48, 16, 32, 0, 64, 80},
        {0, 64, 32, 48, 16, 80}, {48, 64, 32, 0, 16, 80},
        {0, 16, 80, 48, 64, 32}, {48, 16, 80, 0, 64, 32},
        {0, 64, 80, 48, 16, 32}, {48, 64, 80, 0, 16, 32}};
    b->corner = corners[negative & 7];
}

static inline f4 bvh_bound(const bvh4_node *n, uint32_t offset)
{
    f4 v;
    memcpy(&v, (const char *)n->bound + offset, sizeof v);
    return v;
}

/* The next float up from a positive finite t (nextafterf without the
 * library call). */
static inline float bvh_next_up(float t)
{
    uint32_t bits;
    memcpy(&bits, &t, sizeof bits);
    bits++;
    memcpy(&t, &bits, sizeof t);
    return t;
}

/* Where the ray enters each of the node's boxes, and as bits the boxes it
 * enters within (0, tmax) at a finite distance. */
static inline f4 bvh_node_entries(const bvh4_node *n, const bvh_ray *b, float tmax,
                                  int *bits)
{
    f4 x0 = (bvh_bound(n, b->corner[0]) - b->r.ox) * b->ix;
    f4 x1 = (bvh_bound(n, b->corner[3]) - b->r.ox) * b->ix;
    f4 y0 = (bvh_bound(n, b->corner[1]) - b->r.oy) * b->iy;
    f4 y1 = (bvh_bound(n, b->corner[4]) - b->r.oy) * b->iy;
    f4 z0 = (bvh_bound(n, b->corner[2]) - b->r.oz) * b->iz;
    f4 z1 = (bvh_bound(n, b->corner[5]) - b->r.oz) * b->iz;
    f4 t0 = f4_max(f4_max(x0, y0), f4_max(z0, f4_splat(0.0f)));
    f4 t1 = f4_min(f4_min(x1, y1), f4_min(z1, f4_splat(tmax))) * f4_splat(BVH_SLAB_ROUND_UP);
    *bits = i4_bits((t0 <= t1) & (t0 < f4_splat(INFINITY)));
    return t0;
}

/* shape_triangle_hit on each lane, operation for operation: the lanes
 * with a hit in (0, tmax) as bits, their distances in *t. */
static inline int bvh_triangle_packet(const bvh_packet *q, const ray4 *r,
                                      float tmax, f4 *t)
{
    f4 dx = r->dx, dy = r->dy, dz = r->dz;
    const f4 *e1 = q->e1, *e2 = q->e2;
    f4 tvx = r->ox - q->p0[0], tvy = r->oy - q->p0[1], tvz = r->oz - q->p0[2];
    const f4 *n = q->n;
    f4 dn = n[0] * dx + n[1] * dy + n[2] * dz;
    /* Lanes with dn = 0 get inf or NaN here and are misses below. */
    *t = -(n[0] * tvx + n[1] * tvy + n[2] * tvz) / dn;
    f4 zero = f4_splat(0.0f), one = f4_splat(1.0f);
    i4 in_range = (*t > zero) & (*t < f4_splat(tmax));
    /* No plane met within reach (a shadow ray ending just short of its
     * light): the rest of the test cannot accept a lane. */
    if (!i4_bits(in_range))
        return 0;
    f4 pvx = dy * e2[2] - dz * e2[1];
    f4 pvy = dz * e2[0] - dx * e2[2];
    f4 pvz = dx * e2[1] - dy * e2[0];
    f4 det = e1[0] * pvx + e1[1] * pvy + e1[2] * pvz;
    f4 inv = f4_splat(1.0f) / det;
    f4 u = (tvx * pvx + tvy * pvy + tvz * pvz) * inv;
    f4 qvx = tvy * e1[2] - tvz * e1[1];
    f4 qvy = tvz * e1[0] - tvx * e1[2];
    f4 qvz = tvx * e1[1] - tvy * e1[0];
    f4 v = (dx * qvx + dy * qvy + dz * qvz) * inv;
    i4 miss = (q->culled & ((det <= zero) | (dn >= zero))) |
              (~q->culled & ((det == zero) | (dn == zero))) |
              (u < zero) | (u > one) | (v < zero) | (u + v > one);
    i4 hit = ~miss & in_range;
    return i4_bits(hit);
}

static inline int bvh_sphere_packet(const bvh_packet *q, vec3f o, vec3f d,
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
        p.c_lo = f3(q->e1[0][i], q->e1[1][i], q->e1[2][i]); /* (bvh.h) */
        p.r_lo = q->e2[0][i];
        p.culled = q->culled[i] != 0;
        (*t)[i] = shape_sphere_hit(&p, o, d, 0.0f, tmax);
        if ((*t)[i] > 0.0f)
            bits |= 1 << i;
    }
    return bits;
}

typedef struct bvh_stack_entry {
    int32_t ref;
    float entry;
} bvh_stack_entry;

/* Nearest hit below h->t (any = 0), or whether there is one (any = 1).
 * Always inlined, so each query gets its own copy with `any` a constant
 * (GCC otherwise kept one copy testing it at run time). */
__attribute__((always_inline))
static inline int bvh_traverse(const bvh_tree *tr, const bvh_ray *b, hit *h,
                               int any)
{
    if (tr->node_count == 0)
        return 0;
    float best = h->t;
    /* After a hit, equal distances are let through so the lower part index
     * can win a tie, as it does in the oracle's loop. */
    float limit = best;
    int found = 0;
    bvh_stack_entry stack[BVH_STACK_SIZE];
    int sp = 0;
    int32_t ref = 0;
    for (;;) {
        if (ref >= 0) {
            const bvh4_node *n = &tr->nodes[ref];
            int bits;
            f4 e = bvh_node_entries(n, b, limit, &bits);
            /* The boxes entered, nearest first (any order will do for
             * visibility). */
            bvh_stack_entry in[BVH_WIDTH];
            int m = 0;
            for (; bits; bits &= bits - 1) {
                int i = __builtin_ctz((unsigned)bits);
                int j = m++;
                while (!any && j > 0 && in[j - 1].entry > e[i]) {
                    in[j] = in[j - 1];
                    j--;
                }
                in[j] = (bvh_stack_entry){n->child[i], e[i]};
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
                               ? bvh_triangle_packet(q, &b->r, limit, &t)
                               : bvh_sphere_packet(q, b->o, b->d, limit, &t);
                for (; bits; bits &= bits - 1) {
                    int i = __builtin_ctz((unsigned)bits);
                    if (!(t[i] < limit && (t[i] < best || q->part[i] < h->part)))
                        continue;
                    if (any)
                        return 1;
                    best = t[i];
                    limit = bvh_next_up(best);
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
            if (stack[sp].entry <= limit * BVH_SLAB_ROUND_UP) {
                ref = stack[sp].ref;
                break;
            }
        }
    }
}

#endif
