/* The background rule and the planes, around the backends' raw queries. */
#include "geom/accel_internal.h"

#include <float.h>

#include "geom/shapes.h"

/* Planes: t = (offset - n.o) / (n.d), valid in (0, tmax) and, for culled
 * planes, only from the front.  All planes of a layer are computed at once
 * in fixed-width blocks the compiler turns into vector code; a failed
 * division (n.d = 0) gives inf or nan, which compare false. */
static inline void plane_block(const rs_planes *pl, int base, vec3f o, vec3f d,
                               float *restrict t)
{
    const float *restrict nx = pl->nx + base, *restrict ny = pl->ny + base;
    const float *restrict nz = pl->nz + base, *restrict off = pl->offset + base;
    const float *restrict cull = pl->culled + base;
    for (int i = 0; i < PLANE_LANES; i++) {
        float dn = d.x * nx[i] + d.y * ny[i] + d.z * nz[i];
        float on = o.x * nx[i] + o.y * ny[i] + o.z * nz[i];
        float ti = (off[i] - on) / dn;
        /* Culled planes seen from behind: no hit.  Arithmetic instead of a
         * branch keeps the loop vectorisable (inf/nan still compare false). */
        float m = (float)((cull[i] > 0.0f) & (dn >= 0.0f));
        t[i] = ti * (1.0f - m) - m;
    }
}

static void planes_nearest(const rscene *rs, int layer, vec3f o, vec3f d, hit *h)
{
    const rs_planes *pl = &rs->planes[layer];
    float t[PLANE_LANES];
    float best = h->t;
    int part = h->part;
    for (int base = 0; base < pl->padded; base += PLANE_LANES) {
        plane_block(pl, base, o, d, t);
        for (int i = 0; i < PLANE_LANES; i++) {
            int better = t[i] > 0.0f && t[i] < best;
            best = better ? t[i] : best;
            part = better ? pl->part[base + i] : part;
        }
    }
    h->t = best;
    h->part = part;
}

static int planes_any(const rscene *rs, int layer, vec3f o, vec3f d, float tmax)
{
    const rs_planes *pl = &rs->planes[layer];
    float t[PLANE_LANES];
    for (int base = 0; base < pl->padded; base += PLANE_LANES) {
        plane_block(pl, base, o, d, t);
        int any = 0;
        for (int i = 0; i < PLANE_LANES; i++)
            any |= t[i] > 0.0f && t[i] < tmax;
        if (any)
            return 1;
    }
    return 0;
}

hit accel_intersect(const rscene *rs, vec3f o, vec3f d)
{
    const accel *a = rs->accel;
    for (int layer = 0; layer < 2; layer++) {
        hit h = {FLT_MAX, -1};
        a->nearest(a, layer, o, d, &h);
        planes_nearest(rs, layer, o, d, &h);
        if (h.part >= 0)
            return h;
    }
    hit none = {FLT_MAX, -1};
    return none;
}

int accel_occluded(const rscene *rs, vec3f o, vec3f d, float dist,
                   int target_is_background)
{
    const accel *a = rs->accel;
    float fg_reach = target_is_background ? FLT_MAX : dist;
    if (planes_any(rs, 0, o, d, fg_reach) || a->any(a, 0, o, d, fg_reach))
        return 1;
    if (target_is_background &&
        (planes_any(rs, 1, o, d, dist) || a->any(a, 1, o, d, dist)))
        return 1;
    return 0;
}

void accel_free(struct accel *a)
{
    if (a)
        a->destroy(a);
}


zt_status accel_build(rscene *rs, accel_kind kind, zt_error *err)
{
    switch (kind) {
    case ACCEL_EMBREE: return accel_build_embree(rs, err);
    case ACCEL_BRUTE: return accel_build_brute(rs, err);
    case ACCEL_BVH: return accel_build_bvh(rs, err);
    }
    return ZT_ERR_ARGUMENT;
}
