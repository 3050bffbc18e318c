/* Lambert's formula: the irradiance at a point from a uniformly emitting
 * polygon, as a sum over the polygon's edges.  This is what makes direct
 * light exact in the zone tracer. */
#ifndef ZT_ZONE_LAMBERT_H
#define ZT_ZONE_LAMBERT_H

#include "util/vec3.h"

/* Irradiance at x (unit normal n) from a convex polygon of unit radiance
 * with vertices q[0..count-1], all on the side of x's tangent plane that n
 * points to: (1/2) |sum_i theta_i n . (a_i x a_i+1)/|a_i x a_i+1||, where
 * a_i are the unit directions to the vertices and theta_i the angles
 * between neighbours. */
double lambert_polygon(vec3 x, vec3 n, const vec3 *q, int count);

#endif
