/* A path tracer's rays for the benchmarks: camera rays over the screen,
 * one diffuse bounce from each hit, and visibility rays between random
 * pairs of the hit points, recorded once so that several backends trace the
 * very same rays; and their throughput. */
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

/* Traces one recorded ray (a visibility query when any) and returns
 * something that depends on the answer, so the work cannot be dropped. */
typedef long (*bench_trace_fn)(const void *ctx, const bench_ray *r, int any);

/* The renderers' queries, accel_intersect and accel_occluded; ctx is the
 * rscene. */
long bench_trace_accel(const void *rs, const bench_ray *r, int any);

/* Million rays per second over the set's nearest (or, with any, visibility)
 * rays on `threads` threads: the best of `runs` runs, each repeating the
 * set for at least min_seconds. */
double bench_throughput(const ray_set *set, int any, int threads, bench_trace_fn trace,
                        const void *ctx, int runs, double min_seconds);

#endif
