/* The zone tracer's entry point (the renderer itself is work in progress). */
#include "render/render_internal.h"
#include "util/error.h"

zt_status render_zone(const zt_scene *scene, const zt_render_options *o,
                      zt_image *img, zt_render_stats *stats, zt_error *err)
{
    (void)scene; (void)o; (void)img; (void)stats;
    return zt_fail(err, ZT_ERR_UNSUPPORTED,
                   "the zone tracer (--method zone) is not available in this version yet");
}
