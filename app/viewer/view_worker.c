/* The viewer's render worker: keeps a persistent renderer, accumulates
 * samples in batches of one per pixel, and publishes the average about once
 * per frame period.  It restarts when the camera, the options or (with
 * motions) the time change; a camera change only replaces the renderer's
 * camera, anything else recreates the renderer. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <SDL.h>

#include "viewer.h"

/* Samples per pixel after which a still image is taken as converged. */
#define MAX_SPP (1 << 20)

double view_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double view_motion_time(const view_request *r, double now)
{
    if (r->motions_paused)
        return r->motion_time_paused;
    double t = now - r->motion_origin;
    return t > 0 ? t : 0;
}

typedef struct wstate {
    view_worker *w;
    zt_scene *scene;       /* scene0 moved to motion_time, with the camera */
    zt_renderer *r;
    zt_image *sum;
    int spp;
    int done;              /* nothing more to do until something changes */
    int first_batch;       /* the first batch after a restart is not cancelled */
    uint64_t cam_epoch, opt_epoch;
    int have_state;
    view_request req;      /* what the renderer was made for */
    int method;            /* the method actually rendering */
    int zone_failed;       /* zone fell back to path for this opt epoch */
    double motion_time;
    double restart_time;
    double last_publish;
    uint64_t rays;
    double auto_ev;
    int have_ev;
    double ev_time;
    int ev_stale;
    int ev_spp;            /* samples per pixel when it was computed */
    int zone_preview;      /* zone: next frame a preview (moving) */
    int preview_div;       /* its resolution's divisor: 1, 2 or 4 */
    int preview_shown;     /* the picture shown is a preview at 1/this
                              resolution; 0: a full image */
    zt_image *small;       /* a preview at a lower resolution */
} wstate;

/* Zone mode while the camera moves: the zone tracer's preview (one sample
 * a pixel from the forest's nodes, zt_renderer_preview), at the full
 * resolution while it fits in a frame period, else at 1/2 or 1/4 of it and
 * shown enlarged; the full image follows once the camera rests.  Returns
 * the status of the render. */
static zt_status zone_preview_frame(wstate *s, zt_render_stats *stats, zt_error *err)
{
    int w = s->sum->width, h = s->sum->height, div = s->preview_div > 1 ? s->preview_div : 1;
    int sw = w / div > 1 ? w / div : 1, sh = h / div > 1 ? h / div : 1;
    double t0 = view_now();
    zt_status st;
    if (div == 1) {
        memset(s->sum->pixels, 0, (size_t)w * h * 3 * sizeof(float));
        st = zt_renderer_preview(s->r, s->sum, stats, err);
    } else {
        if (!s->small || s->small->width != sw || s->small->height != sh) {
            zt_image_release(s->small);
            s->small = zt_image_create(sw, sh);
            if (!s->small)
                return ZT_ERR_MEMORY;
        }
        zt_camera cam = s->req.camera;
        st = zt_camera_set_resolution(&cam, sw, sh, err);
        if (st == ZT_OK)
            st = zt_renderer_set_camera(s->r, &cam, err);
        if (st != ZT_OK)
            return st;
        memset(s->small->pixels, 0, (size_t)sw * sh * 3 * sizeof(float));
        st = zt_renderer_preview(s->r, s->small, stats, err);
        zt_error ignored;
        zt_renderer_set_camera(s->r, &s->req.camera, &ignored);
        if (st == ZT_OK)
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    const float *src = zt_image_pixel(s->small, x * sw / w, y * sh / h);
                    float *dst = zt_image_pixel(s->sum, x, y);
                    dst[0] = src[0];
                    dst[1] = src[1];
                    dst[2] = src[2];
                }
    }
    if (st != ZT_OK)
        return st;
    /* The next preview's scale: a quarter of the pixels when this one
     * took more than a frame period, four times as many when that would
     * still take less than half of one. */
    double dt = view_now() - t0, frame = s->w->cfg.frame_seconds;
    if (dt > frame && div < 4)
        s->preview_div = div * 2;
    else if (div > 1 && 4.0 * dt < 0.5 * frame)
        s->preview_div = div / 2;
    s->preview_shown = div;
    return ZT_OK;
}

static int ilog2(int x)
{
    int n = -1;
    while (x > 0) {
        x >>= 1;
        n++;
    }
    return n;
}

