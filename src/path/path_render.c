/* The path tracer's driver: tiles over threads, samples per pixel, box
 * filter.  Each pixel's samples depend only on the pixel, the sample index
 * and the seed, so the image is the same at any thread count. */
#include <omp.h>
#include <stdlib.h>

#include "camera/camera.h"
#include "geom/accel.h"
#include "path/path_tracer.h"
#include "render/render_internal.h"
#include "util/error.h"
#include "util/sampler.h"

#define TILE 16

zt_status path_accumulate(zt_renderer *r, int first, int count, zt_image *sum,
                          zt_render_stats *stats, zt_error *err)
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

    int tiles_x = (sum->width + TILE - 1) / TILE;
    int tiles_y = (sum->height + TILE - 1) / TILE;
    int tiles = tiles_x * tiles_y;
    int threads = render_thread_count(o->threads);
    progress prog;
    progress_init(&prog, o, "path", (double)tiles);
    uint64_t rays = 0;
    const uint32_t s0 = (uint32_t)first, s1 = (uint32_t)first + (uint32_t)count;

#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : rays)
    for (int t = 0; t < tiles; t++) {
        if (prog.cancelled)
            continue;
        int x0 = (t % tiles_x) * TILE, y0 = (t / tiles_x) * TILE;
        int x1 = x0 + TILE < sum->width ? x0 + TILE : sum->width;
        int y1 = y0 + TILE < sum->height ? y0 + TILE : sum->height;
        uint64_t local_rays = 0;
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                path_pixel pix = path_pixel_make(sampler_hash3((uint32_t)x, (uint32_t)y, pp.seed));
                double acc[3] = {0, 0, 0};
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
                float *px = zt_image_pixel(sum, x, y);
                for (int k = 0; k < 3; k++)
                    px[k] += (float)acc[k];
            }
        rays += local_rays;
        progress_add(&prog, 1.0);
    }
    stats->threads = threads;
    stats->rays = rays;
    stats->samples = (uint64_t)sum->width * (uint64_t)sum->height * (uint64_t)count;
    if (prog.cancelled)
        return zt_fail(err, ZT_ERR_CANCELLED, "render cancelled");
    return ZT_OK;
}
