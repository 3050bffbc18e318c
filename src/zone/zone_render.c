/* The zone tracer's driver: Phase One (or reading the forest from a file)
 * when the renderer is made, Phase Two for every image, and the statistics.
 * The stages themselves are in phase_one/ and phase_two/. */
#include <stdlib.h>
#include <string.h>

#include "render/memory.h"
#include "render/share.h"
#include "util/error.h"
#include "zone/io/forest_io.h"
#include "zone/phase_two/phase_two.h"
#include "zone/zone.h"

static void fill_forest_stats(const zone_forest *f, const zt_renderer *r, zt_render_stats *stats)
{
    stats->zones = (uint64_t)f->zone_count;
    stats->zones_pruned = f->pruned;
    memset(stats->zones_per_level, 0, sizeof stats->zones_per_level);
    for (int i = 0; i < f->zone_count; i++)
        if (f->zones[i].level < 32)
            stats->zones_per_level[f->zones[i].level]++;
    stats->memory_bytes = forest_memory(f);
    stats->forest_loaded = f->loaded;
    stats->cuts = f->cuts;
    stats->cuts_capped = f->cuts_capped;
    stats->cuts_shared = f->cuts_shared;
    stats->sky_portals = f->portals.count;
    stats->nodes_gathered = f->gathers;
    /* Here, not only at creation: a renderer made without stats (saving
     * its forest first) reports it with its first image. */
    stats->memory_estimate = r->memory_estimate +
                             memory_zone_nodes(f->sn.node_count, f->map_levels) +
                             f->photon_estimate;
}

zt_status zone_prepare(zt_renderer *r, zt_render_stats *stats, zt_error *err)
{
    double t0 = render_clock();
    zone_forest *f = calloc(1, sizeof *f);
    if (!f)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    r->forest = (struct zone_forest *)f;
    zone_quality q = zone_quality_for(r->scene, &r->rs, r->options.quality);
    zt_status st;
    if (r->options.forest_file) {
        st = forest_load(f, r, &q, r->options.forest_file, err);
    } else {
        f->q = q;
        st = zone_phase_one(f, r, err);
    }
    f->phase_one_seconds = render_clock() - t0;
    if (!f->loaded)
        f->build_seconds = f->phase_one_seconds;
    if (stats) {
        stats->phase_one_seconds = f->phase_one_seconds;
        fill_forest_stats(f, r, stats);
    }
    return st;
}

int zone_stop_reason(const zt_renderer *r)
{
    const zone_forest *f = (const zone_forest *)r->forest;
    return f ? f->stopped : ZT_STOP_NONE;
}

void zone_release(zt_renderer *r)
{
    zone_forest *f = (zone_forest *)r->forest;
    if (!f)
        return;
    zone_forest_free(f);
    free(f);
    r->forest = NULL;
}

/* Phase Two's context for the renderer's camera and levels (no terms or
 * marks yet). */
static void p2_ctx_begin(p2_ctx *c, zt_renderer *r)
{
    const zt_render_options *o = &r->options;
    memset(c, 0, sizeof *c);
    c->r = r;
    c->f = (zone_forest *)r->forest;
    cam_init(&c->c, &r->scene->camera);
    vec3f mid = f3_add(c->c.to_screen, f3_scale(f3_add(c->c.right, c->c.down), 0.5f));
    c->screen_dist = f3_length(mid);
    c->pixel_angle = f3_length(c->c.right) / (float)c->c.width / c->screen_dist;
    c->lo = o->level >= 0 ? o->level : 0;
    c->hi = o->level >= 0 ? o->level : o->depth;
    c->g = c->f->q.aa;
}

