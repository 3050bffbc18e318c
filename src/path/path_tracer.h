/* The reference path tracer: unbiased radiance estimates along camera
 * paths with next-event estimation, multiple importance sampling (power
 * heuristic) against BSDF sampling, and Russian roulette. */
#ifndef ZT_PATH_PATH_TRACER_H
#define ZT_PATH_PATH_TRACER_H

#include <stdint.h>
#include "render/render_scene.h"

typedef struct path_params {
    int min_level;   /* contributions with fewer scattering events are dropped */
    int max_level;   /* paths stop after this many scattering events */
    uint32_t seed;
} path_params;

/* The dimension pairs every sample draws from the stratified sampler: the
 * pixel position, then the first vertex's light point and direction, and
 * its direction toward light from far away (sun, environment map). */
#define PATH_SEEDED_PAIRS 4

/* A pixel's sampler key and the scramble seeds of those pairs
 * (sampler_pair_seed), which are the same for all its samples. */
typedef struct path_pixel {
    uint32_t key;
    uint32_t pair_seed[PATH_SEEDED_PAIRS];
} path_pixel;

path_pixel path_pixel_make(uint32_t key);

/* One radiance sample along the camera ray (o, d) for pixel px and sample
 * number index, whose bits reversed are rev_index.  *rays counts traced
 * rays. */
vec3f path_trace_sample(const rscene *rs, const path_params *pp, vec3f o,
                        vec3f d, const path_pixel *px, uint32_t index,
                        uint32_t rev_index, uint64_t *rays);

#endif