static int has_motions(const wstate *s)
{
    return s->w->cfg.motions && zt_motions_moves_objects(s->w->cfg.motions);
}

/* Whether the scene must move to a new motion time. */
static int motion_due(const wstate *s, const view_request *req, double now)
{
    if (!has_motions(s))
        return 0;
    double t = view_motion_time(req, now);
    if (req->motions_paused)
        return t != s->motion_time;
    return fabs(t - s->motion_time) >= s->w->cfg.frame_seconds;
}

/* The progress callback: cancels a render that has become stale. */
static int cancel_check(void *user, const char *stage, double done, double total)
{
    (void)stage; (void)done; (void)total;
    wstate *s = user;
    view_shared *sh = s->w->shared;
    if (atomic_load(&sh->quit))
        return 1;
    if (atomic_load(&sh->opt_epoch) != s->opt_epoch)
        return 1;
    if (s->first_batch)
        return 0;
    if (atomic_load(&sh->cam_epoch) != s->cam_epoch)
        return 1;
    if (has_motions(s)) {
        pthread_mutex_lock(&sh->lock);
        int due = motion_due(s, &sh->req, view_now());
        pthread_mutex_unlock(&sh->lock);
        return due;
    }
    return 0;
}

static void post_message(wstate *s, const char *msg, int forced_method)
{
    view_shared *sh = s->w->shared;
    pthread_mutex_lock(&sh->lock);
    snprintf(sh->message, sizeof sh->message, "%s", msg);
    sh->message_seq++;
    if (forced_method >= 0) {
        sh->req.method = forced_method;
        sh->method_forced = forced_method;
        sh->method_forced_seq++;
    }
    pthread_mutex_unlock(&sh->lock);
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = sh->publish_event;
    SDL_PushEvent(&ev);
}

static zt_render_options make_options(wstate *s, const view_request *req, int method)
{
    zt_render_options o = zt_render_options_default();
    o.method = method;
    o.spp = 1;
    o.depth = req->depth;
    o.level = req->level;
    if (o.level > o.depth)
        o.depth = o.level;
    o.seed = s->w->cfg.seed;
    o.threads = s->w->cfg.threads;
    memcpy(o.lights_off, req->lights_off, sizeof o.lights_off);
    o.lights_off_count = req->lights_off_count;
    o.progress = cancel_check;
    o.progress_user = s;
    o.stop = &s->w->shared->stop_build;
    return o;
}

/* Recreates the renderer for req at the current motion time.  Returns
 * ZT_OK, ZT_ERR_CANCELLED, or another failure (posted as a message). */
static zt_status rebuild(wstate *s, const view_request *req, double now)
{
    zt_error err;
    zt_error_clear(&err);
    zt_renderer_release(s->r);
    s->r = NULL;
    if (has_motions(s)) {
        double t = view_motion_time(req, now);
        zt_status st = zt_motions_apply(s->w->cfg.motions, s->w->cfg.scene0, t,
                                        s->w->cfg.seed, s->scene, &err);
        if (st != ZT_OK) {
            post_message(s, err.message, -1);
            return st;
        }
        s->motion_time = t;
    }
    zt_scene_set_camera(s->scene, &req->camera);
    int method = req->method;
    if (method == ZT_METHOD_ZONE && s->zone_failed)
        method = ZT_METHOD_PATH;
    s->first_batch = 1; /* creation itself is never cancelled for the camera */
    zt_render_options o = make_options(s, req, method);
    zt_status st;
    if (method == ZT_METHOD_ZONE && getenv("ZT_VIEW_FAIL_ZONE")) {
        /* a test hook: behave as a build without the zone tracer */
        st = err.status = ZT_ERR_UNSUPPORTED;
        snprintf(err.message, sizeof err.message, "not available (ZT_VIEW_FAIL_ZONE is set)");
    } else {
        st = zt_renderer_create(s->scene, &o, &s->r, &err);
    }
    if (st == ZT_ERR_CANCELLED)
        return st;
    if (st != ZT_OK && method == ZT_METHOD_ZONE) {
        char msg[VIEW_MESSAGE_MAX];
        snprintf(msg, sizeof msg, "zone tracer: %s; showing the path tracer", err.message);
        post_message(s, msg, ZT_METHOD_PATH);
        s->zone_failed = 1;
        s->req.method = ZT_METHOD_PATH; /* as the request now says */
        method = ZT_METHOD_PATH;
        o = make_options(s, req, method);
        zt_error_clear(&err);
        st = zt_renderer_create(s->scene, &o, &s->r, &err);
    }
    if (st != ZT_OK) {
        if (st != ZT_ERR_CANCELLED)
            post_message(s, err.message, -1);
        return st;
    }
    s->method = method;
    return ZT_OK;
}

