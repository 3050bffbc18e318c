/* The zone tracer's state: the forest of zones grown from the lights
 * (Phase One) and what Phase Two reads from it. */
#ifndef ZT_ZONE_ZONE_INTERNAL_H
#define ZT_ZONE_ZONE_INTERNAL_H

#include <stdint.h>

#include "render/render_internal.h"
#include "zone/direct.h"
#include "zone/zone_maps.h"

/* How light leaves a zone's source. */
typedef enum zone_kind {
    ZONE_EMIT = 0,      /* a root: the light part itself */
    ZONE_DIFFUSE,
    ZONE_METALLIC,
    ZONE_MIRROR,
    ZONE_REFRACT,       /* the dielectric lobe: reflected and transmitted */
    ZONE_KINDS
} zone_kind;

/* One zone: the light leaving `source` by `kind`, having arrived along the
 * branch of its parent.  Diffuse zones of one level on one surface share
 * that surface's irradiance map (their light is the map's value). */
typedef struct zone {
    int parent;         /* -1 for roots */
    int source;         /* part the light leaves */
    int root_light;     /* light part at the root of the tree */
    uint8_t kind;       /* zone_kind */
    uint8_t level;      /* scattering events so far (0 at the root) */
    float power;        /* bound on the power carried, for --cutoff */
    int first_child, child_count;
    int first_occluder, occluder_count; /* parts that can shadow it */
} zone;

/* Quality settings derived from --quality. */
typedef struct zone_quality {
    int gather;         /* directions per texel for indirect maps */
    double texel;       /* target texel size in scene units */
    int sides;          /* polygon vertices for disks */
    int aa;             /* sub-pixel grid per side */
    double texel_divisor; /* texel = scene extent / texel_divisor */
    double theta;       /* transfer: pieces are split above this size/distance */
    int max_texels;     /* at most this many texels along a map's side */
    int glint_cuts;     /* a light triangle is cut n x n for its images */
    int edge_grade;     /* maps' end texels cut this many times (map_axis) */
    int edge_grid;      /* coverage grid of a pixel an edge crosses (<= 64) */
    int edge_shade;     /* its shaded subset, per side (divides edge_grid) */
    int cover_quasi;    /* coverage points: 0 the n x n cell centres, 1 the
                           first n^2 of a quasi-random (R2) sequence */
    int probe;          /* signatures per side that look for an edge in a
                           pixel (no more than aa: the samples' own) */
    int photons;        /* caustic photons per light (caustic.h) */
    int refine_sub;     /* fine cells per texel side where a map is refined
                           (refine.h; 0: none) */
    double refine_contrast; /* texels refined where a neighbour differs by
                               more than this share */
    double refine_kink; /* or where the second difference exceeds this
                           share (0: not looked for) */
    double refine_theta; /* fine cells' transfer piece size, in thetas */
    int refine_end_sub; /* finer cells per texel side around the ends of
                           crossings (0: none; refine.c) */
} zone_quality;

typedef struct transfer_blockers transfer_blockers;

typedef struct zone_forest {
    zone *zones;
    int zone_count, zone_capacity;
    int *occluders;     /* occluder lists of all zones */
    int occluder_count, occluder_capacity;
    uint64_t pruned;
    part_map *maps;     /* per part (only diffuse things have texels) */
    int map_count;
    int map_levels;     /* irradiance levels E_0 .. E_{map_levels-1} */
    int sky_slot;       /* map level holding the sky's direct irradiance
                           (map_levels), or -1 under a black sky */
    direct_ctx direct;
    zone_quality q;
    int need_gather;    /* some light arrives by specular surfaces or spheres */
    int *glint_spheres; /* spheres that reflect lights as images (glint.h) */
    int glint_count;
    vec3 *dirs;         /* the gather directions (q.gather of them) */
    transfer_blockers *blockers; /* Phase One: what may hide a piece */
    double phase_one_seconds;
    uint64_t rays;
    int loaded;         /* read from a forest file (forest_io.c), not built */
    double build_seconds; /* Phase One time of the build (kept in the file) */
    int images;         /* images rendered from it so far */
} zone_forest;

/* The quality settings of --quality q for scene sc. */
zone_quality zone_quality_for(const zt_scene *sc, int q);

/* Phase One pieces. */
zt_status forest_build_tree(zone_forest *f, const zt_renderer *r, zt_error *err);
zt_status forest_build_maps(zone_forest *f, const zt_renderer *r, zt_error *err);

/* The scene's core: the box of the finite parts and of the corners where
 * three planes meet; independent of the camera. */
void forest_scene_bounds(const zt_scene *sc, vec3 *lo, vec3 *hi);
void forest_free(zone_forest *f);
/* The fixed gather directions (cosine-weighted, around +z). */
vec3 *forest_gather_directions(int n);

/* Radiance arriving along a ray with levels lo..hi (flags below). */
typedef struct zone_trace {
    const zone_forest *f;
    const zt_renderer *r;
    uint64_t rays;
    float cone;         /* angular radius a gather ray stands for (0: exact) */
} zone_trace;

/* The sky's direct irradiance at x (normal n), gathered at x itself over
 * the forest's directions: camera samples take it here rather than from
 * the map, which smears it where surfaces meet or cross. */
vec3 forest_sky_irradiance(zone_trace *t, vec3 x, vec3 n);
/* E_0 at point x (normal n) of a part as a level-0 texel has it: every
 * light exactly, plus the sky by the gather directions. */
vec3 forest_direct_at(zone_trace *t, int part_index, vec3 x, vec3 n);

/* The direct irradiance of every light part (exact, direct.c) at x
 * (normal n) on a part, without the sky's. */
vec3 forest_lights_at(zone_trace *t, int part_index, vec3 x, vec3 n);

enum {
    ZR_EXACT_DIRECT = 1, /* level 1 from the analytic direct term, not maps */
    ZR_NO_EMISSION = 2,  /* lights hit by this very ray count nothing (the
                            camera's level 0 is measured analytically) */
    ZR_SKIP_FLAT_DIFFUSE = 4, /* the diffuse lobe of a flat part hit by this
                            very ray counts nothing (transfer covers it) */
    ZR_NO_GLINT = 8,     /* a light seen in a glint sphere (glint.h) by this
                            very ray counts nothing (its image covers it) */
    ZR_NO_CAUSTIC = 16,  /* a light reached after one or more specular events
                            and no diffuse one, the last of them off a
                            caustic target (caustic.h), counts nothing if it
                            sends photons (a triangle or sphere): they carry
                            it */
    ZR_CAUSTIC_LIGHT = 32 /* set by zone_radiance under ZR_NO_CAUSTIC: this
                            very ray left a caustic target */
};
vec3 zone_radiance(zone_trace *t, vec3f o, vec3f d, int lo, int hi,
                   int flags, const int *media, int media_count);

#endif
