/* zonetrace: rendering.
 *
 * Two renderers share one scene, material, light and camera model
 * (docs/light-transport.md): "path", an unbiased Monte Carlo path tracer,
 * and "zone", the deterministic zone tracer.  Both understand levels: level
 * L is the light that scattered exactly L times between a light and the
 * eye (0 = lights seen directly, 1 = direct illumination, ...), and depth D
 * keeps levels 0..D.
 */
#ifndef ZONETRACE_RENDER_H
#define ZONETRACE_RENDER_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include "zonetrace/error.h"
#include "zonetrace/image.h"
#include "zonetrace/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum zt_method { ZT_METHOD_PATH = 0, ZT_METHOD_ZONE = 1 } zt_method;

typedef enum zt_strategy {
    ZT_STRATEGY_PIXEL = 0, /* zone tracer: pixel by pixel */
    ZT_STRATEGY_ZONE = 1   /* zone tracer: zone by zone */
} zt_strategy;

/* Called from the rendering threads, serialised, about a hundred times per
 * stage of a render (the zone tracer's are "phase one K/N" for each level
 * of light it builds, then Phase Two's).  done/total count work units
 * (rows of tiles, nodes, zones...).  Return non-zero to cancel the render
 * (it then fails with ZT_ERR_CANCELLED). */
typedef int (*zt_progress_fn)(void *user, const char *stage, double done,
                              double total);

#define ZT_MAX_LIGHTS_OFF 64

/* One of several processes rendering the same scene with the same options
 * (MPI ranks: docs/cluster.md).  The work is dealt out in units (tiles,
 * rows of pixels, blocks of Phase One's nodes) round-robin by rank,
 * and the processes exchange results through merge; every process ends
 * with the image, the same bit for bit as one process renders. */
typedef struct zt_share {
    int rank;   /* this process: 0 .. ranks - 1 */
    int ranks;  /* >= 1 */
    /* Called by every process at the same points in the same order, with a
     * buffer of the same size whose every byte is either written by one
     * process alone (the others hold 0 there) or equal on all of them.  On
     * return each process's buffer holds the bitwise OR of all of them:
     * what each process wrote, everywhere.  Returns 0, or non-zero when the
     * exchange failed (the render then fails with ZT_ERR_EXCHANGE). */
    int (*merge)(void *user, void *buffer, size_t bytes);
    void *user;
} zt_share;

typedef struct zt_render_options {
    zt_method method;
    int spp;            /* path: samples per pixel (>= 1) */
    int depth;          /* maximum scattering events (>= 0) */
    int level;          /* < 0: all levels up to depth; else only this one */
    uint64_t seed;      /* path: sampler seed */
    int threads;        /* 0: all cores */
    /* Light objects (by index, as in the scene file) that are switched off. */
    int lights_off[ZT_MAX_LIGHTS_OFF];
    int lights_off_count;
    /* Zone tracer */
    zt_strategy strategy;
    double cutoff;      /* prune zones whose power bound is below this */
    int quality;        /* zone: discretisation level, higher is finer */
    zt_progress_fn progress;
    void *progress_user;
    /* Zone tracer: when not NULL, the forest is read from this file (written
     * by zt_renderer_save_forest) instead of being built: creating the
     * renderer then costs no Phase One.  The file must have been made for
     * the same scene (geometry, materials, lights, sky) with the same
     * effective depth (the level when one is given), cutoff, quality and
     * lights-off set; the camera may differ.  Otherwise, or when the file
     * is truncated, corrupt or of another format version, creation fails
     * with ZT_ERR_PARSE (ZT_ERR_READ when it cannot be read) and a message
     * naming the file and the reason.  Format: docs/zone-tracer.md. */
    const char *forest_file;

    /* Long renders (docs/long-renders.md): zt_render and zt_renderer_render
     * (zt_renderer_accumulate takes no notice of them). */
    /* Seconds the whole zt_render may take (0: no limit).  Path tracer:
     * whole passes of samples while the next one fits, at least one sample
     * per pixel; spp is then an upper bound.  Zone tracer: Phase One builds
     * the levels that fit and the image has the depth reached (not with
     * level >= 0).  stats say what was reached.  A persistent renderer
     * counts it from zt_renderer_create for its Phase One and from each
     * zt_renderer_render for the path tracer's passes. */
    double time_limit;
    /* When not NULL and it becomes non-zero (a signal handler's flag): the
     * path tracer finishes its pass and returns the image of the samples
     * done; the zone tracer builds no further level. */
    const volatile sig_atomic_t *stop;
    /* Path tracer: the running sums and the sample count are written to this
     * file (atomically) every checkpoint_seconds, when the render stops
     * early and when it ends.  With resume, the render continues from the
     * file, which must be for the same scene, camera, seed, depth, level and
     * lights-off, with at most spp samples (else ZT_ERR_PARSE); the image
     * is then bit for bit the one an uninterrupted render gives. */
    const char *checkpoint_file;
    double checkpoint_seconds; /* 0: 300 */
    int resume;
    /* Bytes the render may use (0: the machine's physical memory, or the
     * control group's limit when lower).  A render whose estimate (image,
     * scene, acceleration structure, zone forest) passes it fails before
     * the work with ZT_ERR_MEMORY and a message with the size it needs. */
    uint64_t max_memory;

    /* When not NULL with ranks > 1: this process does its share of the
     * work of zt_render (path tracer: its tiles; zone tracer: its
     * blocks of nodes at every level of Phase One and its rows of Phase
     * Two) and of a zone renderer's zt_renderer_create and
     * zt_renderer_accumulate; the path tracer's zt_renderer_accumulate
     * refuses it.  Stops, time limits and checkpoints are agreed: the
     * passes are the ones the slowest process can fit, and only rank 0
     * reads and writes the checkpoint file. */
    const zt_share *share;
} zt_render_options;

