/* Light by way of mirrors, metal and glass at a node, gathered. */
#ifndef ZT_ZONE_SPECULAR_GATHER_H
#define ZT_ZONE_SPECULAR_GATHER_H

#include "zone/zone.h"

/* The irradiance of level `level` arriving at x (normal n) by way of
 * specular surfaces (diffuse surfaces are the transfer's), without the
 * caustics and glints (caustic.c, glint.c).  It can only come from within
 * the cones that the specular targets' bounding spheres subtend
 * (specular_targets.h), so the gather aims there: each target seen under a
 * cone narrower than pi sr gets its own directions, uniform in the cone,
 * at least q.gather / 8 of them and never sparser than the hemisphere's;
 * the rest
 * (wide cones, a target around the node, a specular plane) are found by
 * the q.gather directions over the hemisphere.  All directions are weighed
 * together by the balance heuristic: a direction's value x cos over the
 * sum of every strategy's count x density there.  Aimed at a mirror sphere
 * beside the engine room's engine, a node casts a few dozen rays where
 * the hemisphere cast 256 and most missed.  When the aimed directions
 * would outnumber the hemisphere's, the hemisphere alone serves. */
vec3 zone_specular_gather(zone_trace *t, vec3 x, vec3 n, int level);

#endif
