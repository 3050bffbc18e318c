/* zt_render for the path tracer: samples in passes over the whole image, so
 * that a render can end early (a time limit, an interrupt) with the image of
 * the samples done, and can checkpoint its running sums and resume from
 * them.  The sums continue sample by sample (path_render.c), so however the
 * samples fall into passes, runs and resumptions, the bits are the same. */
#include <math.h>
#include <stdlib.h>

#include "render/checkpoint.h"
#include "render/render_internal.h"
#include "render/share.h"
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
    if (share_rank(&r->options) != 0)
        return ZT_OK; /* rank 0 alone keeps the checkpoint */
    return checkpoint_write(r->options.checkpoint_file, key, c->width, c->height, done, sums,
                            err);
}

/* Split over processes, each holds its own tiles: the others' pixels are
 * cleared (they hold an earlier merge's or a checkpoint's sums) and the
 * merge gives every process the whole image. */
static zt_status gather_sums(const zt_renderer *r, double *sums, zt_error *err)
{
    const zt_render_options *o = &r->options;
    if (share_ranks(o) == 1)
        return ZT_OK;
    const int w = r->scene->camera.width, h = r->scene->camera.height;
    path_clear_others(o, sums, w, h);
    return share_merge(o, sums, 3 * (size_t)w * (size_t)h * sizeof *sums, err);
}

/* Rank 0 reads the checkpoint; the others learn whether it could and take
 * its sums and count. */
static zt_status resume(const zt_renderer *r, uint64_t key, double *sums, int *done,
                        zt_error *err)
{
    const zt_render_options *o = &r->options;
    const zt_camera *c = &r->scene->camera;
    zt_status st = ZT_OK;
    if (share_rank(o) == 0)
        st = checkpoint_read(o->checkpoint_file, key, c->width, c->height, o->spp, sums, done,
                             err);
    if (share_ranks(o) == 1)
        return st;
    /* Rank 0's status and count; the others' are 0. */
    double told[2] = {st, *done};
    zt_status exchanged = share_max(o, told, 2, err);
    if (exchanged != ZT_OK)
        return exchanged;
    if (told[0] != ZT_OK)
        return st != ZT_OK ? st
                           : zt_fail(err, (zt_status)told[0], "the checkpoint '%s' could not "
                                     "be resumed (process 0 says why)", o->checkpoint_file);
    *done = (int)told[1];
    return share_merge(o, sums, 3 * (size_t)c->width * (size_t)c->height * sizeof *sums, err);
}

/* What the processes do next, agreed: stop if any was asked to, a pass
 * that fits on all of them, a checkpoint if any is due one. */
typedef struct pass_plan {
    int stop, count, save;
} pass_plan;

static zt_status agree(const zt_render_options *o, pass_plan *p, zt_error *err)
{
    /* The fewest samples is the most of their negatives. */
    double x[3] = {p->stop, -p->count, p->save};
    zt_status st = share_max(o, x, 3, err);
    p->stop = x[0] != 0;
    p->count = (int)-x[1];
    p->save = x[2] != 0;
    return st;
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
        st = resume(r, key, sums, &done, err);
    stats->spp_resumed = done;

    progress prog;
    progress_init(&prog, o, "path", (double)path_tiles_owned(o, w, h) * (o->spp - done));
    double deadline = o->time_limit > 0 ? t0 + o->time_limit : INFINITY;
    double every = o->checkpoint_seconds > 0 ? o->checkpoint_seconds : CHECKPOINT_SECONDS;
    double last_save = render_clock(), per_sample = 0;
    while (st == ZT_OK && done < o->spp) {
        double now = render_clock();
        pass_plan plan = {o->stop && *o->stop, next_pass(o, done, per_sample, now, deadline),
                          o->checkpoint_file && done > 0 && now - last_save >= every};
        st = agree(o, &plan, err);
        if (st == ZT_OK && plan.save) {
            st = gather_sums(r, sums, err);
            if (st == ZT_OK)
                st = save(r, key, done, sums, err);
            last_save = render_clock();
        }
        if (st != ZT_OK)
            break;
        if (plan.stop) {
            stats->stopped = ZT_STOP_INTERRUPT;
            break;
        }
        if (plan.count == 0) {
            stats->stopped = ZT_STOP_TIME;
            break;
        }
        now = render_clock();
        zt_render_stats ps = {0};
        st = path_accumulate_into(r, done, plan.count, (path_sums){sums, NULL, w, h}, &prog, &ps,
                                  err);
        if (st != ZT_OK)
            break;
        done += plan.count;
        per_sample = fmax((render_clock() - now) / plan.count, 1e-9); /* > 0: measured */
        stats->rays += ps.rays;
        stats->samples += ps.samples;
        stats->threads = ps.threads;
    }
    if (st == ZT_OK && done == 0)
        st = zt_fail(err, ZT_ERR_CANCELLED, "stopped before the first sample");
    if (st == ZT_OK)
        st = gather_sums(r, sums, err);
    double counts[2] = {(double)stats->rays, (double)stats->samples};
    if (st == ZT_OK && (st = share_sum(o, counts, 2, err)) == ZT_OK) {
        stats->rays = (uint64_t)counts[0];
        stats->samples = (uint64_t)counts[1];
    }
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
