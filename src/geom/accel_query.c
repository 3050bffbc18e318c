/* The background rule, the planes and holes (coverage 0), around the
 * backends' raw queries. */
#include "geom/accel_internal.h"

#include <float.h>
#include <string.h>

#include "geom/bvh_traverse.h"
#include "geom/ray4.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "render/prim.h"
#include "util/simd4.h"

/* Planes: t = (offset - n.o) / (n.d), valid in (0, tmax) and, for culled
 * planes, only from the front.  Four planes at a time in vector lanes; a
 * failed division (n.d = 0) gives inf or nan, which compare false. */
static inline f4 plane_block(const rs_planes *pl, int base, const ray4 *r)
{
    f4 nx, ny, nz, off, cull;
    memcpy(&nx, pl->nx + base, sizeof nx);
    memcpy(&ny, pl->ny + base, sizeof ny);
    memcpy(&nz, pl->nz + base, sizeof nz);
    memcpy(&off, pl->offset + base, sizeof off);
    memcpy(&cull, pl->culled + base, sizeof cull);
    f4 dn = r->dx * nx + r->dy * ny + r->dz * nz;
    f4 on = r->ox * nx + r->oy * ny + r->oz * nz;
    /* Culled planes seen from behind: no hit. */
    i4 behind = (cull > f4_splat(0.0f)) & (dn >= f4_splat(0.0f));
    return f4_select(behind, f4_splat(-1.0f), (off - on) / dn);
}

/* Lowers *t and sets *part if a plane is hit nearer: the nearest plane,
 * the first one on a tie, as a loop over the planes in order would pick.
 * Per block, the nearest lane is found with vector minima instead of a
 * branch per lane (whose outcome is random: it was mispredicted). */
static inline void planes_nearest(const rscene *rs, int layer, const ray4 *r,
                                  float *t, int *part)
{
    const rs_planes *pl = &rs->planes[layer];
    for (int base = 0; base < pl->padded; base += PLANE_LANES) {
        f4 tp = plane_block(pl, base, r);
        i4 valid = (tp > f4_splat(0.0f)) & (tp < f4_splat(*t));
        if (!i4_bits(valid))
            continue;
        f4 near = f4_hmin(f4_select(valid, tp, f4_splat(INFINITY)));
        int i = __builtin_ctz((unsigned)i4_bits(valid & (tp == near)));
        *t = tp[i];
        *part = pl->part[base + i];
    }
}

static inline int planes_any(const rscene *rs, int layer, const ray4 *r, float tmax)
{
    const rs_planes *pl = &rs->planes[layer];
    for (int base = 0; base < pl->padded; base += PLANE_LANES) {
        f4 t = plane_block(pl, base, r);
        if (i4_bits((t > f4_splat(0.0f)) & (t < f4_splat(tmax))))
            return 1;
    }
    return 0;
}

/* The backend's nearest hit of one layer into (*t, *part). */
static inline void prims_nearest(const accel *a, int layer, const bvh_ray *b,
                                 float *t, int *part)
{
    if (!a->has_prims[layer])
        return;
    hit h = {*t, *part};
    if (a->bvh)
        bvh_traverse(&a->bvh[layer], b, &h, 0);
    else
        a->nearest(a, layer, b->o, b->d, &h);
    *t = h.t;
    *part = h.part;
}

static inline int prims_any(const accel *a, int layer, const bvh_ray *b, float tmax)
{
    if (!a->has_prims[layer])
        return 0;
    if (a->bvh) {
        hit h = {tmax, -1};
        return bvh_traverse(&a->bvh[layer], b, &h, 1);
    }
    return a->any(a, layer, b->o, b->d, tmax);
}

/* Holes (hits of coverage 0: rs_coverage_at) a query looks through
 * before it takes the next hit as solid: a ray through more layers of
 * leaves than this is lost in them anyway, and a ray cannot loop. */
#define HOLES_MAX 64

/* accel_intersect in a scene with coverage: a hit in a hole is no hit, the
 * search going on from just beyond it in the same layer.  The same for
 * every backend, so they agree as they do without holes. */
