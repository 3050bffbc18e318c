/* Next-event estimation: choosing a light and a point on it, and the density
 * of that choice for multiple importance sampling.
 *
 * Area lights (triangles, spheres) emit their emission as radiance from the
 * front (both sides when not backculled); point lights emit it as radiant
 * intensity.  Light planes are unbounded and left to BSDF sampling. */
#ifndef ZT_LIGHT_LIGHT_SAMPLE_H
#define ZT_LIGHT_LIGHT_SAMPLE_H

#include "render/render_scene.h"

typedef struct light_sample {
    vec3f wi;        /* unit direction from the shaded point to the light */
    float dist;      /* distance to the sampled point */
    vec3f li;        /* radiance arriving (area) or intensity/dist^2 (point) */
    float pdf;       /* solid-angle density including the light choice;
                        for points the choice probability alone */
    int delta;       /* a point light: no MIS */
    int part;        /* the light's part */
} light_sample;

/* Picks a light with u_select and a point on it with u2, as seen from x.
 * Returns 0 when the sample carries nothing (back of a culled light...). */
int light_sample_point(const rscene *rs, vec3f x, float u_select,
                       const float u2[2], light_sample *out);

/* The density with which light_sample_point would have chosen direction wi
 * from x, reaching light primitive p (rs_prim) at distance t. */
float light_pdf(const rs_part *p, vec3f x, vec3f wi, float t);

/* Radiance leaving light primitive prim (view p) at point y towards
 * direction -d (d is the ray direction arriving at y): its emission, times
 * its emissive texture's texel at y when it has one. */
vec3f light_emitted(const rscene *rs, int prim, const rs_part *p, vec3f y, vec3f d);

#endif
