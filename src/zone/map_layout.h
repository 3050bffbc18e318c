/* The layout of a part's map (zone_maps.h) made from the scene. */
#ifndef ZT_ZONE_MAP_LAYOUT_H
#define ZT_ZONE_MAP_LAYOUT_H

#include "zone/zone_maps.h"

/* The scene's walls: planes no light can get behind (back-culled, opaque,
 * every light in front, a black sky), which bound the other surfaces. */
typedef struct map_walls {
    int *part;
    int count;
} map_walls;

/* Finds the walls into walls[] (room for every part); returns their count. */
int map_layout_walls(const zt_scene *sc, int *walls);

/* Lays part i out: texels of about `texel` (at most max_texels a side over
 * the scene's core [lo, hi]), the end ones of a plane's core and of a
 * triangle's axes cut with `grade` (map_axis: where walls meet, at a
 * room's corners and a triangle's edges, the indirect light can drop
 * within the last texel); for planes and triangles, the half-planes that
 * bound the surface that exists (clip_n, clip_d). */
void map_layout_part(const zt_scene *sc, const map_walls *w, int i, vec3 lo, vec3 hi,
                     double texel, int max_texels, int grade, map_layout *l);

/* The lines where other triangles pierce triangle part i (each strictly
 * crosses the other's plane and their chords overlap), at most max of
 * them, into out; returns their count (0 for other shapes). */
int map_layout_crossings(const zt_scene *sc, int i, map_crossing *out, int max);

#endif
