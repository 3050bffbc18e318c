/* zt_render and the persistent renderer: option checks, the render scene,
 * and the dispatch to the path or zone tracer. */
#include "zonetrace/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "render/memory.h"
#include "render/render_internal.h"
#include "render/share.h"
#include "util/error.h"

zt_render_options zt_render_options_default(void)
{
    zt_render_options o;
    memset(&o, 0, sizeof o);
    o.method = ZT_METHOD_PATH;
    o.spp = 64;
    o.depth = 16;
    o.level = -1;
    o.quality = 2;
    return o;
}

static zt_status check_camera(const zt_camera *c, zt_error *err)
{
    if (c->width < 1 || c->height < 1)
        return zt_fail(err, ZT_ERR_ARGUMENT, "the camera has no pixels (%dx%d)",
                       c->width, c->height);
    return ZT_OK;
}

static zt_status check_options(const zt_scene *scene, const zt_render_options *o,
                               zt_error *err)
{
    if (o->method != ZT_METHOD_PATH && o->method != ZT_METHOD_ZONE)
        return zt_fail(err, ZT_ERR_ARGUMENT, "unknown method %d", (int)o->method);
    if (o->strategy != ZT_STRATEGY_PIXEL && o->strategy != ZT_STRATEGY_ZONE)
        return zt_fail(err, ZT_ERR_ARGUMENT, "unknown strategy %d", (int)o->strategy);
    if (o->spp < 1 || o->spp > (1 << 24))
        return zt_fail(err, ZT_ERR_ARGUMENT, "samples per pixel must be 1..16777216, not %d", o->spp);
    if (o->depth < 0 || o->depth > 1024)
        return zt_fail(err, ZT_ERR_ARGUMENT, "depth must be 0..1024, not %d", o->depth);
    if (o->level > o->depth)
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "level %d is deeper than depth %d (levels count from 0)",
                       o->level, o->depth);
    if (o->threads < 0 || o->threads > 1024)
        return zt_fail(err, ZT_ERR_ARGUMENT, "threads must be 0..1024, not %d", o->threads);
    if (!(o->cutoff >= 0))
        return zt_fail(err, ZT_ERR_ARGUMENT, "cutoff must be a number >= 0");
    if (o->quality < 0 || o->quality > 16)
        return zt_fail(err, ZT_ERR_ARGUMENT, "quality must be 0..16, not %d", o->quality);
    if (o->lights_off_count < 0 || o->lights_off_count > ZT_MAX_LIGHTS_OFF)
        return zt_fail(err, ZT_ERR_ARGUMENT, "too many lights switched off");
    for (int i = 0; i < o->lights_off_count; i++)
        if (o->lights_off[i] < 0 || o->lights_off[i] >= scene->light_count)
            return zt_fail(err, ZT_ERR_ARGUMENT,
                           "cannot switch off light %d: the scene has %d light%s",
                           o->lights_off[i], scene->light_count,
                           scene->light_count == 1 ? "" : "s");
    if (!(o->time_limit >= 0 && o->time_limit < 1e12))
        return zt_fail(err, ZT_ERR_ARGUMENT, "the time limit must be a number of seconds >= 0");
    if (o->time_limit > 0 && o->method == ZT_METHOD_ZONE && o->level >= 0)
        return zt_fail(err, ZT_ERR_ARGUMENT, "a time limit cannot be kept with a single level: "
                       "the zone tracer reaches a level only through all before it");
    if (!(o->checkpoint_seconds >= 0 && o->checkpoint_seconds < 1e12))
        return zt_fail(err, ZT_ERR_ARGUMENT, "the checkpoint interval must be a number of seconds >= 0");
    if ((o->checkpoint_file || o->resume) && o->method != ZT_METHOD_PATH)
        return zt_fail(err, ZT_ERR_ARGUMENT, "checkpoints are for the path tracer (the zone "
                       "tracer keeps its Phase One in a forest file)");
    if (o->resume && !o->checkpoint_file)
        return zt_fail(err, ZT_ERR_ARGUMENT, "resuming needs a checkpoint file");
    if (o->share && (o->share->ranks < 1 || o->share->rank < 0 ||
                     o->share->rank >= o->share->ranks ||
                     (o->share->ranks > 1 && !o->share->merge)))
        return zt_fail(err, ZT_ERR_ARGUMENT, "bad process share: rank %d of %d%s",
                       o->share->rank, o->share->ranks,
                       o->share->merge ? "" : " without a merge function");
    if (!scene->has_camera)
        return zt_fail(err, ZT_ERR_ARGUMENT, "the scene has no camera");
    return check_camera(&scene->camera, err);
}

void zt_renderer_release(zt_renderer *r)
{
    if (!r)
        return;
    zone_release(r);
    rscene_free(&r->rs);
    zt_scene_release(r->scene);
    free(r);
}

static zt_status renderer_create(const zt_scene *scene, const zt_render_options *o,
                                 double deadline, int one_image, zt_renderer **out,
                                 zt_render_stats *stats, zt_error *err)
{
    *out = NULL;
    zt_status st = check_options(scene, o, err);
    if (st == ZT_OK)
        st = share_check_same(scene, o, err);
    if (st != ZT_OK)
        return st;
    uint64_t need = memory_estimate_render(scene, o);
    if (stats)
        stats->memory_estimate = need;
    char what[160];
    snprintf(what, sizeof what, "this render (a %dx%d image, %d parts, %lld mesh triangles)",
             scene->camera.width, scene->camera.height, scene->part_count,
             scene_mesh_triangles(scene));
    st = memory_check(need, what, o, err);
    if (st != ZT_OK)
        return st;
    zt_renderer *r = calloc(1, sizeof *r);
    if (!r || !(r->scene = zt_scene_clone(scene))) {
        free(r);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    }
    r->options = *o;
    r->depth_asked = o->depth;
    r->memory_estimate = need;
    r->deadline = deadline;
    r->one_image = one_image;
    st = rscene_build(&r->rs, r->scene, o->lights_off, o->lights_off_count,
                      render_accel_kind(r->scene->part_count +
                                        scene_mesh_triangles(r->scene)), err);
    if (st == ZT_OK && o->method == ZT_METHOD_ZONE)
        st = zone_prepare(r, stats, err);
    if (st != ZT_OK) {
        zt_renderer_release(r);
        return st;
    }
    *out = r;
    return ZT_OK;
}

