/* The light leaving the diffuse surfaces at one level, as a tree of
 * clusters: every element (surface_nodes.h) is a leaf with the radiance
 * of its nodes, and every cluster knows its box, the cone of its elements'
 * normals and the flux they send.  The transfer (transfer.h) takes light
 * from a whole cluster at once where that is accurate enough, and goes
 * down to single elements, exactly, where it is not: hierarchical
 * radiosity's idea (Hanrahan, Salzman and Aupperle 1991), with the
 * clusters of Smits, Arvo and Greenberg (1994) chosen per receiver as
 * Lightcuts (Walter et al. 2005) chooses lights.
 *
 * The tree's shape depends on the geometry only; each level's light is
 * put into it by sender_tree_fill, and sums are made in a fixed order, so
 * the result is the same at any thread count. */
#ifndef ZT_ZONE_PHASE_ONE_SENDER_TREE_H
#define ZT_ZONE_PHASE_ONE_SENDER_TREE_H

#include <stdint.h>

#include "zone/maps/surface_nodes.h"

/* One element, as a leaf: a piece of a diffuse surface, or a light. */
typedef struct sender_elem {
    int32_t prim;
    int32_t index;      /* element of the primitive's side; -1: the whole
                           primitive (a light) */
    uint8_t side;
    uint8_t background; /* the primitive's layer, for visibility rays */
    uint8_t any_way;    /* sends in every direction (a sphere or point
                           light): no normal, no estimate from afar */
    float c[3];         /* centroid */
    float n[3];         /* unit normal of the side that sends */
    float lo[3], hi[3]; /* box */
    float area;
    float albedo[3];    /* w_d x colour (x the texture's mean) / pi: the
                           radiance leaving per unit irradiance */
} sender_elem;

/* One cache line (64 bytes, so aligned): a cut reads a node's whole
 * record for every cluster it weighs, from all over the tree. */
typedef struct sender_node {
    _Alignas(64) float lo[3];
    float hi[3];
    float axis[3];      /* normal cone: every element normal lies within */
    float cone;         /* this angle (radians) of axis; > pi/2: any */
    float cos_cone, sin_cone;
    float radius;       /* half the box's diagonal */
    int32_t left;       /* inner: left child, the right one follows it;
                           leaf: -1 - first element */
    int32_t count;      /* leaf: elements; inner: 0 */
    int16_t background; /* every element is of the background layer */
    int16_t any_way;    /* some element sends every way (a sphere light) */
} sender_node;

/* One level's light in a cluster, two cache lines (128 bytes, so
 * aligned); the first holds what a cut reads for every cluster it weighs:
 * the luminance of the flux (radiance x area summed), the
 * luminance-weighted centroid, and the vector flux per channel (radiance x
 * area x normal: for a receiver every element faces, the sum of flux x
 * cosine is this dotted with the direction). */
typedef struct sender_light {
    _Alignas(64) float power;
    float c[3];
    float vflux[3][3];  /* [channel][axis] */
    /* Where the cluster is seen from: the centroid of one of its
     * elements, drawn in proportion to power by a fixed number per node
     * (a child by its share of the power, down to an element).
     * Visibility is tested there, not at the centroid, which may lie
     * inside an object the cluster's elements surround. */
    float rep[3];
    /* The normal of the side rep's element sends from: whether it faces
     * a receiver. */
    float rep_n[3];
    /* For clusters whose elements do not all face a receiver: the flux
     * times the magnitude of each normal component, sum flux |n_a|.  Half
     * of it plus or minus half the vector flux is the flux of the
     * elements' normal components along each signed axis, so
     * (|w| . aflux + w . vflux) / 2 is flux x cosine exactly for elements
     * facing along axes (a room's walls), and never below it for
     * others. */
    float aflux[3][3];  /* [channel][axis] */
} sender_light;

typedef struct sender_tree {
    sender_elem *elems;
    int elem_count;
    sender_node *nodes;
    int node_count;
    sender_light *light;    /* per node, the level last filled */
    float *elem_radiance;   /* per element, rgb, the level last filled */
    double total_power;     /* of the level last filled */
    double total_area;
} sender_tree;

/* The tree over every element of sn whose surface is diffuse.  Returns 0
 * when out of memory. */
int sender_tree_build(sender_tree *t, const surface_nodes *sn, const rscene *rs);

/* The tree over the lights (rs->lights): each one-sided light one element,
 * a two-sided triangle two (one a side), spheres and points sending every
 * way; filled with their emission (switched-off lights send nothing, but
 * keep their place: the tree is the same with lights off).  Returns 0 when
 * out of memory. */
int sender_tree_build_lights(sender_tree *t, const rscene *rs);

void sender_tree_free(sender_tree *t);

/* Puts one level's light in: each element's radiance is its albedo times
 * the mean irradiance of its live corner nodes, e (3 floats per node; an
 * element with none live sends nothing). */
void sender_tree_fill(sender_tree *t, const surface_nodes *sn, const rscene *rs, const float *e);

/* Element i's power in the level filled last: the luminance of its
 * radiance times its area. */
static inline double sender_elem_power(const sender_tree *t, int32_t i)
{
    const float *b = &t->elem_radiance[3 * (size_t)i];
    return (0.2126 * b[0] + 0.7152 * b[1] + 0.0722 * b[2]) * t->elems[i].area;
}

#endif
