/* Caustic maps: light that reaches a diffuse surface by way of mirrors,
 * metal or glass, traced from the lights instead of gathered.  Seen from a
 * texel, a light focused by a glass ball is a small bright image that a
 * fixed set of gather directions finds in some texels and misses in their
 * neighbours; seen from the light, the same light is a bundle of rays aimed
 * at the ball, which a fixed low-discrepancy set of rays samples evenly.
 *
 * For every emitting triangle or sphere light and every specular target
 * (a part other than a plane with mirror, metallic or refractive weight),
 * rays from points on the light towards the target (its bounding cone, or
 * points on a triangle) that hit the target first are followed through
 * every specular interaction (glass: both the reflected and the transmitted
 * ray, with Fresnel weights).  Where a ray meets a mapped diffuse surface
 * after k >= 1 specular events, its flux over the texel's area is added to
 * E_k of that texel (and over a fine cell's area to a quarter-texel grid
 * where the caustic is concentrated: map_detail in zone_maps.h).  The gathers leave exactly these chains out
 * (ZR_NO_CAUSTIC), and the one reflection off a glint sphere straight onto
 * a texel stays with glint.c. */
#ifndef ZT_ZONE_CAUSTIC_H
#define ZT_ZONE_CAUSTIC_H

#include "zone/zone_internal.h"

/* Whether the photons start at part i: a non-light part, not a plane, that
 * has a specular lobe.  A gather ray that meets a triangle or sphere light
 * right after such a part (and after no diffuse event) counts nothing. */
int caustic_target(const rscene *rs, int i);

/* Adds the caustic irradiance of levels 1..f->map_levels-1 into the maps'
 * texels (which must hold zeros or other light of the same levels, and
 * their weights and covers).  Deterministic: the same bytes at any thread
 * count.  Counts its rays in f->rays. */
zt_status caustic_build(zone_forest *f, const zt_renderer *r, zt_error *err);

/* After the last level: takes the caustics kept apart (map_detail) out of
 * the texels and lets reads add them instead, finely where they are
 * concentrated.  Returns 0 when out of memory. */
int caustic_finish(zone_forest *f);

#endif
