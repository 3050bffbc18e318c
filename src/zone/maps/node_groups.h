/* Nodes close together on one sheet of a mesh, which share one cut.
 *
 * A model's vertices lie far closer together than the node spacing h, and
 * a vertex on the rim of a flat face or along a crease has no surrounding
 * nodes to be read from (mesh_rounds.h), so nearly every one is computed
 * with a cut of its own, and neighbouring cuts choose nearly the same
 * clusters.  Here the live vertex nodes of each mesh side are gathered into
 * groups: a leader, and the nodes within `radius` of it on its sheet
 * (mesh_sheet.h: a crease or the gap between two fins ends it) that face
 * its way and lie near its tangent plane.  The leader's cut, with the
 * share of each cluster its rays saw, is the start of each member's cut
 * (cut.h, cut_resume), as Lightcuts' reconstruction cuts reuse nearby
 * cuts.  The groups depend on the geometry alone, in node order. */
#ifndef ZT_ZONE_MAPS_NODE_GROUPS_H
#define ZT_ZONE_MAPS_NODE_GROUPS_H

#include <stdint.h>

#include "render/render_scene.h"
#include "zone/maps/surface_nodes.h"

typedef struct node_groups {
    int32_t *lead;      /* per node: its group's leader (itself for a
                           leader), or -1 when it has no group; NULL when
                           no node has one */
    int32_t *first;     /* nodes + 1: leader k's members are */
    int32_t *member;    /* member[first[k] .. first[k + 1] - 1] */
    int groups;         /* leaders */
    int members;        /* nodes that are not leaders */
} node_groups;

/* Groups sn's live mesh vertex nodes (node life marked before): members
 * within radius of their leader, normals within acos(min_cos) of its.
 * Returns 0 when out of memory. */
int node_groups_build(node_groups *ng, const surface_nodes *sn, const rscene *rs, double radius,
                      double min_cos);

void node_groups_free(node_groups *ng);

static inline int32_t node_group_lead(const node_groups *ng, int32_t k)
{
    return ng->lead ? ng->lead[k] : -1;
}

#endif