static hit intersect_through_holes(const rscene *rs, vec3f o, vec3f d)
{
    const accel *a = rs->accel;
    for (int layer = 0; layer < 2; layer++) {
        vec3f from = o;
        for (int k = 0;; k++) {
            ray4 r = ray4_make(from, d);
            bvh_ray b;
            bvh_ray_init(&b, &r, from, d);
            float t = FLT_MAX;
            int part = -1;
            prims_nearest(a, layer, &b, &t, &part);
            planes_nearest(rs, layer, &r, &t, &part);
            if (part < 0)
                break; /* nothing in this layer beyond the holes */
            rs_part tmp;
            const rs_part *p = rs_prim(rs, part, &tmp);
            const rs_object *m = &rs->objects[p->object];
            vec3f x = shape_hit_point(p, from, d, t);
            float dt = f3_dot(f3_sub(x, o), d);
            if (k == HOLES_MAX || rs_coverage(rs, part, p, m, x) > 0.0f)
                return (hit){k == 0 ? t : dt, part};
            vec3f ng = shape_normal(p, x);
            from = ray_offset(x, f3_dot(ng, d) > 0.0f ? ng : f3_neg(ng));
        }
    }
    hit none = {FLT_MAX, -1};
    return none;
}

hit accel_intersect(const rscene *rs, vec3f o, vec3f d)
{
    if (__builtin_expect(rs->alpha_count != 0, 0))
        return intersect_through_holes(rs, o, d);
    const accel *a = rs->accel;
    ray4 r = ray4_make(o, d);
    bvh_ray b;
    bvh_ray_init(&b, &r, o, d);
    for (int layer = 0; layer < 2; layer++) {
        /* The answer is built from locals, not from a struct the backend
         * wrote: that read stalled on store forwarding. */
        float t = FLT_MAX;
        int part = -1;
        prims_nearest(a, layer, &b, &t, &part);
        planes_nearest(rs, layer, &r, &t, &part);
        if (part >= 0)
            return (hit){t, part};
    }
    hit none = {FLT_MAX, -1};
    return none;
}

int accel_occluded(const rscene *rs, vec3f o, vec3f d, float dist,
                   int target_is_background)
{
    if (__builtin_expect(rs->alpha_count != 0, 0)) {
        /* The nearest hit that is not a hole, under the same rule: a
         * foreground target is hidden by a foreground hit before it, a
         * background one by any foreground hit or a background one
         * before it. */
        hit h = intersect_through_holes(rs, o, d);
        if (h.part < 0)
            return 0;
        rs_part tmp;
        int bg = rs_prim(rs, h.part, &tmp)->background;
        return target_is_background ? (!bg || h.t < dist) : (!bg && h.t < dist);
    }
    const accel *a = rs->accel;
    ray4 r = ray4_make(o, d);
    bvh_ray b;
    bvh_ray_init(&b, &r, o, d);
    float fg_reach = target_is_background ? FLT_MAX : dist;
    if (planes_any(rs, 0, &r, fg_reach) || prims_any(a, 0, &b, fg_reach))
        return 1;
    if (target_is_background &&
        (planes_any(rs, 1, &r, dist) || prims_any(a, 1, &b, dist)))
        return 1;
    return 0;
}

/* Rays accel_occluded_n takes at a time. */
#define ACCEL_N_MAX 64

/* One layer's primitives for the rays not yet hidden. */
static void prims_any_n(const accel *a, int layer, vec3f o, const vec3f *d, const float *tmax,
                        int n, unsigned char *hidden)
{
    if (!a->has_prims[layer])
        return;
    if (a->any_n) {
        a->any_n(a, layer, o, d, tmax, n, hidden);
        return;
    }
    for (int i = 0; i < n; i++)
        if (!hidden[i]) {
            ray4 r = ray4_make(o, d[i]);
            bvh_ray b;
            bvh_ray_init(&b, &r, o, d[i]);
            hidden[i] = (unsigned char)prims_any(a, layer, &b, tmax[i]);
        }
}

