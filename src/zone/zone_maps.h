/* Irradiance maps: what reaches each diffuse surface at one level, stored
 * on a grid over the surface (per side for two-sided surfaces) and read back
 * by bilinear interpolation.  Light leaving a diffuse surface forgets where
 * it came from, so all the zones of one level that land on one surface share
 * one map; the tree keeps separate branches only where direction matters. */
#ifndef ZT_ZONE_ZONE_MAPS_H
#define ZT_ZONE_ZONE_MAPS_H

#include "scene/scene.h"
#include "util/vec3.h"

/* Where the texel edges of one planar axis lie.  Texels [k0, k1) are the
 * core, of width w, except that with grade g the core's first and last
 * texels are cut into g + 1 each, halving towards the core's ends (w/2^g,
 * w/2^g, w/2^(g-1), ..., w/2): where surfaces meet, at the core's and a
 * triangle's edges, the light changes fastest.  Outside the core each
 * texel is r times wider than its inner neighbour, so a plane's map reaches
 * far from the scene for a few texels more.  Widths are in scene units;
 * the axis is len long. */
typedef struct map_axis {
    int n, k0, k1;
    int grade;
    double w, r, len;
    double *edge;       /* the n + 1 edges as fractions of len (a cache of
                           the formula, made by map_layout_cache) */
} map_axis;

/* At most this many half-planes bound the mapped part of a surface. */
#define MAP_CLIPS 12

/* How a part's surface is laid out on its grid. */
typedef struct map_layout {
    int shape;          /* part_shape */
    int nu, nv;         /* grid size */
    vec3 origin, du, dv;/* planar: point = origin + s*du + t*dv, s,t in [0,1] */
    map_axis au, av;    /* planar: texel edges along du and dv */
    vec3 centre;        /* sphere: centre, radius */
    double radius;
    int sides;          /* 1 (front only) or 2 */
    /* Planar: the surface that exists and can be lit is the part of the
     * parallelogram where clip_n[k] . p + clip_d[k] >= 0 for every k (a
     * triangle's far diagonal; for a plane, the walls of the room it lies
     * in).  Phase One only: not saved with a forest. */
    int clips;
    vec3 clip_n[MAP_CLIPS];
    double clip_d[MAP_CLIPS];
} map_layout;

#define MAP_MIPS 8

/* At most this many lines where other surfaces pierce a planar part. */
#define MAP_CROSSINGS 64

/* A line where another triangle pierces a planar part: the other's plane
 * (n . p = d) and the segment of the line that lies on both, a to b.  The
 * light on the part jumps across it (one side may be hidden from a light,
 * or see other surfaces), so a map must not smear it. */
typedef struct map_crossing {
    vec3 n, a, b;
    double d;
    int part;           /* the piercing part */
} map_crossing;
/* One level and side's caustic (caustic.c), kept apart from the texels
 * once Phase One is done, with a finer grid where it is concentrated: a
 * light focused by glass is often narrower than a texel, and a texel's
 * average read back bilinearly would smear it over three.  A read adds,
 * inside a texel marked in the window, the fine grid's value; elsewhere
 * the caustic's own texels, interpolated like the map's.  A refinement
 * window (refine.c) is read the same way; its fine cells hold what the
 * bilinear read misses, and it has nothing outside its marks. */
typedef struct map_detail {
    int level, side;
    int i0, j0, ni, nj; /* the window: texels [i0, i0+ni) x [j0, j0+nj) */
    int sub;            /* fine cells per texel side */
    unsigned char *use; /* per window texel: 1 where the fine grid holds enough
                           photons to be read */
    float *e;           /* fine irradiance [nj*sub][ni*sub][rgb] */
    float *coarse;      /* the caustic per texel of the whole map [nv][nu][rgb],
                           in the texels too until caustic_finish takes it out;
                           NULL where nothing is read outside the marks */
    /* Refinement only: cells a crossing passes through hold a second
     * value, for their part on the far side of it from the cell centre.
     * split[cell] is 1 there; far[cell] is that value (rgb) and the part's
     * centroid (xyz).  NULL when no cell is split. */
    unsigned char *split;
    float *far;         /* [nj*sub][ni*sub][6] */
} map_detail;

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
    /* Per texel, the share of its area inside the clipped surface, and per
     * side and texel the point (s, t) where its value is computed: the
     * centre, or a point of the part that exists and can be lit.  Phase
     * One only. */
    float *cover;
    float *eval_st;
    /* Crossings: texels a crossing cuts are split in two along it.  cut[k]
     * is the crossing cutting texel k (-1: none); the texel's value is that
     * of its larger half, alt[] holds the other half's, on the side of the
     * crossing's plane given by alt_sign[k] (+1: n . p > d).  alt_weight
     * is the other half's reachability, per side and texel, as weight[0];
     * alt_cover its share of the texel's area (Phase One only), alt_st the
     * point where it is computed (Phase One only). */
    int crossings;
    map_crossing *cross;
    signed char *cut, *alt_sign;
    float *alt;         /* [level][side][v][u][rgb], only with crossings */
    float *alt_weight;
    float *alt_cover;
    float *alt_st;
    /* Summed-area tables per level and side: [level][side][(nv+1)*(nu+1)]
     * of area*weight*rgb (3 doubles) and area, built by transfer.c. */
    double *sat;
    map_detail *detail; /* caustics apart; read once detail_live */
    int details, detail_live;
} part_map;

