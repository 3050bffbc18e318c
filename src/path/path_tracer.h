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

/* One radiance sample along the camera ray (o, d) for the pixel with sampler
 * key pixel_key and sample number index.  *rays counts traced rays. */
vec3f path_trace_sample(const rscene *rs, const path_params *pp, vec3f o,
                        vec3f d, uint32_t pixel_key, uint32_t index,
                        uint64_t *rays);

#endif