/* Defaults: path method, 64 spp, depth 16, all levels, seed 0, all cores. */
zt_render_options zt_render_options_default(void);

/* Why zt_render returned an image with less than was asked for. */
typedef enum zt_stop_reason {
    ZT_STOP_NONE = 0,      /* everything asked for was rendered */
    ZT_STOP_TIME = 1,      /* options.time_limit */
    ZT_STOP_INTERRUPT = 2  /* options.stop */
} zt_stop_reason;

/* How the zone tracer's Phase Two sampled a pixel (docs/zone-tracer.md,
 * "Phase Two"), for its time split in zt_render_stats. */
typedef enum zt_pixel_kind {
    ZT_PIXEL_ONE = 0,  /* one smooth surface: the quality's g x g samples */
    ZT_PIXEL_CURVED,   /* a sphere on the way: 2 x 2 */
    ZT_PIXEL_DETAIL,   /* a mesh's sub-pixel detail: 8 x 8 sharing one point's rays */
    ZT_PIXEL_SHADOW,   /* a busy shadow: 2 x 2 sharing one point's rays */
    ZT_PIXEL_EDGE,     /* an edge: coverage grid, its groups shaded on a subset */
    ZT_PIXEL_FINE,     /* a light's image in a mirror or glass: the fine grid */
    ZT_PIXEL_KINDS
} zt_pixel_kind;

typedef struct zt_render_stats {
    double seconds;        /* wall time of the whole render */
    double trace_seconds;  /* of which rendering the image itself (the rest
                              prepares the scene: acceleration structure,
                              and for the zone tracer Phase One) */
    uint64_t samples;      /* camera samples taken */
    uint64_t rays;         /* rays traced (camera, extension and shadow) */
    int threads;           /* threads used */
    /* zone tracer */
    double phase_one_seconds;
    double phase_two_seconds;
    uint64_t zones;
    uint64_t zones_pruned;
    uint64_t zones_per_level[32];
    uint64_t memory_bytes;
    uint64_t cuts;         /* zone, Phase One: transfer cuts made (0 when
                              the forest was read from a file) */
    uint64_t cuts_capped;  /* of which reached the cluster limit: the rest
                              of their light is estimated more coarsely
                              (docs/zone-tracer.md) */
    uint64_t cuts_shared;  /* of which started from a nearby node's cut
                              (a mesh's vertex nodes in groups) */
    uint64_t nodes_gathered; /* zone, Phase One: nodes whose transfer was
                              gathered instead of cut (docs/zone-tracer.md) */
    int sky_portals;       /* zone: windows whose panes the sky's gather
                              aims at (docs/zone-tracer.md) */
    int forest_loaded;     /* zone: the forest came from options.forest_file
                              (phase_one_seconds is then the time to read it) */
    /* zone, Phase Two's time split in thread-seconds (the sum over threads
     * of the time each spent there; this process's share of the image):
     * finding every pixel's samples, the gathers at pixel centres on
     * meshes, and shading the pixels of each kind (the pixel strategy
     * only; the zone strategy's shading is not split), with how many
     * pixels and samples each kind had. */
    double p2_lists_seconds;
    double p2_records_seconds;
    double p2_shade_seconds[ZT_PIXEL_KINDS];
    uint64_t p2_pixels[ZT_PIXEL_KINDS];
    uint64_t p2_samples[ZT_PIXEL_KINDS];
    /* zt_render */
    int spp_done;          /* path: samples per pixel in the image */
    int spp_resumed;       /* path: of which read from the checkpoint */
    int depth_done;        /* the depth the image has (zone: below the
                              options' when the time ran out) */
    zt_stop_reason stopped;
    uint64_t memory_estimate; /* bytes, as checked against max_memory */
} zt_render_stats;

