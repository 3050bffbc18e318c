/* A path tracer's rays for the benchmarks: camera rays over the screen,
 * one diffuse bounce from each hit, and visibility rays between random
 * pairs of the hit points, recorded once so that several backends trace the
 * very same rays. */
#ifndef ZT_BENCH_RAYS_H
#define ZT_BENCH_RAYS_H

#include <stdint.h>

#include "render/render_scene.h"
#include "util/vec3f.h"
#include "zonetrace/scene.h"

typedef struct bench_ray {
    vec3f o, d;
    float dist;  /* visibility rays: the target's distance */
    int bg;      /* and whether it is in the background */
} bench_ray;

typedef struct ray_set {
    bench_ray *nearest, *any;
    int n_nearest, n_any;
} ray_set;

/* A uniform number in [0, 1) from a xorshift state. */
float bench_rnd(uint32_t *s);

/* camera_rays camera rays of the scene's camera and the rest as above,
 * traced through rs (its accel built).  Exits when out of memory. */
void bench_make_rays(const rscene *rs, const zt_scene *scene, int camera_rays, ray_set *set);

void bench_free_rays(ray_set *set);

#endif
