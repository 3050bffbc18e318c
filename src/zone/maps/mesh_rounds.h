/* Coarse and fine vertex nodes of a mesh, for computing fewer of them
 * where the light is smooth (as surface_node_line does on grids).
 *
 * A model's vertices lie far closer together than the node spacing h (the
 * engine room's edges average a tenth of h), and every vertex of a smooth
 * mesh is a node.  So vertex nodes are taken in rounds: round 0 a spread of
 * vertices 2h apart along the surface, round r a spread 2h / 2^r apart
 * from those before, the last round the rest.  A node of a later round has
 * *supports*: nodes of earlier rounds around it on its own sheet of
 * surface, reached from it along the mesh's edges through vertices facing
 * its way (a crease, or the gap between two fins, ends the sheet), and
 * surrounding it in its tangent plane.  Its light is read from them when a
 * plane through their values fits each within `smooth` of the largest;
 * else it is computed.  The rounds depend on the geometry alone. */
#ifndef ZT_ZONE_MAPS_MESH_ROUNDS_H
#define ZT_ZONE_MAPS_MESH_ROUNDS_H

#include <stdint.h>

#include "render/render_scene.h"
#include "zone/maps/surface_nodes.h"

#define MESH_ROUNDS 8

typedef struct mesh_rounds {
    uint8_t *round;     /* per node: 0 (computed) or the round it is read
                           in; 0 for every node that is not a mesh's vertex */
    int32_t *first;     /* nodes + 1: node k's supports are
                           support[first[k] .. first[k + 1] - 1] */
    int32_t *support;
} mesh_rounds;

/* Lays out the rounds over sn's live mesh vertex nodes (node life marked
 * before), on `threads` threads; *rays counts the rays cast.  Returns 0
 * when out of memory. */
int mesh_rounds_build(mesh_rounds *mr, const surface_nodes *sn, const rscene *rs, int threads);

void mesh_rounds_free(mesh_rounds *mr);

static inline int mesh_round(const mesh_rounds *mr, int32_t k)
{
    return mr->round ? mr->round[k] : 0;
}

/* Node k's light read from its supports' values v (3 floats a node) into
 * out, if a plane through them fits each within `smooth` of their largest;
 * returns 0 (out unset) when it does not. */
int mesh_rounds_read(const mesh_rounds *mr, const surface_nodes *sn, const float *v, int32_t k,
                     double smooth, float out[3]);

#endif
