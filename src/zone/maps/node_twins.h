/* Nodes that stand at one point with one normal, whose light is computed
 * once.
 *
 * A smooth mesh's triangles share their corner nodes by vertex, but each
 * keeps its own grid nodes, and those on its edges lie on the edge itself.
 * Two triangles across an edge whose grids put a node at the same fraction
 * of it (the same steps, or steps a multiple of each other) thus have a
 * node each at the same point, with the same normal (interpolated between
 * the same two vertex normals).  One of them is computed and the other
 * takes its value.  Computed each on its own triangle they differed only
 * in the occluders of the exact direct light, which are chosen per
 * triangle: on the N-series spheres taking one for both moved the error by
 * at most 0.004 points, and the engine room's not at all. */
#ifndef ZT_ZONE_MAPS_NODE_TWINS_H
#define ZT_ZONE_MAPS_NODE_TWINS_H

#include <stdint.h>

#include "render/render_scene.h"
#include "zone/maps/surface_nodes.h"

typedef struct node_twins {
    int32_t *of;    /* per node: the live node computed in its stead, or -1;
                       NULL when no node has a twin */
    int count;      /* nodes that take a twin's value */
} node_twins;

/* Pairs the live edge nodes of sn's smooth meshes (node life marked
 * before).  Returns 0 when out of memory. */
int node_twins_build(node_twins *tw, const surface_nodes *sn, const rscene *rs);

void node_twins_free(node_twins *tw);

/* The node whose value node k takes, or -1 when k is computed itself.
 * That node is never one that takes a value in turn. */
static inline int32_t node_twin(const node_twins *tw, int32_t k)
{
    return tw->of ? tw->of[k] : -1;
}

#endif