static void publish(wstate *s, double batch_seconds)
{
    view_shared *sh = s->w->shared;
    int w = s->sum->width, h = s->sum->height;
    size_t n = (size_t)w * (size_t)h * 3;
    double now = view_now();
    int spp = s->method == ZT_METHOD_PATH ? s->spp : 1;
    float inv = 1.0f / (float)spp;

    /* Automatic exposure: from the averaged image, when there is none yet,
     * at 4, 8, 16... samples (so it settles as the noise goes), after an
     * option change, and at least once a second while things move. */
    int pow2 = s->spp >= 4 && ilog2(s->spp) > ilog2(s->ev_spp);
    int recompute = !s->have_ev || s->ev_stale || pow2 ||
                    (s->spp == 1 && now - s->ev_time > 1.0) ||
                    s->method != ZT_METHOD_PATH;

    pthread_mutex_lock(&sh->lock);
    view_frame *f = &sh->front;
    for (size_t i = 0; i < n; i++)
        f->linear[i] = s->sum->pixels[i] * inv;
    pthread_mutex_unlock(&sh->lock);

    if (recompute) {
        /* Only this thread writes f->linear, so reading it unlocked is safe. */
        zt_image view = {w, h, f->linear};
        s->auto_ev = zt_image_auto_exposure(&view);
        s->ev_spp = s->spp;
        s->have_ev = 1;
        s->ev_time = now;
        s->ev_stale = 0;
    }

    pthread_mutex_lock(&sh->lock);
    f->seq++;
    f->cam_epoch = s->cam_epoch;
    f->opt_epoch = s->opt_epoch;
    f->spp = s->spp;
    f->rays = s->rays;
    f->restart_time = s->restart_time;
    f->motion_time = s->motion_time;
    f->method = s->method;
    f->auto_exposure = s->auto_ev;
    f->batch_seconds = batch_seconds;
    f->preview = s->method == ZT_METHOD_ZONE ? s->preview_shown : 0;
    pthread_mutex_unlock(&sh->lock);
    s->last_publish = now;

    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = sh->publish_event;
    SDL_PushEvent(&ev);
}