static zt_status phase_two(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                           int reference, zt_error *err)
{
    zone_forest *f = (zone_forest *)r->forest;
    const zt_render_options *o = &r->options;
    double t0 = render_clock();
    p2_ctx c;
    p2_ctx_begin(&c, r);
    p2_split split;
    memset(&split, 0, sizeof split);
    c.split = &split;
    zt_status st = p2_terms_build(&c.terms, f, r, c.lo, c.hi, err);
    p2_marks marks = {NULL, NULL, NULL, 0, 0};
    if (st == ZT_OK && !p2_marks_build(&marks, &c))
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory for the pixel marks");
    c.marks = &marks;
    uint64_t rays = 0;
    struct zone_gather_cache cache;
    memset(&cache, 0, sizeof cache);
    if (st == ZT_OK)
        st = p2_gather_cache_build(&cache, &c, &rays, err);
    c.cache = &cache;
    /* Split over processes, each renders its rows into an image of its
     * own, the merge joins them, and the whole is added to sum: the same
     * additions, in the same order, as one process makes. */
    int shared = !reference && share_ranks(o) > 1;
    zt_image *own = shared ? zt_image_create(sum->width, sum->height) : sum;
    if (st == ZT_OK && !own)
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory for a %dx%d image", sum->width,
                     sum->height);
    if (st == ZT_OK) {
        if (reference)
            st = p2_render_reference(&c, own, &rays, err);
        else if (o->strategy == ZT_STRATEGY_ZONE)
            st = p2_render_zones(&c, own, &rays, err);
        else
            st = p2_render_pixels(&c, own, &rays, err);
    }
    if (shared && own) {
        size_t n = 3 * (size_t)sum->width * (size_t)sum->height;
        if (st == ZT_OK)
            st = share_merge(o, own->pixels, n * sizeof *own->pixels, err);
        for (size_t i = 0; st == ZT_OK && i < n; i++)
            sum->pixels[i] += own->pixels[i];
        zt_image_release(own);
    }
    p2_terms_free(&c.terms);
    p2_marks_free(&marks);
    p2_gather_cache_free(&cache);
    if (stats) {
        stats->threads = render_thread_count(o->threads);
        /* Phase One's rays are charged to the first image, unless the
         * forest was read from a file. */
        stats->rays = rays + (f->images == 0 && !f->loaded ? f->rays : 0);
        double all = (double)stats->rays;
        if (shared && st == ZT_OK && (st = share_sum(o, &all, 1, err)) == ZT_OK)
            stats->rays = (uint64_t)all; /* every process's */
        stats->samples = (uint64_t)sum->width * sum->height * (uint64_t)(c.g * c.g);
        /* Phase One is charged to the first image of the renderer only. */
        stats->phase_one_seconds = f->images == 0 ? f->phase_one_seconds : 0.0;
        stats->phase_two_seconds = render_clock() - t0;
        stats->p2_lists_seconds = split.lists;
        stats->p2_records_seconds = split.records;
        for (int k = 0; k < ZT_PIXEL_KINDS; k++) {
            stats->p2_shade_seconds[k] = split.shade[k];
            stats->p2_pixels[k] = split.pixels[k];
            stats->p2_samples[k] = split.samples[k];
        }
        fill_forest_stats(f, r, stats);
    }
    if (st == ZT_OK && !reference)
        f->images++;
    return st;
}

zt_status zone_accumulate(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                          zt_error *err)
{
    return phase_two(r, sum, stats, 0, err);
}

zt_status zone_preview(zt_renderer *r, zt_image *sum, zt_render_stats *stats, zt_error *err)
{
    zone_forest *f = (zone_forest *)r->forest;
    if (f->top_gathered)
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "this forest was built for one image (zt_render): no preview");
    const zt_render_options *o = &r->options;
    double t0 = render_clock();
    p2_ctx c;
    p2_ctx_begin(&c, r);
    uint64_t rays = 0;
    zt_status st = p2_render_preview(&c, sum, &rays, err);
    if (stats) {
        stats->threads = render_thread_count(o->threads);
        stats->rays = rays;
        stats->samples = (uint64_t)sum->width * sum->height;
        stats->phase_one_seconds = 0.0;
        stats->phase_two_seconds = render_clock() - t0;
        fill_forest_stats(f, r, stats);
    }
    return st;
}

zt_status zone_accumulate_reference(zt_renderer *r, zt_image *sum, zt_error *err)
{
    if (r->options.method != ZT_METHOD_ZONE || !r->forest)
        return zt_fail(err, ZT_ERR_ARGUMENT, "not a zone tracer");
    return phase_two(r, sum, NULL, 1, err);
}
