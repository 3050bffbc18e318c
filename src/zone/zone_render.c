/* The zone tracer's driver: Phase One (or reading the forest from a file)
 * when the renderer is made, Phase Two for every image, and the statistics.
 * Phase Two itself is in phase_two_*.c. */
#include <stdlib.h>
#include <string.h>

#include "util/error.h"
#include "zone/forest_io.h"
#include "zone/phase_two.h"
#include "zone/zone_internal.h"

zone_quality zone_quality_for(const zt_scene *sc, int q)
{
    /* The scene's size (not the camera's: the forest must not depend on
     * it) sets the texel size; each quality step halves the texel area,
     * doubles the gather directions and refines the transfer. */
    vec3 lo, hi;
    forest_scene_bounds(sc, &lo, &hi);
    double extent = v3_length(v3_sub(hi, lo));
    double step = pow(sqrt(2.0), q);
    zone_quality z;
    z.gather = 64 << q;
    z.texel_divisor = 20.0 * step;
    z.texel = extent / z.texel_divisor;
    z.max_texels = (int)(48.0 * step); /* a side, over the core */
    z.sides = 16 << (q / 2);
    z.aa = q < 3 ? 1 : 2;
    z.glint_cuts = 2 << (q / 2);
    z.photons = 131072 << q;
    z.theta = 0.5 / step;
    /* Edge texels cut twice from quality 3: Cornell's level 3 at quality 4
     * went from 1.04% to 0.96% for 1.3x Phase One; at quality 2 it would
     * cost 1.6x, with the 2-second Cornell target in view. */
    z.edge_grade = q >= 3 ? 2 : 0;
    /* Coverage where an edge crosses a pixel: the grid's counting error
     * along a straight edge was most of level 1's (Cornell, 64x64,
     * quality 4: 0.97% with 16 x 16, 0.67% with 32, 0.56% with 64). */
    z.edge_grid = q < 3 ? 16 : q == 3 ? 32 : 64;
    z.edge_shade = q < 4 ? 4 : q == 4 ? 8 : 16;
    /* A regular grid counts a thin surface parallel to one of its
     * diagonals or axes with the same bias in every row: a 45-degree sliver
     * made triangletest's pixel (23, 33) 1.6% too dark at quality 5, and
     * more shaded samples did not help.  A quasi-random set has no such
     * direction: level 2 went from 1.59% to 1.42% with 16 x 16 shaded.  At
     * quality 4 the maps' error dominates (level 2: 5.6% on the grid, 6.0%
     * on R2; Cornell's levels within 0.04 points), so the images of
     * qualities 0-4 are kept. */
    z.cover_quasi = q >= 5;
    /* Signatures that look for edges inside smooth-looking pixels:
     * triangletest's level 1 at 64x64, quality 4, went from 6.1% to 1.8%
     * with 4 x 4 and 0.96% with 8 x 8 (thin lit slivers between shadows). */
    z.probe = q < 3 ? z.aa : q == 3 ? 4 : 8;
    /* Exact irradiance in fine cells where a map's bilinear read cannot
     * follow it (refine.c).  triangletest's level 2 at quality 4 went from
     * 5.6% to 4.0%, but for 4x its Phase One (the Cornell box's level 3:
     * 0.86% to 0.84%, 2.3x): from quality 5 only. */
    z.refine_sub = q >= 5 ? 4 : 0;
    z.refine_contrast = 0.25;
    /* Kinks too (triangletest's level 2 at quality 5: 1.42% -> 1.29%,
     * Phase One 1.5-1.6x the CPU; its pixel (33, 29) had been 2.9% too
     * bright, the floor of a valley where a receiver crosses another
     * triangle's plane smoothed over). */
    z.refine_kink = 0.04;
    /* Fine cells with coarser pieces than the texels', measured against
     * texels computed again at their size (refine.c).  At 2 theta a
     * profile over triangletest's refined texels read 0.32% (RMS) from the
     * transfer at theta, at 1.5 theta 0.21%, at theta 0.19%; triangle 12's
     * level-1 refinement took 1.25x (1.5 theta) and 2.2x (theta) the time
     * of 2 theta. */
    z.refine_theta = 1.5;
    /* Where a crossing ends (another triangle's edge passes through the
     * surface), the light has detail at every scale down to the point:
     * on triangletest, a point light's shadow of the piercing triangle is
     * a sliver between the crossing and the shadow of that edge, and the
     * light the two triangles trade across the sliver changed by a third
     * within the quarter texel beside the crossing (bench_zone_probe).
     * The texels around each end get cells twice as fine. */
    z.refine_end_sub = q >= 5 ? 8 : 0;
    return z;
}

