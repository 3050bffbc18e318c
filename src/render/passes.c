/* zt_render for the path tracer: samples in passes over the whole image, so
 * that a render can end early (a time limit, an interrupt) with the image of
 * the samples done, and can checkpoint its running sums and resume from
 * them.  The sums continue sample by sample (path_render.c), so however the
 * samples fall into passes, runs and resumptions, the bits are the same. */
#include <math.h>
#include <stdlib.h>

#include "render/checkpoint.h"
#include "render/render_internal.h"
#include "util/error.h"

/* A pass takes about this long once the time per sample is known: short
 * enough for an interrupt or the time limit to be met promptly, long
 * enough that starting the threads costs nothing; and a render has at least
 * PASSES_MIN of them, so even a short one stops soon after an interrupt. */
#define PASS_SECONDS 0.5
#define PASSES_MIN 8
/* Passes are sized for a sample time this much slower than measured. */
#define PASS_SAFETY 1.15
#define CHECKPOINT_SECONDS 300.0

/* Samples for the next pass: none when the time limit leaves no room. */
static int next_pass(const zt_render_options *o, int done, double per_sample, double now,
                     double deadline)
{
    int left = o->spp - done;
    if (per_sample <= 0)
        return 1; /* the first pass of this run measures */
    double fit = (deadline - now) / (per_sample * PASS_SAFETY);
    if (fit < 1)
        return 0;
    double n = fmin(fmin(PASS_SECONDS / per_sample, fit), ceil((double)o->spp / PASSES_MIN));
    return n < 1 ? 1 : n > left ? left : (int)n;
}

static zt_status save(const zt_renderer *r, uint64_t key, int done, const double *sums,
                      zt_error *err)
{
    const zt_camera *c = &r->scene->camera;
    return checkpoint_write(r->options.checkpoint_file, key, c->width, c->height, done, sums,
                            err);
}

zt_status path_render_passes(zt_renderer *r, double t0, zt_image **out,
                             zt_render_stats *stats, zt_error *err)
{
    const zt_render_options *o = &r->options;
    const int w = r->scene->camera.width, h = r->scene->camera.height;
    size_t n = 3 * (size_t)w * (size_t)h;
    double *sums = calloc(n, sizeof *sums);
    zt_image *img = zt_image_create(w, h);
    if (!sums || !img) {
        free(sums);
        zt_image_release(img);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for a %dx%d image", w, h);
    }
    int done = 0;
    uint64_t key = o->checkpoint_file ? checkpoint_key(r->scene, o) : 0;
    zt_status st = ZT_OK;
    if (o->resume)
        st = checkpoint_read(o->checkpoint_file, key, w, h, o->spp, sums, &done, err);
    stats->spp_resumed = done;

    progress prog;
    progress_init(&prog, o, "path", (double)path_tile_count(w, h) * (o->spp - done));
    double deadline = o->time_limit > 0 ? t0 + o->time_limit : INFINITY;
    double every = o->checkpoint_seconds > 0 ? o->checkpoint_seconds : CHECKPOINT_SECONDS;
    double last_save = render_clock(), per_sample = 0;
    while (st == ZT_OK && done < o->spp) {
        if (o->stop && *o->stop) {
            stats->stopped = ZT_STOP_INTERRUPT;
            break;
        }
        double now = render_clock();
        int count = next_pass(o, done, per_sample, now, deadline);
        if (count == 0) {
            stats->stopped = ZT_STOP_TIME;
            break;
        }
        zt_render_stats ps = {0};
        st = path_accumulate_into(r, done, count, (path_sums){sums, NULL, w, h}, &prog, &ps, err);
        if (st != ZT_OK)
            break;
        double after = render_clock();
        done += count;
        per_sample = fmax((after - now) / count, 1e-9); /* > 0: measured */
        stats->rays += ps.rays;
        stats->samples += ps.samples;
        stats->threads = ps.threads;
        if (o->checkpoint_file && done < o->spp && after - last_save >= every) {
            st = save(r, key, done, sums, err);
            last_save = render_clock();
        }
    }
    if (st == ZT_OK && done == 0)
        st = zt_fail(err, ZT_ERR_CANCELLED, "stopped before the first sample");
    if (st == ZT_OK && o->checkpoint_file)
        st = save(r, key, done, sums, err);
    if (st == ZT_OK)
        for (size_t i = 0; i < n; i++)
            img->pixels[i] = (float)(sums[i] / done);
    free(sums);
    if (st != ZT_OK) {
        zt_image_release(img);
        return st;
    }
    stats->spp_done = done;
    *out = img;
    return ZT_OK;
}
