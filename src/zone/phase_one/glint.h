/* Light reaching a diffuse point after one reflection off a mirror, metal or
 * glass sphere, computed from the light's image in the sphere instead of by
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

#include "zone/zone.h"

/* Whether part i is a sphere whose reflection off its outside
 * glint_irradiance accounts for (mirror, metal or glass; not a light).
 * Light through glass is not an image here: it is gathered. */
int glint_sphere(const rscene *rs, int i);

/* The point *s on sphere (c, r) where light from y reflects towards x (both
 * outside).  Returns 0 when the reflection would be at or past grazing for
 * either point. */
int glint_specular_point(vec3 c, double r, vec3 x, vec3 y, vec3 *s);

/* Irradiance at x (unit normal n) from every emitting triangle and sphere
 * light (rs->lights) by way of one reflection off the glint spheres
 * spheres[0..sphere_count-1]; a triangle light is cut subdivisions ways
 * along each side, a sphere light's outline has 4 x subdivisions corners.
 * Visibility, emission and reflectance are taken once per light part (at
 * its centre, or a sphere light's point facing the image). */
vec3 glint_irradiance(zone_trace *t, const int *spheres, int sphere_count, vec3 x, vec3 n,
                      int subdivisions);

#endif