static void fill_forest_stats(const zone_forest *f, zt_render_stats *stats)
{
    stats->zones = (uint64_t)f->zone_count;
    stats->zones_pruned = f->pruned;
    memset(stats->zones_per_level, 0, sizeof stats->zones_per_level);
    for (int i = 0; i < f->zone_count; i++)
        if (f->zones[i].level < 32)
            stats->zones_per_level[f->zones[i].level]++;
    uint64_t zb, ob, mb;
    forest_memory(f, &zb, &ob, &mb);
    stats->memory_bytes = zb + ob + mb;
    stats->forest_loaded = f->loaded;
}

zt_status zone_prepare(zt_renderer *r, zt_render_stats *stats, zt_error *err)
{
    double t0 = render_clock();
    zone_forest *f = calloc(1, sizeof *f);
    if (!f)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    r->forest = (struct zone_forest *)f;
    zone_quality q = zone_quality_for(r->scene, r->options.quality);
    zt_status st;
    if (r->options.forest_file) {
        st = forest_load(f, r, &q, r->options.forest_file, err);
    } else {
        f->q = q;
        f->direct.scene = r->scene;
        f->direct.rs = &r->rs;
        f->direct.sides = f->q.sides;
        st = forest_build_tree(f, r, err);
        if (st == ZT_OK)
            st = forest_build_maps(f, r, err);
    }
    if (st == ZT_OK && !f->dirs && !(f->dirs = forest_gather_directions(f->q.gather)))
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    f->phase_one_seconds = render_clock() - t0;
    if (!f->loaded)
        f->build_seconds = f->phase_one_seconds;
    if (stats) {
        stats->phase_one_seconds = f->phase_one_seconds;
        fill_forest_stats(f, stats);
    }
    return st;
}

void zone_release(zt_renderer *r)
{
    zone_forest *f = (zone_forest *)r->forest;
    if (!f)
        return;
    forest_free(f);
    free(f);
    r->forest = NULL;
}

static zt_status phase_two(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                           int reference, zt_error *err)
{
    zone_forest *f = (zone_forest *)r->forest;
    const zt_render_options *o = &r->options;
    double t0 = render_clock();
    p2_ctx c;
    memset(&c, 0, sizeof c);
    c.r = r;
    c.f = f;
    cam_init(&c.c, &r->scene->camera);
    c.lo = o->level >= 0 ? o->level : 0;
    c.hi = o->level >= 0 ? o->level : o->depth;
    c.g = f->q.aa;
    zt_status st = p2_terms_build(&c.terms, f, r, c.lo, c.hi, err);
    p2_marks marks = {NULL, NULL, NULL, 0, 0};
    if (st == ZT_OK && !p2_marks_build(&marks, &c))
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory for the pixel marks");
    c.marks = &marks;
    uint64_t rays = 0;
    if (st == ZT_OK) {
        if (reference)
            st = p2_render_reference(&c, sum, &rays, err);
        else if (o->strategy == ZT_STRATEGY_ZONE)
            st = p2_render_zones(&c, sum, &rays, err);
        else
            st = p2_render_pixels(&c, sum, &rays, err);
    }
    p2_terms_free(&c.terms);
    p2_marks_free(&marks);
    if (stats) {
        stats->threads = render_thread_count(o->threads);
        /* Phase One's rays are charged to the first image, unless the
         * forest was read from a file. */
        stats->rays = rays + (f->images == 0 && !f->loaded ? f->rays : 0);
        stats->samples = (uint64_t)sum->width * sum->height * (uint64_t)(c.g * c.g);
        /* Phase One is charged to the first image of the renderer only. */
        stats->phase_one_seconds = f->images == 0 ? f->phase_one_seconds : 0.0;
        stats->phase_two_seconds = render_clock() - t0;
        fill_forest_stats(f, stats);
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

zt_status zone_accumulate_reference(zt_renderer *r, zt_image *sum, zt_error *err)
{
    if (r->options.method != ZT_METHOD_ZONE || !r->forest)
        return zt_fail(err, ZT_ERR_ARGUMENT, "not a zone tracer");
    return phase_two(r, sum, NULL, 1, err);
}