void accel_occluded_n(const rscene *rs, vec3f o, const vec3f *d, const float *dist, int n,
                      int target_is_background, unsigned char *hidden)
{
    if (__builtin_expect(rs->alpha_count != 0, 0) || n <= 1) {
        for (int i = 0; i < n; i++)
            hidden[i] = (unsigned char)accel_occluded(rs, o, d[i], dist[i], target_is_background);
        return;
    }
    const accel *a = rs->accel;
    /* The rule of accel_occluded, lane by lane: the foreground up to the
     * target (or everywhere, for a background target), then the
     * background before it. */
    float reach[ACCEL_N_MAX];
    for (int base = 0; base < n; base += ACCEL_N_MAX) {
        int m = n - base < ACCEL_N_MAX ? n - base : ACCEL_N_MAX;
        const vec3f *dd = d + base;
        unsigned char *hh = hidden + base;
        for (int i = 0; i < m; i++) {
            reach[i] = target_is_background ? FLT_MAX : dist[base + i];
            ray4 r = ray4_make(o, dd[i]);
            hh[i] = (unsigned char)planes_any(rs, 0, &r, reach[i]);
        }
        prims_any_n(a, 0, o, dd, reach, m, hh);
        if (!target_is_background)
            continue;
        for (int i = 0; i < m; i++)
            if (!hh[i]) {
                ray4 r = ray4_make(o, dd[i]);
                hh[i] = (unsigned char)planes_any(rs, 1, &r, dist[base + i]);
            }
        prims_any_n(a, 1, o, dd, dist + base, m, hh);
    }
}

/* Ray i from o[i * o_step] along d[i] (accel_intersect_n,
 * accel_intersect_rays). */
static void intersect_n(const rscene *rs, const vec3f *o, int o_step, const vec3f *d, int n,
                        hit *h)
{
    const accel *a = rs->accel;
    if (__builtin_expect(rs->alpha_count != 0, 0) || n <= 1 || !a->nearest_n) {
        for (int i = 0; i < n; i++)
            h[i] = accel_intersect(rs, o[i * o_step], d[i]);
        return;
    }
    /* accel_intersect's order lane by lane: a layer's primitives, then its
     * planes; the background only for rays the foreground missed. */
    unsigned char want[ACCEL_N_MAX];
    for (int base = 0; base < n; base += ACCEL_N_MAX) {
        int m = n - base < ACCEL_N_MAX ? n - base : ACCEL_N_MAX;
        const vec3f *ob = o + base * o_step;
        hit *hh = h + base;
        for (int i = 0; i < m; i++) {
            hh[i] = (hit){FLT_MAX, -1};
            want[i] = 1;
        }
        for (int layer = 0; layer < 2; layer++) {
            if (a->has_prims[layer])
                a->nearest_n(a, layer, ob, o_step, d + base, m, want, hh);
            for (int i = 0; i < m; i++) {
                if (!want[i])
                    continue;
                ray4 r = ray4_make(ob[i * o_step], d[base + i]);
                planes_nearest(rs, layer, &r, &hh[i].t, &hh[i].part);
                if (hh[i].part >= 0)
                    want[i] = 0;
            }
        }
        for (int i = 0; i < m; i++)
            if (hh[i].part < 0)
                hh[i] = (hit){FLT_MAX, -1};
    }
}

void accel_intersect_n(const rscene *rs, vec3f o, const vec3f *d, int n, hit *h)
{
    intersect_n(rs, &o, 0, d, n, h);
}

void accel_intersect_rays(const rscene *rs, const vec3f *o, const vec3f *d, int n, hit *h)
{
    intersect_n(rs, o, 1, d, n, h);
}

int accel_nearest_all_sides(const rscene *rs, vec3f o, vec3f d, float tmax, hit *h)
{
    const accel *a = rs->accel;
    if (!a->nearest_all_sides)
        return 0;
    hit best = {tmax, -1};
    for (int layer = 0; layer < 2; layer++)
        if (a->has_prims[layer])
            a->nearest_all_sides(a, layer, o, d, &best);
    *h = best.part >= 0 ? best : (hit){FLT_MAX, -1};
    return 1;
}

void accel_free(struct accel *a)
{
    if (a)
        a->destroy(a);
}


zt_status accel_build(rscene *rs, accel_kind kind, zt_error *err)
{
    zt_status st = ZT_ERR_ARGUMENT;
    switch (kind) {
    case ACCEL_EMBREE: st = accel_build_embree(rs, err); break;
    case ACCEL_BRUTE: st = accel_build_brute(rs, err); break;
    case ACCEL_BVH: st = accel_build_bvh(rs, err); break;
    }
    if (st != ZT_OK)
        return st;
    for (int i = 0; i < rs->part_count; i++) {
        const rs_part *p = &rs->parts[i];
        if (p->shape == SHAPE_TRIANGLE || p->shape == SHAPE_SPHERE)
            rs->accel->has_prims[p->background] = 1;
    }
    for (int k = 0; k < rs->mesh_count; k++)
        rs->accel->has_prims[rs->meshes[k].background] = 1;
    return ZT_OK;
}
