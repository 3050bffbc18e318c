/* The zone tracer's entry points (the renderer itself is work in progress). */
#include "render/render_internal.h"
#include "util/error.h"

zt_status zone_prepare(zt_renderer *r, zt_render_stats *stats, zt_error *err)
{
    (void)r; (void)stats;
    return zt_fail(err, ZT_ERR_UNSUPPORTED,
                   "the zone tracer (--method zone) is not available in this version yet");
}

zt_status zone_accumulate(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                          zt_error *err)
{
    (void)r; (void)sum; (void)stats;
    return zt_fail(err, ZT_ERR_UNSUPPORTED, "the zone tracer is not available yet");
}

void zone_release(zt_renderer *r)
{
    (void)r;
}