static void *worker_main(void *arg)
{
    view_worker *w = arg;
    view_shared *sh = w->shared;
    wstate s;
    memset(&s, 0, sizeof s);
    s.w = w;
    s.scene = zt_scene_clone(w->cfg.scene0);
    zt_camera cam0 = zt_scene_get_camera(w->cfg.scene0);
    s.sum = zt_image_create(cam0.width, cam0.height);
    if (!s.scene || !s.sum) {
        post_message(&s, "out of memory", -1);
        atomic_store(&sh->quit, 1);
    }
    double frame = w->cfg.frame_seconds;

    pthread_mutex_lock(&sh->lock);
    while (!atomic_load(&sh->quit)) {
        view_request req = sh->req;
        uint64_t cam_epoch = atomic_load(&sh->cam_epoch);
        uint64_t opt_epoch = atomic_load(&sh->opt_epoch);
        double now = view_now();
        int opt_changed = !s.have_state || opt_epoch != s.opt_epoch;
        int cam_changed = cam_epoch != s.cam_epoch;
        int moved = s.have_state && motion_due(&s, &req, now);
        if (!opt_changed && !cam_changed && !moved && s.done) {
            /* idle: wait for a change (or the next motion step) */
            double wait = has_motions(&s) && !req.motions_paused ? frame / 4 : 0.25;
            struct timespec ts;
            clock_gettime(CLOCK_REALTIME, &ts);
            double t = (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec + wait;
            ts.tv_sec = (time_t)t;
            ts.tv_nsec = (long)((t - (double)ts.tv_sec) * 1e9);
            pthread_cond_timedwait(&sh->wake, &sh->lock, &ts);
            continue;
        }
        pthread_mutex_unlock(&sh->lock);

        if (opt_changed && s.have_state && req.method != s.req.method)
            s.zone_failed = 0; /* asking for zone again tries again */
        zt_status st = ZT_OK;
        if (opt_changed || moved || !s.r) {
            if (opt_changed)
                s.ev_stale = 1;
            s.opt_epoch = opt_epoch;
            s.cam_epoch = cam_epoch;
            s.have_state = 1;
            s.req = req;
            st = rebuild(&s, &req, now);
        } else if (cam_changed) {
            zt_error err;
            s.cam_epoch = cam_epoch;
            s.req.camera = req.camera;
            s.req.camera_time = req.camera_time;
            st = zt_renderer_set_camera(s.r, &req.camera, &err);
            s.zone_preview = s.method == ZT_METHOD_ZONE;
        }
        /* A camera path's picture is of its camera's time when no object
         * moves (else of the objects' time, within a frame of it). */
        if (!has_motions(&s) && s.req.camera_time >= 0)
            s.motion_time = s.req.camera_time;
        if (opt_changed || moved || cam_changed || st != ZT_OK) {
            s.spp = 0;
            s.ev_spp = 0;
            s.rays = 0;
            s.done = st != ZT_OK && st != ZT_ERR_CANCELLED;
            s.first_batch = 1;
            s.restart_time = now;
            memset(s.sum->pixels, 0, (size_t)s.sum->width * (size_t)s.sum->height * 3 * sizeof(float));
        }
        if (st != ZT_OK || !s.r) {
            pthread_mutex_lock(&sh->lock);
            continue;
        }

        /* one batch */
        zt_error err;
        zt_error_clear(&err);
        zt_render_stats stats;
        memset(&stats, 0, sizeof stats);
        double t0 = view_now();
        if (s.method == ZT_METHOD_ZONE && s.zone_preview) {
            s.zone_preview = 0;
            st = zone_preview_frame(&s, &stats, &err);
            if (st == ZT_OK) {
                /* Shown as 0 samples: screenshots wait for the full frame. */
                s.rays += stats.rays;
                s.first_batch = 0;
                publish(&s, view_now() - t0);
                pthread_mutex_lock(&sh->lock);
                continue;
            }
            if (st == ZT_ERR_CANCELLED) {
                pthread_mutex_lock(&sh->lock);
                continue;
            }
        }
        if (s.method == ZT_METHOD_ZONE)
            memset(s.sum->pixels, 0, (size_t)s.sum->width * (size_t)s.sum->height * 3 * sizeof(float));
        s.preview_shown = 0;
        st = zt_renderer_accumulate(s.r, s.spp, 1, s.sum, &stats, &err);
        double dt = view_now() - t0;
        if (st == ZT_ERR_CANCELLED) {
            /* the sum holds part of a batch: start again */
            memset(s.sum->pixels, 0, (size_t)s.sum->width * (size_t)s.sum->height * 3 * sizeof(float));
            s.spp = 0;
            s.rays = 0;
            pthread_mutex_lock(&sh->lock);
            continue;
        }
        if (st != ZT_OK) {
            if (s.method == ZT_METHOD_ZONE) {
                char msg[VIEW_MESSAGE_MAX];
                snprintf(msg, sizeof msg, "zone tracer: %s; showing the path tracer",
                         err.message);
                post_message(&s, msg, ZT_METHOD_PATH);
                s.zone_failed = 1;
                s.req.method = ZT_METHOD_PATH;
                zt_renderer_release(s.r);
                s.r = NULL; /* rebuilt as path on the next round */
                s.done = 0;
            } else {
                post_message(&s, err.message, -1);
                s.done = 1;
            }
            pthread_mutex_lock(&sh->lock);
            continue;
        }
        s.spp++;
        s.rays += stats.rays;
        int was_first = s.first_batch;
        s.first_batch = 0;
        if (s.method == ZT_METHOD_ZONE || s.spp >= MAX_SPP)
            s.done = 1;
        double now2 = view_now();
        if (was_first || s.done || now2 - s.last_publish >= 0.8 * frame)
            publish(&s, dt);
        pthread_mutex_lock(&sh->lock);
    }
    pthread_mutex_unlock(&sh->lock);
    zt_renderer_release(s.r);
    zt_scene_release(s.scene);
    zt_image_release(s.sum);
    zt_image_release(s.small);
    return NULL;
}

int view_worker_start(view_worker *w)
{
    return pthread_create(&w->thread, NULL, worker_main, w) == 0;
}

void view_worker_join(view_worker *w)
{
    pthread_join(w->thread, NULL);
}
