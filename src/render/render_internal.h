/* Shared by the renderers' drivers. */
#ifndef ZT_RENDER_RENDER_INTERNAL_H
#define ZT_RENDER_RENDER_INTERNAL_H

#include "zonetrace/render.h"
#include "scene/scene.h"

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

zt_status render_path(const zt_scene *scene, const zt_render_options *o,
                      zt_image *img, zt_render_stats *stats, zt_error *err);
zt_status render_zone(const zt_scene *scene, const zt_render_options *o,
                      zt_image *img, zt_render_stats *stats, zt_error *err);

/* The acceleration structure renderers use; ZT_ACCEL=brute in the
 * environment selects the brute-force oracle (for tests and benchmarks). */
int render_accel_kind(void);

#endif
