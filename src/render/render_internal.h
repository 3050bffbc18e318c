/* Shared by the renderers' drivers. */
#ifndef ZT_RENDER_RENDER_INTERNAL_H
#define ZT_RENDER_RENDER_INTERNAL_H

#include "zonetrace/render.h"
#include "scene/scene.h"
#include "render/render_scene.h"

/* Wall-clock seconds from an arbitrary origin. */
double render_clock(void);

/* The number of threads to use for a requested count (0 = all cores). */
int render_thread_count(int requested);

/* Serialised progress reports, at most every 1% of the work: returns
 * non-zero when the caller asked to cancel. */
typedef struct progress {
    zt_progress_fn fn;
    void *user;
    const char *stage;
    double total;
    double done;
    int last_percent;
    volatile int cancelled;
} progress;

void progress_init(progress *p, const zt_render_options *o, const char *stage,
                   double total);
/* Adds amount of finished work; thread-safe. */
void progress_add(progress *p, double amount);

/* The state a renderer keeps between images. */
struct zone_forest;
struct zt_renderer {
    zt_scene *scene;            /* the renderer's own copy */
    zt_render_options options;
    rscene rs;
    struct zone_forest *forest; /* zone tracer only */
};

/* Adds path-traced samples first..first+count-1 of every pixel to sum. */
zt_status path_accumulate(zt_renderer *r, int first, int count, zt_image *sum,
                          zt_render_stats *stats, zt_error *err);

/* Zone tracer: Phase One (on creation) and Phase Two (per image). */
zt_status zone_prepare(zt_renderer *r, zt_render_stats *stats, zt_error *err);
zt_status zone_accumulate(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                          zt_error *err);
void zone_release(zt_renderer *r);

/* The acceleration structure for a scene of that many primitives: our BVH
 * for small scenes, Embree for large ones, unless ZT_ACCEL in the
 * environment says "embree", "bvh" or "brute" (for tests and benchmarks). */
#define ACCEL_SMALL_SCENE 1000
int render_accel_kind(long long primitives);

#endif
