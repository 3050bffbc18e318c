/* Which nodes light can reach.  A node is dead when it lies behind a wall
 * (a plane no light can get behind: opaque, every light in front of it,
 * the sky black) or inside a closed object (most directions from it first
 * meet the back of a back-culled surface).  Dead nodes send nothing and are left out
 * of every read, so light does not leak from under a box standing on the
 * floor, or from outside the room.  A node on a wall's plane (where the
 * wall meets the floor) is moved a hair inside.  A model's vertex sunk
 * into another part (a fin's root in the cylinder it stands on) is moved
 * along an edge of its triangle to where that edge leaves the open space,
 * and lives there: the triangle shows outside the part, and its light near
 * the junction is the junction's, not that of its far corners. */
#ifndef ZT_ZONE_PHASE_ONE_NODE_LIFE_H
#define ZT_ZONE_PHASE_ONE_NODE_LIFE_H

#include <stdint.h>

#include "zone/light/occluders.h"
#include "zone/maps/surface_nodes.h"

/* Sets sn->live (and nudges nodes on walls).  Returns the rays traced. */
uint64_t node_life_mark(surface_nodes *sn, const occluder_index *occ, const zt_scene *scene,
                        const rscene *rs, int threads);

/* How far node_life_mark may move each node from where the layout puts
 * it, a bound on each coordinate: a node on a wall's plane a quarter cell,
 * a model's sunk vertex along an edge of one of its triangles, at most the
 * longest.  A forest file's nodes are checked against it.  NULL when out
 * of memory; the caller frees it. */
float *node_life_reach(const surface_nodes *sn, const rscene *rs);

/* The nearest hit of ray (o, d) among occ's primitives and the scene's
 * planes, ignoring back-face culling: its primitive (-1: none), and
 * whether the ray meets its back (*back). */
int node_life_first_hit(const occluder_index *occ, const zt_scene *scene, const rscene *rs,
                        vec3 o, vec3 d, int *back);

#endif
