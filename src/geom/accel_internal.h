/* What a backend provides: raw nearest/any-hit queries over the non-plane
 * primitives of one layer (0 foreground, 1 background). */
#ifndef ZT_GEOM_ACCEL_INTERNAL_H
#define ZT_GEOM_ACCEL_INTERNAL_H

#include "geom/accel.h"

typedef struct accel {
    /* Lowers h->t and sets h->part if a nearer hit in (0, h->t) exists. */
    void (*nearest)(const struct accel *a, int layer, vec3f o, vec3f d, hit *h);
    /* Whether any primitive is hit in (0, tmax). */
    int (*any)(const struct accel *a, int layer, vec3f o, vec3f d, float tmax);
    /* The same for n rays from one origin, where the backend has packets
     * (NULL: it has not): sets hidden[i] for each ray i not yet hidden
     * that hits something in (0, tmax[i]). */
    void (*any_n)(const struct accel *a, int layer, vec3f o, const vec3f *d, const float *tmax,
                  int n, unsigned char *hidden);
    /* Nearest hits of n rays, where the backend has packets (NULL: it has
     * not): ray i from o[i * o_step] (o_step 0: one origin for all) along
     * d[i]; lowers h[i].t and sets h[i].part as nearest does, for the rays
     * whose want[i] is set. */
    void (*nearest_n)(const struct accel *a, int layer, const vec3f *o, int o_step,
                      const vec3f *d, int n, const unsigned char *want, hit *h);
    /* nearest with culling off: back faces of culled primitives are hit
     * too (NULL where the backend has no such query: the BVH's, whose
     * culling is part of its hot triangle test, and the brute force). */
    void (*nearest_all_sides)(const struct accel *a, int layer, vec3f o, vec3f d, hit *h);
    void (*destroy)(struct accel *a);
    /* Whether the layer has any primitives (set by accel_build): most
     * scenes have only planes in one of them, and the call is skipped. */
    int has_prims[2];
    /* The width of the packets any_n and nearest_n send (4, 8 or 16: the
     * machine's native one; a test may lower it), 0 when they are NULL. */
    int packet;
    /* The BVH backend's trees by layer, NULL for the other backends: the
     * queries walk them inline instead of through the pointers above. */
    const struct bvh_tree *bvh;
} accel;

zt_status accel_build_embree(rscene *rs, zt_error *err);
zt_status accel_build_brute(rscene *rs, zt_error *err);
zt_status accel_build_bvh(rscene *rs, zt_error *err);

#endif
