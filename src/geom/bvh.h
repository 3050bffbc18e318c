/* The BVH backend's tree as the queries read it: four-wide nodes whose
 * children's boxes sit side by side, and leaves of primitives packed four
 * to a packet, so that one node or one packet is met with a few vector
 * instructions (the loops over BVH_WIDTH lanes are written for the
 * compiler to vectorise, as the plane tests are). */
#ifndef ZT_GEOM_BVH_H
#define ZT_GEOM_BVH_H

#include <stdint.h>

#include "render/render_scene.h"
#include "util/simd4.h"

#define BVH_WIDTH 4

/* A child reference: >= 0 an inner node; < 0 a leaf, ~(first packet <<
 * BVH_LEAF_BITS | packet count).  Unused children have empty boxes. */
#define BVH_LEAF_BITS 3
#define BVH_LEAF_MAX_PACKETS ((1 << BVH_LEAF_BITS) - 1)

typedef struct bvh4_node {
    f4 bound[2][3];     /* [low/high corner][axis], a lane per child */
    int32_t child[BVH_WIDTH];
} bvh4_node;

/* Up to four primitives of one shape.  Unused lanes have zero edges and
 * normals and part -1: their triangle test fails on the determinant. */
typedef struct bvh_packet {
    f4 p0[3];           /* triangle vertex 0 or sphere centre, by axis */
    f4 e1[3], e2[3];    /* triangle edges; a sphere's c_lo, and its r_lo
                           in e2[0] (render_scene.h) */
    f4 n[3];            /* triangle unit normal, for t */
    f4 radius;
    i4 culled;          /* -1 culled, else 0 */
    int32_t part[BVH_WIDTH];
    int32_t shape;      /* SHAPE_TRIANGLE or SHAPE_SPHERE */
} bvh_packet;

typedef struct bvh_tree {
    bvh4_node *nodes;   /* nodes[0] is the root */
    bvh_packet *packets;
    int node_count, packet_count;
} bvh_tree;

/* Builds the tree of the layer's triangles and spheres (none: an empty
 * tree).  Returns 0 when out of memory. */
int bvh_build(bvh_tree *tr, const rscene *rs, int layer);

void bvh_tree_free(bvh_tree *tr);

#endif
