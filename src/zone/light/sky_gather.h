/* The sky's light at a point: gathered over fixed directions, the share
 * of them whose rays escape (docs/zone-tracer.md, "The sky's light is
 * gathered").
 *
 * A sky of one colour is gathered over a cosine-weighted set about the
 * point's normal; an environment map (a file, or the sky model) over
 * directions drawn from the map by importance, in the world frame, whose
 * escaping share scales the map's irradiance on an open surface of that
 * normal (a table), so that a point with nothing in the way is exact.
 * Window panes, where the scene has them, take part of the directions
 * (sky_portals.h).
 *
 * The camera's samples and the nodes of planes, spheres and triangles
 * written in the scene take every direction.  A mesh's node takes a
 * quarter of them (ZONE_MESH_NODE_DIV), set apart from its neighbours'
 * by a key of its own (zone_trace.node_draw): a mesh's nodes are read
 * only through averages of many, and the same directions at every node
 * would err alike over whole regions, which no average takes out. */
#ifndef ZT_ZONE_LIGHT_SKY_GATHER_H
#define ZT_ZONE_LIGHT_SKY_GATHER_H

#include "zone/zone.h"

/* The sky's direct irradiance at x (unit normal n): a camera sample's or
 * a node's (t->node_draw: a mesh node's quarter set). */
vec3 zone_sky_irradiance(zone_trace *t, vec3 x, vec3 n);

/* The forest's sky directions and the map's open-surface table (none
 * without a sky); 0 when out of memory. */
int zone_sky_build(zone_forest *f, const rscene *rs);
void zone_sky_free(zone_forest *f);

#endif
