/* Nearest-hit and visibility queries: the one small interface behind which
 * the acceleration structures live.
 *
 * The scene format's "background" rule is part of the query: a ray's hit is
 * its nearest foreground hit if it has any, otherwise its nearest background
 * hit.  Infinite planes are tested directly (there are few of them); the
 * other primitives go to the chosen backend.  So are holes: a hit of
 * coverage 0 (an alpha mask's, render/prim.h rs_coverage) is no hit, and
 * the query goes on beyond it, whatever the backend.
 */
#ifndef ZT_GEOM_ACCEL_H
#define ZT_GEOM_ACCEL_H

#include "geom/hit.h"
#include "render/render_scene.h"

typedef enum accel_kind {
    ACCEL_EMBREE = 0, /* Intel Embree 3 (default) */
    ACCEL_BRUTE = 1,  /* every primitive, every ray: the test oracle */
    ACCEL_BVH = 2     /* the project's own four-wide SAH BVH (accel_bvh.c) */
} accel_kind;

/* Builds the structure for rs (rs->accel).  ZT_ERR_MEMORY or
 * ZT_ERR_UNSUPPORTED on failure. */
zt_status accel_build(rscene *rs, accel_kind kind, zt_error *err);

void accel_free(struct accel *a);

/* The hit of the ray (origin o, unit direction d) beyond tmin = 0 under the
 * background rule; h.part = -1 when nothing is hit. */
hit accel_intersect(const rscene *rs, vec3f o, vec3f d);

/* The nearest triangle or sphere of either layer on the ray within
 * (0, tmax), back faces included whether or not the primitive is culled,
 * planes and holes not looked at: the first surface a direction meets,
 * as node life's probes ask it (zone/phase_one/node_life.c).  Returns 0
 * when the backend has no such query (then *h is untouched), else 1 with
 * h->part = -1 when nothing is hit. */
int accel_nearest_all_sides(const rscene *rs, vec3f o, vec3f d, float tmax, hit *h);

/* Whether the point at distance dist along (o, d) is hidden: by a
 * foreground primitive before dist; when the target is a background
 * primitive also by any foreground primitive beyond it or a background one
 * before it.  This is the same rule as accel_intersect, so a ray towards a
 * point is unblocked exactly when it would hit that point. */
int accel_occluded(const rscene *rs, vec3f o, vec3f d, float dist,
                   int target_is_background);

/* accel_intersect for n rays from one origin o along unit directions
 * d[i], into h[i]: the same hits as n calls, the rays traced as packets
 * where the backend can. */
void accel_intersect_n(const rscene *rs, vec3f o, const vec3f *d, int n, hit *h);

/* The same for rays of their own origins o[i] (a camera's, say: nearby
 * and nearly parallel). */
void accel_intersect_rays(const rscene *rs, const vec3f *o, const vec3f *d, int n, hit *h);

/* accel_occluded for n rays from one origin o, to distances dist[i] along
 * unit directions d[i]: hidden[i] is 1 or 0, the same answers as n calls
 * of accel_occluded.  Rays from one point towards one light are nearly
 * parallel, and the backend traces them as packets where it can. */
void accel_occluded_n(const rscene *rs, vec3f o, const vec3f *d, const float *dist, int n,
                      int target_is_background, unsigned char *hidden);

#endif