static double deadline_from(const zt_render_options *o, double t0)
{
    return o->time_limit > 0 ? t0 + o->time_limit : INFINITY;
}

zt_status zt_renderer_create(const zt_scene *scene, const zt_render_options *o,
                             zt_renderer **out, zt_error *err)
{
    return renderer_create(scene, o, deadline_from(o, render_clock()), 0, out, NULL, err);
}

zt_status zt_renderer_set_camera(zt_renderer *r, const zt_camera *camera,
                                 zt_error *err)
{
    zt_status st = check_camera(camera, err);
    if (st != ZT_OK)
        return st;
    zt_scene_set_camera(r->scene, camera);
    return ZT_OK;
}

zt_status zt_renderer_accumulate(zt_renderer *r, int first, int count, zt_image *sum,
                                 zt_render_stats *stats, zt_error *err)
{
    zt_render_stats local;
    if (!stats)
        stats = &local;
    if (sum->width != r->scene->camera.width || sum->height != r->scene->camera.height)
        return zt_fail(err, ZT_ERR_ARGUMENT, "accumulation image is %dx%d, the camera %dx%d",
                       sum->width, sum->height, r->scene->camera.width,
                       r->scene->camera.height);
    if (first < 0 || count < 1)
        return zt_fail(err, ZT_ERR_ARGUMENT, "bad sample range %d+%d", first, count);
    double t0 = render_clock();
    zt_status st = r->options.method == ZT_METHOD_PATH
                       ? path_accumulate(r, first, count, sum, stats, err)
                       : zone_accumulate(r, sum, stats, err);
    stats->seconds = render_clock() - t0;
    stats->trace_seconds = stats->seconds;
    return st;
}

zt_status zt_renderer_preview(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                              zt_error *err)
{
    if (r->options.method == ZT_METHOD_PATH)
        return zt_renderer_accumulate(r, 0, 1, sum, stats, err);
    zt_render_stats local;
    if (!stats)
        stats = &local;
    if (sum->width != r->scene->camera.width || sum->height != r->scene->camera.height)
        return zt_fail(err, ZT_ERR_ARGUMENT, "preview image is %dx%d, the camera %dx%d",
                       sum->width, sum->height, r->scene->camera.width,
                       r->scene->camera.height);
    double t0 = render_clock();
    zt_status st = zone_preview(r, sum, stats, err);
    stats->seconds = render_clock() - t0;
    stats->trace_seconds = stats->seconds;
    return st;
}

/* One image of the renderer's camera; t0 is when its time limit started. */
static zt_status renderer_render(zt_renderer *r, double t0, zt_image **out,
                                 zt_render_stats *stats, zt_error *err)
{
    const zt_render_options *o = &r->options; /* the zone tracer's depth may be lower */
    const zt_camera *c = &r->scene->camera;
    stats->depth_done = o->level >= 0 ? o->level : o->depth;
    if (o->method == ZT_METHOD_PATH)
        return path_render_passes(r, t0, out, stats, err);
    zt_image *img = zt_image_create(c->width, c->height);
    if (!img)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for a %dx%d image", c->width,
                       c->height);
    zt_status st = zt_renderer_accumulate(r, 0, 1, img, stats, err);
    if (st != ZT_OK) {
        zt_image_release(img);
        return st;
    }
    if (o->depth < r->depth_asked)
        stats->stopped = (zt_stop_reason)zone_stop_reason(r);
    *out = img;
    return ZT_OK;
}

zt_status zt_renderer_render(zt_renderer *r, zt_image **out, zt_render_stats *stats,
                             zt_error *err)
{
    zt_render_stats local;
    if (!stats)
        stats = &local;
    memset(stats, 0, sizeof *stats);
    *out = NULL;
    double t0 = render_clock();
    zt_status st = renderer_render(r, t0, out, stats, err);
    stats->seconds = stats->trace_seconds = render_clock() - t0;
    if (!stats->memory_estimate) /* the zone tracer's includes its forest */
        stats->memory_estimate = r->memory_estimate;
    return st;
}

zt_status zt_render(const zt_scene *scene, const zt_render_options *options,
                    zt_image **out, zt_render_stats *stats, zt_error *err)
{
    zt_render_stats local;
    if (!stats)
        stats = &local;
    memset(stats, 0, sizeof *stats);
    *out = NULL;
    double t0 = render_clock();
    zt_renderer *r;
    zt_status st = renderer_create(scene, options, deadline_from(options, t0), 1, &r, stats, err);
    if (st != ZT_OK)
        return st;
    double prepared = render_clock();
    zt_image *img = NULL;
    st = renderer_render(r, t0, &img, stats, err);
    zt_renderer_release(r);
    if (st != ZT_OK)
        return st;
    stats->seconds = render_clock() - t0;
    stats->trace_seconds = render_clock() - prepared;
    *out = img;
    return ZT_OK;
}
