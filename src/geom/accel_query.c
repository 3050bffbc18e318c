/* The background rule and the planes, around the backends' raw queries. */
#include "geom/accel_internal.h"

#include <float.h>

#include "geom/shapes.h"

static void planes_nearest(const rscene *rs, int layer, vec3f o, vec3f d,
                           hit *h)
{
    for (int i = 0; i < rs->plane_count[layer]; i++) {
        int pi = rs->plane_parts[layer][i];
        float t = shape_plane_hit(&rs->parts[pi], o, d, 0.0f, h->t);
        if (t > 0.0f) {
            h->t = t;
            h->part = pi;
        }
    }
}

static int planes_any(const rscene *rs, int layer, vec3f o, vec3f d,
                      float tmax)
{
    for (int i = 0; i < rs->plane_count[layer]; i++)
        if (shape_plane_hit(&rs->parts[rs->plane_parts[layer][i]], o, d, 0.0f,
                            tmax) > 0.0f)
            return 1;
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
    }
    return ZT_ERR_ARGUMENT;
}
