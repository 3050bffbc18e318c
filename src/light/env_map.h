/* An environment map: an equirectangular (latitude-longitude) image of the
 * radiance arriving from far away, and the distribution that importance
 * samples it.
 *
 * Orientation, in the map's own frame (the scene's, before `rotate`): the
 * top row looks straight up (+y), the bottom row straight down; the centre
 * column looks along -z, the column a quarter from the left along -x, three
 * quarters along +x, and the left and right edges along +z.  Seen from
 * inside, the image is therefore not mirrored: a camera looking along -z
 * with +x to its right sees the middle of the image the right way round.
 *
 * Radiance is piecewise constant: each texel's value over its solid angle
 * (no filtering), so that the sampling density below is exactly
 * proportional to luminance x solid angle and the estimator has no
 * mismatch.  The map is immutable once made and shared by reference
 * (scene copies, renderers). */
#ifndef ZT_LIGHT_ENV_MAP_H
#define ZT_LIGHT_ENV_MAP_H

#include "util/vec3f.h"

typedef struct env_map {
    int refs;
    int width, height;
    float *rgb;         /* width*height*3, top row (+y) first */
    /* Sampling: rows by marginal_cdf (height + 1 entries, 0 .. 1), then a
     * column within the row by its conditional cdf (row r: width + 1
     * entries at conditional_cdf[r * (width + 1)]).  A texel's weight is its
     * luminance times its solid angle; rows of zero weight get none. */
    float *marginal_cdf;
    float *conditional_cdf;
    double *row_cos;    /* cos of the polar angle at each row boundary
                           (height + 1), for sampling */
    double weight_sum;  /* sum of luminance x solid angle (W/m^2 of luminance
                           over the whole sphere) */
    double mean_luminance; /* luminance averaged over the sphere by solid angle */
} env_map;

/* A map of width x height texels from rgb (copied; width*height*3 floats,
 * top row first).  Every value must be finite and >= 0 (the caller checks
 * and reports).  NULL when out of memory.  refs is 1. */
env_map *env_map_create(const float *rgb, int width, int height);

env_map *env_map_retain(env_map *m);
void env_map_release(env_map *m);

/* Texel coordinates (u, v in [0,1), u across, v down) of unit direction d in
 * the map's frame, and back (d for the centre of (u, v)). */
void env_map_uv(vec3f d, float *u, float *v);
vec3f env_map_direction(float u, float v);

/* Radiance from unit direction d (the map's frame): the texel's value. */
vec3f env_map_radiance(const env_map *m, vec3f d);

/* Draws a direction (map's frame) from u[2] in [0,1)^2 with density
 * proportional to luminance; returns its solid-angle density (0 when the
 * map is black everywhere: nothing to sample). */
float env_map_sample(const env_map *m, const float u[2], vec3f *d);

/* The solid-angle density with which env_map_sample draws d. */
float env_map_pdf(const env_map *m, vec3f d);

/* Both at once (one texel lookup): the radiance from d, and its density in
 * *pdf. */
vec3f env_map_lookup(const env_map *m, vec3f d, float *pdf);

#endif
