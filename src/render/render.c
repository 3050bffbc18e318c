/* zt_render: option checks, the render scene, and the dispatch to a
 * renderer. */
#include "zonetrace/render.h"

#include <string.h>

#include "geom/accel.h"
#include "render/render_internal.h"
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

static zt_status check_options(const zt_scene *scene, const zt_render_options *o,
                               zt_error *err)
{
    if (o->method != ZT_METHOD_PATH && o->method != ZT_METHOD_ZONE)
        return zt_fail(err, ZT_ERR_ARGUMENT, "unknown method %d", (int)o->method);
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
    if (o->lights_off_count < 0 || o->lights_off_count > ZT_MAX_LIGHTS_OFF)
        return zt_fail(err, ZT_ERR_ARGUMENT, "too many lights switched off");
    for (int i = 0; i < o->lights_off_count; i++)
        if (o->lights_off[i] < 0 || o->lights_off[i] >= scene->light_count)
            return zt_fail(err, ZT_ERR_ARGUMENT,
                           "cannot switch off light %d: the scene has %d light%s (0..%d)",
                           o->lights_off[i], scene->light_count,
                           scene->light_count == 1 ? "" : "s", scene->light_count - 1);
    if (!scene->has_camera || scene->camera.width < 1 || scene->camera.height < 1)
        return zt_fail(err, ZT_ERR_ARGUMENT, "the scene has no usable camera");
    return ZT_OK;
}

zt_status zt_render(const zt_scene *scene, const zt_render_options *options,
                    zt_image **out, zt_render_stats *stats, zt_error *err)
{
    zt_render_stats local;
    if (!stats)
        stats = &local;
    memset(stats, 0, sizeof *stats);
    *out = NULL;
    zt_status st = check_options(scene, options, err);
    if (st != ZT_OK)
        return st;
    zt_image *img = zt_image_create(scene->camera.width, scene->camera.height);
    if (!img)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for a %dx%d image",
                       scene->camera.width, scene->camera.height);
    double t0 = render_clock();
    if (options->method == ZT_METHOD_PATH)
        st = render_path(scene, options, img, stats, err);
    else
        st = render_zone(scene, options, img, stats, err);
    stats->seconds = render_clock() - t0;
    if (st != ZT_OK) {
        zt_image_release(img);
        return st;
    }
    *out = img;
    return ZT_OK;
}