/* Renders the scene through its camera into a new linear image (*out, the
 * caller's).  stats may be NULL.  The zone tracer's forest here serves
 * this one image: Phase One leaves out what its Phase Two does not read
 * (the last level on meshes, docs/zone-tracer.md); zt_renderer_create
 * builds it whole, for previews and zt_renderer_save_forest. */
zt_status zt_render(const zt_scene *scene, const zt_render_options *options,
                    zt_image **out, zt_render_stats *stats, zt_error *err);

/* A renderer kept between images: the scene's acceleration structure (and,
 * for the zone tracer, its forest) is built once, so a moving camera or more
 * samples cost only the rendering itself.  Used by the viewer. */
typedef struct zt_renderer zt_renderer;

/* Prepares scene (copied: later changes to it do not affect the renderer)
 * for rendering with options.  *out is the caller's.  The options are kept
 * (their progress and stop pointers too) for the renderer's life. */
zt_status zt_renderer_create(const zt_scene *scene,
                             const zt_render_options *options,
                             zt_renderer **out, zt_error *err);

/* Replaces the camera (its resolution may change too). */
zt_status zt_renderer_set_camera(zt_renderer *renderer, const zt_camera *camera,
                                 zt_error *err);

/* Adds samples first_sample .. first_sample+count-1 of every pixel (path
 * tracer; the zone tracer ignores the numbers and renders its one image)
 * to sum, an image of the camera's size holding running sums of radiance.
 * Samples are numbered, so sums of consecutive batches equal one render
 * with the total count: sum/count is the image.  stats may be NULL. */
zt_status zt_renderer_accumulate(zt_renderer *renderer, int first_sample,
                                 int count, zt_image *sum,
                                 zt_render_stats *stats, zt_error *err);

/* Adds a quick image of the renderer's camera to sum (an image of the
 * camera's size), for a camera that is moving.  Zone tracer: one sample per
 * pixel at its centre, every level of light read from the forest's nodes
 * (no exact direct light, no gathers, no edge coverage): about one ray a
 * pixel, with shadows as soft as the nodes' spacing and aliased edges.
 * Path tracer: sample 0 of every pixel, as zt_renderer_accumulate(0, 1).
 * Cancelled through the progress callback like an image. */
zt_status zt_renderer_preview(zt_renderer *renderer, zt_image *sum,
                              zt_render_stats *stats, zt_error *err);

/* Renders the renderer's camera into a new linear image (*out, the
 * caller's) as zt_render does: the image is the same, bit for bit, as
 * zt_render of the scene with this camera and these options (path tracer:
 * options.spp samples in double-precision sums, in passes that honour the
 * time limit, stop and checkpoint; zone tracer: Phase Two over the
 * renderer's forest).  With options.share every process calls it.  stats
 * (may be NULL) are this image's; the zone tracer charges Phase One to a
 * renderer's first image. */
zt_status zt_renderer_render(zt_renderer *renderer, zt_image **out,
                             zt_render_stats *stats, zt_error *err);

void zt_renderer_release(zt_renderer *renderer);

/* Zone tracer: writes the renderer's forest (the zones, their occluder
 * lists and the irradiance maps: everything Phase One computes; it does not
 * depend on the camera) to path, replacing the file atomically.  A renderer
 * created with options.forest_file = path and the same scene and options
 * then renders the same images bit for bit without Phase One.  Fails with
 * ZT_ERR_ARGUMENT for a path-tracing renderer, ZT_ERR_WRITE when the file
 * cannot be written. */
zt_status zt_renderer_save_forest(const zt_renderer *renderer, const char *path,
                                  zt_error *err);

/* The library's version string, e.g. "0.1.0". */
const char *zt_version(void);

#ifdef __cplusplus
}
#endif
#endif
