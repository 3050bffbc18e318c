/* Light from far away: the environment map (times its strength, turned
 * about +y) and the sun, a disc of directions of uniform radiance.  Both
 * renderers read their radiance along escaping rays; the path tracer also
 * samples them for next-event estimation, as one mixture: the sun with
 * probability sun_select, else the map by its luminance.  The constant sky
 * (rscene.sky) is not part of it: a uniform background gains nothing from
 * light sampling and stays with BSDF sampling alone. */
#ifndef ZT_LIGHT_DISTANT_H
#define ZT_LIGHT_DISTANT_H

#include "render/render_scene.h"

/* Fills d from the scene's sky map and sun (any = 0 when it has neither). */
void distant_build(rs_distant *d, const zt_scene *scene);

/* Radiance arriving from unit direction w (map and sun). */
vec3f distant_radiance(const rs_distant *d, vec3f w);

/* Radiance arriving from unit direction w from the map alone (no sun). */
vec3f distant_map_radiance(const rs_distant *d, vec3f w);

/* Whether unit direction w lies in the sun's disc. */
int distant_in_sun(const rs_distant *d, vec3f w);

/* The mixture's solid-angle density of direction w. */
float distant_pdf(const rs_distant *d, vec3f w);

/* distant_radiance and distant_pdf together, with one map lookup. */
vec3f distant_eval(const rs_distant *d, vec3f w, float *pdf);

/* Draws a direction: the sun or the map by u_select, the direction from
 * u[2].  Sets *w, its mixture density *pdf and the radiance *li arriving
 * from it; returns 0 when nothing can be drawn. */
int distant_sample(const rs_distant *d, float u_select, const float u[2], vec3f *w,
                   float *pdf, vec3f *li);

/* Draws a direction from the map alone (u[2]), with its radiance (strength
 * applied) in *l; returns the map's density of it, 0 when none. */
float distant_map_sample(const rs_distant *d, const float u[2], vec3f *w, vec3f *l);

/* A direction in the sun's disc from u[2] (uniform in solid angle). */
vec3f distant_sun_direction(const rs_distant *d, const float u[2]);

#endif
