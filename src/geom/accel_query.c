/* The background rule and the planes, around the backends' raw queries. */
#include "geom/accel_internal.h"

#include <float.h>

#include "geom/shapes.h"

/* Planes: t = (offset - n.o) / (n.d), valid in (0, tmax) and, for culled
 * planes, only from the front.  The distances are computed for all planes
 * first (independent divisions, which pipeline and vectorise) and reduced
 * after; a failed division (n.d = 0) gives inf or nan, which compare false. */
#define PLANE_BATCH 16

static int plane_distances(const rs_plane *pl, int n, vec3f o, vec3f d,
                           float *t)
{
    for (int i = 0; i < n; i++) {
        float dn = d.x * pl[i].n.x + d.y * pl[i].n.y + d.z * pl[i].n.z;
        float num = pl[i].offset - (o.x * pl[i].n.x + o.y * pl[i].n.y + o.z * pl[i].n.z);
        float ti = num / dn;
        t[i] = (pl[i].culled && dn >= 0.0f) ? -1.0f : ti;
    }
    return n;
}

static void planes_nearest(const rscene *rs, int layer, vec3f o, vec3f d,
                           hit *h)
{
    const rs_plane *pl = rs->planes[layer];
    float t[PLANE_BATCH];
    for (int start = 0; start < rs->plane_count[layer]; start += PLANE_BATCH) {
        int n = rs->plane_count[layer] - start;
        n = plane_distances(pl + start, n < PLANE_BATCH ? n : PLANE_BATCH, o, d, t);
        for (int i = 0; i < n; i++)
            if (t[i] > 0.0f && t[i] < h->t) {
                h->t = t[i];
                h->part = pl[start + i].part;
            }
    }
}

static int planes_any(const rscene *rs, int layer, vec3f o, vec3f d,
                      float tmax)
{
    const rs_plane *pl = rs->planes[layer];
    float t[PLANE_BATCH];
    for (int start = 0; start < rs->plane_count[layer]; start += PLANE_BATCH) {
        int n = rs->plane_count[layer] - start;
        n = plane_distances(pl + start, n < PLANE_BATCH ? n : PLANE_BATCH, o, d, t);
        int any = 0;
        for (int i = 0; i < n; i++)
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

zt_status accel_build_bvh(rscene *rs, zt_error *err); /* accel_bvh.c */

zt_status accel_build(rscene *rs, accel_kind kind, zt_error *err)
{
    switch (kind) {
    case ACCEL_EMBREE: return accel_build_embree(rs, err);
    case ACCEL_BRUTE: return accel_build_brute(rs, err);
    case ACCEL_BVH: return accel_build_bvh(rs, err);
    }
    return ZT_ERR_ARGUMENT;
}