/* Whether the crossing cutting texel (i, j) passes through its fine cell
 * (su, sv) of `sub` a side; if so, *far is the centroid of the cell's part
 * on the far side of it from the cell centre. */
int map_cell_split(const part_map *m, int i, int j, int su, int sv, int sub, vec3 *far);

/* Texel centre (i, j) of the layout as a point and the surface normal. */
void map_texel_point(const map_layout *l, int i, int j, vec3 *p, vec3 *n);

/* Where texel (u, j) of a map is lit on a side (the normal facing that
 * side): its centre, or for a texel cut by the surface's edge a point of
 * the part that exists (Phase One: planar maps read eval_st). */
void map_texel_eval_point(const part_map *m, int u, int j, int side, vec3 *x, vec3 *n);

/* Where the other half of a texel a crossing cuts is lit (Phase One). */
void map_texel_alt_point(const part_map *m, int u, int j, int side, vec3 *x, vec3 *n);

/* Edge i (0..n) of an axis as a fraction of its length. */
static inline double axis_edge(const map_axis *a, int i) { return a->edge[i]; }

/* Fills the edge caches of a layout's axes; 0 when out of memory. */
int map_layout_cache(map_layout *l);

/* The total width of the m texels just outside an axis' core:
 * w r + w r^2 + ... + w r^m (0 for m = 0). */
double axis_outer_span(const map_axis *a, int m);

/* An axis with n equal texels, the end ones cut with grade g (n >= 2 when
 * g > 0). */
map_axis axis_uniform(int n, double len, int g);

/* Width of the core's uncut texels times their count, plus the cut ones:
 * the core's length in scene units. */
static inline double axis_core_span(const map_axis *a)
{
    return (a->k1 - a->k0 - 2 * a->grade) * a->w;
}

/* The point at (s, t) of a planar layout. */
vec3 map_point(const map_layout *l, double s, double t);
/* The centre of fine cell (su, sv) of texel (i, j), its side cut in sub. */
vec3 map_cell_centre(const map_layout *l, int i, int j, int su, int sv, int sub);

/* Texel (i, j) of a planar layout as a polygon (4 corners, then clipped to
 * the surface); returns the corner count, under 3 when nothing is left. */
int map_texel_polygon(const map_layout *l, int i, int j, vec3 *q, int max);
/* The same for the rectangle [s0, s1] x [t0, t1] of a planar layout. */
int map_rect_polygon(const map_layout *l, double s0, double s1, double t0, double t1, vec3 *q,
                     int max);

/* Keeps the part of polygon q (n corners, room for max) where
 * a . p + b >= 0; returns the new corner count. */
int poly3_clip(vec3 *q, int n, int max, vec3 a, double b);

/* Computes cover and eval_st of a planar map from its layout. */
int map_build_cover(part_map *m);

/* Where point p (on the part) falls on the grid, in texel units. */
void map_coords(const map_layout *l, vec3 p, double *u, double *v);

/* Finds the texels the map's crossings cut (m->cross must be set) and
 * splits them: cut, alt_sign, alt_cover, alt_st, and the larger halves'
 * points in eval_st (after map_build_cover); allocates alt and
 * alt_weight.  Returns 0 when out of memory. */
int map_build_cuts(part_map *m);

/* Whether a crossing of the map separates points x and y of its surface:
 * the segment x y passes through a crossing's segment (other than `skip`). */
int map_separated(const part_map *m, vec3 x, vec3 y, int skip);

/* Builds the coarser copies of one level (after its texels are final).
 * The first call also builds the coarser weights from weight[0]. */
int map_build_mips(part_map *m, int level);

/* The value of a level and side at point p, interpolated, averaged over a
 * footprint of about `width` scene units (0: the finest grid). */
vec3 map_lookup_wide(const part_map *m, int level, int side, vec3 p, double width);

/* Whether point p of a planar part lies in a texel some refinement window
 * (refine.c) holds fine cells for, at any level: the light there changes
 * within a texel, and may within a pixel. */
int map_refined_at(const part_map *m, vec3 p);
/* Whether texel (i, j) has fine cells in a refinement window of the level
 * and side (level < 0: of any). */
int map_refined_texel(const part_map *m, int level, int side, int i, int j);

/* Frees what only Phase One uses (cover, evaluation points, the
 * transfer's tables). */
void map_free_phase_one(part_map *m);

void map_free(part_map *m);

static inline float *map_texel(const part_map *m, int level, int side, int i, int j)
{
    const map_layout *l = &m->layout;
    size_t idx = (((size_t)level * (size_t)l->sides + (size_t)side) * (size_t)l->nv + (size_t)j) *
                     (size_t)l->nu + (size_t)i;
    return m->texels + idx * 3;
}

#endif
