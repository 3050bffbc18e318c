/* Direct light, exactly: the irradiance that one light part delivers to a
 * point, with every occluder's shadow cut out of the light's polygon on the
 * light's own plane (Lambert's formula over what is left).  Sphere lights
 * are replaced by their silhouette disk (exact for a uniform sphere) and
 * spheres, as occluders, by their silhouettes; both disks become polygons of
 * `sides` vertices with the disk's area, the one approximation here. */
#ifndef ZT_ZONE_DIRECT_H
#define ZT_ZONE_DIRECT_H

#include "render/render_scene.h"
#include "scene/scene.h"
#include "zone/light/occluders.h"

typedef struct direct_ctx {
    const zt_scene *scene;   /* double-precision geometry of the parts */
    const rscene *rs;        /* mesh triangles, and rays */
    const occluder_index *occ; /* what can cast shadows */
    int sides;               /* polygon vertices for disks */
    /* Where more occluders stand between a point and a light than clipping
     * can take (a mesh), the light is cut into about this many triangles,
     * each seen or hidden by a ray to its centre: exact as it grows. */
    int fallback;
    /* The sun (light DIRECT_SUN): its unit direction and the sine of its
     * angular radius; and a ball holding every finite primitive, beyond
     * which the sun's disc is placed. */
    vec3 sun_dir;
    double sun_sin;
    vec3 far_centre;
    double far_radius;
} direct_ctx;

/* The light number of the sun: a disc of directions, taken as a light
 * sphere beyond the scene that every point sees under the sun's angle
 * (placed from the point, so that no two points see it differently), and
 * occluded as the other lights are.  Its irradiance per unit radiance. */
#define DIRECT_SUN (-2)

/* Occluders clipped exactly at most; beyond, the fallback above. */
#define DIRECT_MAX_OCCLUDERS 48

/* Irradiance at x (unit normal n, on the side light arrives from) from
 * light primitive `light` per unit emission, with exact visibility;
 * receiver is the primitive x lies on (it casts no shadow on itself), -1
 * for none. */
double direct_irradiance(const direct_ctx *c, int light, vec3 x, vec3 n,
                         int receiver);

/* The same for one of a block of points side by side that share the
 * fallback's rays (split 0 is the call above).  DIRECT_SPLIT(j, i) is point
 * i of a 2^j x 2^j block (i's base-4 digits, lowest first, each the cell
 * (x & 1) + 2 (y & 1) of its 2 x 2 level): the pieces are 4^j times as
 * large, and each point's ray goes to the centre of one of a piece's 4^j
 * sub-pieces, the one its digits name, so that the block's points see,
 * between them, the centres one point sees, for one point's rays (when the
 * light's polygon has about as many fan triangles as the fallback has
 * pieces, the sun's disc say, the block's points also share those
 * triangles: each takes every s-th; when it has fewer pieces than the
 * block has points, points 4^k apart share).  A split point always sees
 * the light by rays, without searching for occluders, unless the scene has no more primitives than
 * are clipped exactly: Phase Two splits only where shadows are busy (a
 * mesh's detail, a busy shadow), and there the search nearly always finds
 * too many.  On the engine room skipping it takes Phase Two from 8.4 s to
 * 6.3 s, and changes 367 pixels by at most 0.4%. */
#define DIRECT_SPLIT(j, i) (((j) << 16) | ((i) + 1))
/* The same, but the sky's gather shared by blocks of k <= j levels only
 * (each point takes more of its directions), for blocks of which only a
 * few points may be shaded. */
#define DIRECT_SPLIT_SKY(j, k, i) ((((k) + 1) << 20) | DIRECT_SPLIT(j, i))
/* A split's levels j and point i (0 for split 0), and its sky's levels. */
#define DIRECT_SPLIT_LEVELS(split) (((split) >> 16) & 0xf)
#define DIRECT_SPLIT_SKY_LEVELS(split)                                                              \
    ((((split) >> 20) & 0xf) ? (((split) >> 20) & 0xf) - 1 : DIRECT_SPLIT_LEVELS(split))
/* A split point that stands for the 2 x 2 block of points a level finer
 * (a mesh detail pixel's block on one facet, samples.c): its pieces of a
 * light are those four's between them already (each of its pieces is cut
 * into the four's sub-pieces, lowest digit first); its sky directions are
 * the four's (phase_one.c). */
#define DIRECT_SPLIT_BLOCK (1 << 24)
#define DIRECT_SPLIT_INDEX(split) ((split) ? ((split) & 0xffff) - 1 : 0)
double direct_irradiance_split(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver,
                               int split);

/* The same by colour: panes on the way (a material with "thin") pass
 * their tint.  Without panes the three channels are the value above. */
vec3 direct_irradiance_rgb(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver,
                           int split);

/* The same where the light, if seen by rays, is cut into about `count`
 * triangles instead of the fallback's (rounded up to a whole number of
 * midpoint levels, as the fallback is).  Where that is fewer pieces than
 * the fallback's, the light is seen by rays without searching for
 * occluders: no exact clipping. */
vec3 direct_irradiance_rays(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver,
                            int split, int count);

/* One point's rays for a light part among many (a lamp of many triangles,
 * many lamps): the fallback's by the part's share of the light the point
 * receives, at least one, so that a point's rays do not grow with the
 * number of parts its light is cut into. */
int direct_rays_by_share(const direct_ctx *c, double share);

/* The rays this thread's direct-light calls have cast since the last
 * call (they are counted here, as the calls take no zone_trace): the
 * callers add them to their own count. */
uint64_t direct_rays_take(void);

/* Whether direct_irradiance sees light part `light` from x by rays (too
 * many occluders to clip): where a shadow is that busy, it may change
 * within a pixel. */
int direct_by_rays(const direct_ctx *c, int light, vec3 x, vec3 n);

/* The fraction of a pixel (corners on the screen, in order around it) in
 * which the eye sees light part `light` directly, with exact occlusion:
 * the pixel's footprint on the light's plane, cut like a shadow, measured
 * back on the screen.  -1 when too many occluders stand in the way (the
 * caller measures it by rays). */
double direct_pixel_coverage(const direct_ctx *c, int light, vec3 eye,
                             const vec3 corner[4]);

#endif
