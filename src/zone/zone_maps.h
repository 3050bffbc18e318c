/* Irradiance maps: what reaches each diffuse surface at one level, stored
 * on a grid over the surface (per side for two-sided surfaces) and read back
 * by bilinear interpolation.  Light leaving a diffuse surface forgets where
 * it came from, so all the zones of one level that land on one surface share
 * one map; the tree keeps separate branches only where direction matters. */
#ifndef ZT_ZONE_ZONE_MAPS_H
#define ZT_ZONE_ZONE_MAPS_H

#include "scene/scene.h"
#include "util/vec3.h"

/* How a part's surface is laid out on its grid. */
typedef struct map_layout {
    int shape;          /* part_shape */
    int nu, nv;         /* grid size */
    vec3 origin, du, dv;/* planar: point = origin + s*du + t*dv, s,t in [0,1] */
    vec3 centre;        /* sphere: centre, radius */
    double radius;
    int sides;          /* 1 (front only) or 2 */
} map_layout;

#define MAP_MIPS 8

/* The grid of one part: texel values for each level and side, and coarser
 * copies (each halving the resolution) for lookups that stand for a wide
 * cone of directions. */
typedef struct part_map {
    map_layout layout;
    int levels;         /* levels stored: 0 .. levels-1 */
    float *texels;      /* [level][side][v][u][rgb] */
    int mips;           /* coarser copies in mip[1..mips-1] (mip[0] = texels) */
    float *mip[MAP_MIPS];
    /* Per texel and side, the share of it that lies on a reachable surface
     * (0 for texel centres inside closed objects or outside the room); the
     * same for every level.  weight[0] is the grid's, the rest the copies'. */
    float *weight[MAP_MIPS];
    /* Summed-area tables per level and side: [level][side][(nv+1)*(nu+1)]
     * of weight*rgb (3 doubles) and weight, built by transfer.c. */
    double *sat;
} part_map;

/* Texel centre (i, j) of the layout as a point and the surface normal. */
void map_texel_point(const map_layout *l, int i, int j, vec3 *p, vec3 *n);

/* Where point p (on the part) falls on the grid, in texel units. */
void map_coords(const map_layout *l, vec3 p, double *u, double *v);

/* Builds the coarser copies of one level (after its texels are final).
 * The first call also builds the coarser weights from weight[0]. */
int map_build_mips(part_map *m, int level);

/* The value of a level and side at point p, interpolated, averaged over a
 * footprint of about `width` scene units (0: the finest grid). */
vec3 map_lookup_wide(const part_map *m, int level, int side, vec3 p, double width);

void map_free(part_map *m);

static inline float *map_texel(const part_map *m, int level, int side, int i, int j)
{
    const map_layout *l = &m->layout;
    size_t idx = (((size_t)level * (size_t)l->sides + (size_t)side) * (size_t)l->nv + (size_t)j) *
                     (size_t)l->nu + (size_t)i;
    return m->texels + idx * 3;
}

#endif
