/* The BVH backend: its trees (bvh_build.c) behind the accel interface.
 * The walk itself is bvh_traverse.h, which accel_query.c also calls
 * directly. */
#include "geom/accel_internal.h"

#include <stdlib.h>

#include "geom/bvh.h"
#include "geom/bvh_traverse.h"
#include "util/error.h"

typedef struct bvh_accel {
    accel base;
    bvh_tree layer[2];
} bvh_accel;

static void bvh_nearest(const accel *a, int layer, vec3f o, vec3f d, hit *h)
{
    ray4 r4 = ray4_make(o, d);
    bvh_ray r;
    bvh_ray_init(&r, &r4, o, d);
    bvh_traverse(&((const bvh_accel *)a)->layer[layer], &r, h, 0);
}

static int bvh_any(const accel *a, int layer, vec3f o, vec3f d, float tmax)
{
    ray4 r4 = ray4_make(o, d);
    bvh_ray r;
    bvh_ray_init(&r, &r4, o, d);
    hit h = {tmax, -1};
    return bvh_traverse(&((const bvh_accel *)a)->layer[layer], &r, &h, 1);
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
    b->base.bvh = b->layer;
    for (int l = 0; l < 2; l++)
        if (!bvh_build(&b->layer[l], rs, l)) {
            bvh_destroy(&b->base);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory building the BVH");
        }
    rs->accel = &b->base;
    return ZT_OK;
}
