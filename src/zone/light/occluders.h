/* Which primitives can shadow a point from a light: a bounding volume
 * hierarchy over the finite primitives (triangles, mesh triangles,
 * spheres), asked for those whose boxes meet a convex region (the box
 * around a point and a light, cut by the pyramid from the point through
 * the light).  Exact soft shadows clip only these, so their cost follows
 * what lies between the point and the light, not the scene's size. */
#ifndef ZT_ZONE_LIGHT_OCCLUDERS_H
#define ZT_ZONE_LIGHT_OCCLUDERS_H

#include <stdint.h>

#include "render/render_scene.h"
#include "util/vec3.h"

/* The index is at most OCC_MAX_DEPTH levels below its root (deeper runs
 * stay leaves), so a traversal that pops a node and pushes its two
 * children never holds more than OCC_STACK entries. */
#define OCC_MAX_DEPTH 60
#define OCC_STACK (OCC_MAX_DEPTH + 3)

typedef struct occ_node {
    float lo[3], hi[3];
    int32_t left;       /* inner: index of the left child (the right one
                           follows it); leaf: -1 - first index into prims */
    int32_t count;      /* leaf: primitives; inner: 0 */
} occ_node;

typedef struct occluder_index {
    occ_node *nodes;
    int32_t *prims;     /* primitive numbers, leaves' runs */
    int node_count, prim_count;
} occluder_index;

/* Builds the index over rs's triangles and spheres (both layers).
 * Returns 0 when out of memory. */
int occluders_build(occluder_index *ix, const rscene *rs);
void occluders_free(occluder_index *ix);

/* The half-spaces n . p + d >= 0 that bound a query besides its box. */
#define OCC_PLANES_MAX 16
typedef struct occ_region {
    vec3 lo, hi;
    int planes;
    vec3 n[OCC_PLANES_MAX];
    double d[OCC_PLANES_MAX];
} occ_region;

/* Writes into out (room for max) the primitives whose boxes meet the
 * region (conservatively: some may not), in ascending order; returns how
 * many there are, or max + 1 when there are more than max (the search then
 * stops, and what out holds is no particular subset). */
int occluders_query(const occluder_index *ix, const occ_region *r, int32_t *out, int max);

#endif
