/* The simplest backend: test every primitive (mesh triangles too).  Slow, obviously right, and
 * the oracle the other backends are tested against. */
#include "geom/accel_internal.h"

#include <stdlib.h>

#include "geom/shapes.h"
#include "render/prim.h"
#include "util/error.h"

typedef struct brute {
    accel base;
    const rscene *rs;
} brute;

static void brute_nearest(const accel *a, int layer, vec3f o, vec3f d, hit *h)
{
    const rscene *rs = ((const brute *)a)->rs;
    for (int i = 0; i < rs->prim_count; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, i, &tmp);
        if (p->background != layer || p->shape == SHAPE_PLANE)
            continue;
        float t = shape_hit(p, o, d, 0.0f, h->t);
        if (t > 0.0f) {
            h->t = t;
            h->part = i;
        }
    }
}

static int brute_any(const accel *a, int layer, vec3f o, vec3f d, float tmax)
{
    const rscene *rs = ((const brute *)a)->rs;
    for (int i = 0; i < rs->prim_count; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, i, &tmp);
        if (p->background == layer && p->shape != SHAPE_PLANE &&
            shape_hit(p, o, d, 0.0f, tmax) > 0.0f)
            return 1;
    }
    return 0;
}

static void brute_destroy(accel *a)
{
    free(a);
}

zt_status accel_build_brute(rscene *rs, zt_error *err)
{
    brute *b = calloc(1, sizeof *b);
    if (!b)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    b->base.nearest = brute_nearest;
    b->base.any = brute_any;
    b->base.destroy = brute_destroy;
    b->rs = rs;
    rs->accel = &b->base;
    return ZT_OK;
}
