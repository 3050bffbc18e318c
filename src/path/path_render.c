/* The path tracer's driver: tiles over threads, samples per pixel, box
 * filter.  Each pixel's samples depend only on the pixel, the sample index
 * and the seed, so the image is the same at any thread count.  Running sums
 * in double continue sample by sample from the stored sum, so any split of
 * the samples into passes (interrupts, checkpoints) adds them in the same
 * order and gives the same bits. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camera.h"
#include "geom/accel.h"
#include "path/path_tracer.h"
#include "render/render_internal.h"
#include "render/share.h"
#include "util/error.h"
#include "util/sampler.h"

#define TILE 16

static int path_tile_count(int width, int height)
{
    return ((width + TILE - 1) / TILE) * ((height + TILE - 1) / TILE);
}

long long path_tiles_owned(const zt_render_options *o, int width, int height)
{
    return share_owned(o, path_tile_count(width, height));
}

void path_clear_others(const zt_render_options *o, double *sums, int width, int height)
{
    int tiles_x = (width + TILE - 1) / TILE, tiles = path_tile_count(width, height);
    for (int t = 0; t < tiles; t++) {
        if (share_owns(o, t))
            continue;
        int x0 = (t % tiles_x) * TILE, y0 = (t / tiles_x) * TILE;
        int x1 = x0 + TILE < width ? x0 + TILE : width;
        int y1 = y0 + TILE < height ? y0 + TILE : height;
        for (int y = y0; y < y1; y++)
            memset(sums + 3 * ((size_t)y * (size_t)width + (size_t)x0), 0,
                   3 * (size_t)(x1 - x0) * sizeof *sums);
    }
}

zt_status path_accumulate_into(zt_renderer *r, int first, int count, path_sums out,
                               progress *shared, zt_render_stats *stats, zt_error *err)
{
    const zt_render_options *o = &r->options;
    const rscene *rs = &r->rs;
    cam c;
    cam_init(&c, &r->scene->camera);
    path_params pp;
    pp.min_level = o->level >= 0 ? o->level : 0;
    pp.max_level = o->level >= 0 ? o->level : o->depth;
    /* Both halves of the 64-bit seed matter. */
    pp.seed = sampler_hash((uint32_t)o->seed ^ sampler_hash((uint32_t)(o->seed >> 32) + 0x9e3779b9U));

    const int width = out.width, height = out.height;
    int tiles_x = (width + TILE - 1) / TILE;
    int tiles_y = (height + TILE - 1) / TILE;
    int tiles = tiles_x * tiles_y;
    int threads = render_thread_count(o->threads);
    progress own, *prog = shared;
    if (!prog) {
        progress_init(&own, o, "path", (double)tiles);
        prog = &own;
    }
    /* A shared progress counts tiles times samples. */
    const double tile_work = shared ? (double)count : 1.0;
    uint64_t rays = 0, samples = 0;
    const uint32_t s0 = (uint32_t)first, s1 = (uint32_t)first + (uint32_t)count;

#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : rays, samples)
    for (int t = 0; t < tiles; t++) {
        /* Split over processes, each takes its tiles. */
        if (prog->cancelled || !share_owns(o, t))
            continue;
        int x0 = (t % tiles_x) * TILE, y0 = (t / tiles_x) * TILE;
        int x1 = x0 + TILE < width ? x0 + TILE : width;
        int y1 = y0 + TILE < height ? y0 + TILE : height;
        uint64_t local_rays = 0;
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                path_pixel pix = path_pixel_make(sampler_hash3((uint32_t)x, (uint32_t)y, pp.seed));
                size_t at = 3 * ((size_t)y * (size_t)width + (size_t)x);
                double acc[3] = {0, 0, 0};
                if (out.dsum)
                    for (int k = 0; k < 3; k++)
                        acc[k] = out.dsum[at + k];
                for (uint32_t s = s0; s < s1; s++) {
                    float u[2];
                    uint32_t rev_s = sampler_reverse_bits(s);
                    sampler_get2_seeded(pix.pair_seed[0], rev_s, u);
                    vec3f org, dir;
                    cam_ray(&c, (float)x + u[0], (float)y + u[1], &org, &dir);
                    vec3f l = path_trace_sample(rs, &pp, org, dir, &pix, s, rev_s, &local_rays);
                    acc[0] += l.x;
                    acc[1] += l.y;
                    acc[2] += l.z;
                }
                for (int k = 0; k < 3; k++) {
                    if (out.dsum)
                        out.dsum[at + k] = acc[k];
                    else
                        out.fsum[at + k] += (float)acc[k];
                }
            }
        rays += local_rays;
        samples += (uint64_t)(x1 - x0) * (uint64_t)(y1 - y0) * (uint64_t)count;
        progress_add(prog, tile_work);
    }
    stats->threads = threads;
    stats->rays = rays;
    stats->samples = samples;
    if (prog->cancelled)
        return zt_fail(err, ZT_ERR_CANCELLED, "render cancelled");
    return ZT_OK;
}

zt_status path_accumulate(zt_renderer *r, int first, int count, zt_image *sum,
                          zt_render_stats *stats, zt_error *err)
{
    if (share_ranks(&r->options) > 1)
        return zt_fail(err, ZT_ERR_ARGUMENT, "the path tracer's accumulation runs in one "
                       "process; zt_render splits a render over processes");
    path_sums out = {NULL, sum->pixels, sum->width, sum->height};
    return path_accumulate_into(r, first, count, out, NULL, stats, err);
}
