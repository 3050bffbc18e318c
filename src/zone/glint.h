/* Light reaching a diffuse point after one reflection off a mirror or metal
 * sphere, computed from the light's image in the sphere instead of by
 * gathering: that image is small and bright, and a fixed set of gather
 * directions finds it in some texels and misses it in their neighbours.
 * The light is cut into small triangles; each corner is carried to its
 * specular point on the sphere (the point whose normal halves the angle
 * between the receiver and the corner), and the directions to those points
 * bound the triangle's image, whose irradiance is Lambert's formula.  The
 * straight edges between mapped corners are the discretisation; it shrinks
 * as the triangles do. */
#ifndef ZT_ZONE_GLINT_H
#define ZT_ZONE_GLINT_H

#include "zone/zone_internal.h"

/* Whether part i is a sphere whose reflection glint_irradiance accounts
 * for (mirror or metal, not glass, not a light). */
int glint_sphere(const rscene *rs, int i);

/* Irradiance at x (unit normal n) from every area light by way of one
 * reflection off a glint sphere, with visibility tested at each small
 * triangle's centre. */
vec3 glint_irradiance(zone_trace *t, vec3 x, vec3 n, int subdivisions);

#endif
