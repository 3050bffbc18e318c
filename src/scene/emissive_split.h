/* A model's emissive triangles cut where their emissive texture varies, so
 * that lights of one (mean) radiance each follow the texture: the zone
 * tracer's lights (docs/zone-tracer.md, "Emissive textures"). */
#ifndef ZT_SCENE_EMISSIVE_SPLIT_H
#define ZT_SCENE_EMISSIVE_SPLIT_H

#include "scene/mesh.h"

/* Cuts each triangle of m (the importer's own, texture coordinates and
 * slots read) whose slot emits through a texture that varies over it (its
 * luminance by more than 2% of its largest value, sampled twice per texel)
 * into n^2 similar ones, n its longest side in texels (at most 16; fewer
 * when the mesh would grow by more than 2^18 triangles).  The new vertices
 * interpolate positions, texture coordinates, normals and tangents; the
 * first piece keeps the triangle's index.  *added: the triangles added.
 * Fails only when out of memory (path for the message). */
zt_status mesh_split_emissive(mesh *m, const char *path, int *added, zt_error *err);

#endif
