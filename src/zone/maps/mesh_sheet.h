/* A mesh's sheets of surface: the vertices reached from one along the
 * mesh's edges, near it and facing its way.  A crease, or the gap between
 * two fins, ends a sheet; two sheets stacked close together stay apart.
 * Used to find the nodes a vertex node may be read from (mesh_rounds.h)
 * or share its cut with (node_groups.h). */
#ifndef ZT_ZONE_MAPS_MESH_SHEET_H
#define ZT_ZONE_MAPS_MESH_SHEET_H

#include <stdint.h>

#include "scene/mesh.h"

/* A mesh's vertices' neighbours: along its edges, and its other vertices
 * at the same position (a file splits a vertex where its normal or texture
 * coordinates change: every corner of a faceted model is such a copy, so
 * without them a faceted model's sheets were single triangles). */
typedef struct mesh_adjacency {
    int32_t *first;     /* vertex_count + 1 */
    int32_t *list;
} mesh_adjacency;

/* Returns 0 when out of memory (free it all the same). */
int mesh_adjacency_build(mesh_adjacency *a, const mesh *m);
void mesh_adjacency_free(mesh_adjacency *a);

/* One thread's marks and queue for walks over `count` vertices. */
typedef struct sheet_walk {
    int32_t *stamp, *queue;
    int32_t id;
} sheet_walk;

/* Returns 0 when out of memory (free it all the same). */
int sheet_walk_init(sheet_walk *w, int32_t count);
void sheet_walk_free(sheet_walk *w);

/* The vertices reached from v along the mesh's edges through vertices
 * within `reach` of v whose normals are within acos(min_cos) of v's: v's
 * own sheet.  pos and nrm hold 3 floats a vertex.  They are left in
 * w->queue[1 ..], v first; returns their count with v, or -1 as soon as it
 * meets a vertex that `taken` marks (not 0xff; NULL: none). */
int mesh_sheet_walk(const mesh_adjacency *adj, const float *pos, const float *nrm, int32_t v,
                    double reach, double min_cos, const uint8_t *taken, sheet_walk *w);

#endif
