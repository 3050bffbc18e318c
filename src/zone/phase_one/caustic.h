/* Caustics: light that reaches a diffuse surface by way of mirrors,
 * metal or glass, traced from the lights instead of gathered.  Seen from a
 * point, a light focused by a glass ball is a small bright image that a
 * fixed set of gather directions finds from some points and misses from their
 * neighbours; seen from the light, the same light is a bundle of rays aimed
 * at the ball, which a fixed low-discrepancy set of rays samples evenly.
 *
 * For every emitting triangle or sphere light and every specular target
 * (specular_targets.h), rays from points on the light towards the target (its bounding cone, or
 * points on a triangle part) that hit the target first are followed through
 * every specular interaction (glass: both the reflected and the transmitted
 * ray, with Fresnel weights).  Where a ray meets a diffuse surface after
 * k >= 1 specular events, its flux is shared among the nodes around the
 * point (by their interpolation weights) and added to their E_k over their
 * areas.  The gathers leave exactly these chains out
 * (ZR_NO_CAUSTIC), and the one reflection off a glint sphere straight onto
 * a node stays with glint.c. */
#ifndef ZT_ZONE_CAUSTIC_H
#define ZT_ZONE_CAUSTIC_H

#include "zone/zone.h"

/* Adds the caustic irradiance of levels 1..f->map_levels-1 onto the nodes
 * (f->e, which holds zeros or other light of the same levels; the nodes'
 * life must be marked).  Deterministic: the same bytes at any thread
 * count.  Counts its rays in f->rays. */
zt_status caustic_build(zone_forest *f, const zt_renderer *r, zt_error *err);

#endif
