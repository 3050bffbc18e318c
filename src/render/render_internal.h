/* Shared by the renderers' drivers. */
#ifndef ZT_RENDER_RENDER_INTERNAL_H
#define ZT_RENDER_RENDER_INTERNAL_H

#include "zonetrace/render.h"
#include "scene/scene.h"
#include "render/render_scene.h"

/* Wall-clock seconds from an arbitrary origin. */
double render_clock(void);

/* The lights switched off in o, ascending and without repeats, into out;
 * returns their count.  Files made for one render (forest files,
 * checkpoints) record this form, so the order they were given in does not
 * matter. */
int render_lights_off_sorted(const zt_render_options *o, int out[ZT_MAX_LIGHTS_OFF]);

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
    double deadline;            /* render_clock() time for Phase One to be
                                   done by (INFINITY: no time limit) */
    int depth_asked;            /* options.depth as given (the zone tracer
                                   lowers options.depth to what it built) */
    uint64_t memory_estimate;   /* bytes: image, scene copy, acceleration
                                   (render/memory.h); the zone tracer adds
                                   its forest's */
    int one_image;              /* made by zt_render for one image: the
                                   forest need hold only what its Phase Two
                                   reads (no preview, not saved) */
};

/* Where path-traced samples go: running sums in double (continued sample
 * by sample: the same bits however the samples are split into passes), or
 * added to a float image (the viewer's accumulation). */
typedef struct path_sums {
    double *dsum;  /* 3 per pixel, or NULL */
    float *fsum;   /* used when dsum is NULL */
    int width, height;
} path_sums;

/* Adds samples first..first+count-1 of every pixel to out.  shared, when
 * not NULL, is a progress counting tiles times samples over several calls. */
zt_status path_accumulate_into(zt_renderer *r, int first, int count, path_sums out,
                               progress *shared, zt_render_stats *stats, zt_error *err);

/* Split over processes (render/share.h), the path tracer deals out its
 * tiles: how many of a width x height image's are this process's, and
 * clearing the others' pixels in sums (3 doubles a pixel). */
long long path_tiles_owned(const zt_render_options *o, int width, int height);
void path_clear_others(const zt_render_options *o, double *sums, int width, int height);

/* zt_render's path tracer (passes.c): passes until spp, the time limit or
 * a stop, with checkpoints; t0 is when zt_render began. */
zt_status path_render_passes(zt_renderer *r, double t0, zt_image **out,
                             zt_render_stats *stats, zt_error *err);

/* Adds path-traced samples first..first+count-1 of every pixel to sum. */
zt_status path_accumulate(zt_renderer *r, int first, int count, zt_image *sum,
                          zt_render_stats *stats, zt_error *err);

/* Zone tracer: Phase One (on creation) and Phase Two (per image). */
zt_status zone_prepare(zt_renderer *r, zt_render_stats *stats, zt_error *err);
zt_status zone_accumulate(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                          zt_error *err);
/* One sample per pixel from the forest's nodes (phase_two/preview.c). */
zt_status zone_preview(zt_renderer *r, zt_image *sum, zt_render_stats *stats, zt_error *err);
void zone_release(zt_renderer *r);
/* Why Phase One built fewer levels than asked (a zt_stop_reason). */
int zone_stop_reason(const zt_renderer *r);

/* The acceleration structure for a scene of that many primitives: our BVH
 * for small scenes, Embree for large ones, unless ZT_ACCEL in the
 * environment says "embree", "bvh" or "brute" (for tests and benchmarks). */
#define ACCEL_SMALL_SCENE 1000
int render_accel_kind(long long primitives);

#endif
