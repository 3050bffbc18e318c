/* Evaluating motions at a time t, in closed form (docs/viewer.md):
 *
 *   linear       offset = delta * min(t, stop / |delta|)   (stop < 0: t)
 *   orbiting     rotation by 2 pi t / period about a world axis
 *   oscillating  offset = (end - begin) * (1 - cos(2 pi t / period)) / 2
 *   brownian     offset = scale * 0.01 * (d_0 + ... + d_{n-1} + f d_n),
 *                n = floor(t / 10 ms), f its fraction, d_i seeded unit
 *                directions uniform on the sphere
 *
 * applied in file order, each to the result of those before it.  The
 * camera path is camera_path.c's. */
#include "zonetrace/motion.h"

#include <math.h>
#include <string.h>

#include "scene/motions.h"
#include "scene/scene.h"
#include "util/error.h"

#define TWO_PI 6.283185307179586476925286766559

/* SplitMix64's output function: a bijective 64-bit mix. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

#define GOLDEN 0x9E3779B97F4A7C15ULL

/* A uniform double in [0, 1) from 53 bits of h. */
static double unit_double(uint64_t h)
{
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

void motion_brownian_direction(uint64_t seed, int index, int64_t step,
                               double out[3])
{
    /* one stream per (seed, motion), counter-based within it */
    uint64_t key = mix64(seed ^ mix64((uint64_t)(index + 1) * GOLDEN));
    uint64_t n = (uint64_t)step * 2u;
    double u = unit_double(mix64(key + (n + 1) * GOLDEN));
    double v = unit_double(mix64(key + (n + 2) * GOLDEN));
    double z = 1.0 - 2.0 * u;
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    double phi = TWO_PI * v;
    out[0] = r * cos(phi);
    out[1] = r * sin(phi);
    out[2] = z;
}

/* Sum of the first `steps` directions of walk `index`, from the cache when
 * it can be extended. */
static void brownian_sum(zt_motions *ms, int index, uint64_t seed,
                         int64_t steps, double sum[3])
{
    pthread_mutex_lock(&ms->lock);
    motion_walk *w = &ms->walks[index];
    if (w->seed != seed || w->steps > steps) {
        w->seed = seed;
        w->steps = 0;
        w->sum[0] = w->sum[1] = w->sum[2] = 0.0;
    }
    for (int64_t i = w->steps; i < steps; i++) {
        double d[3];
        motion_brownian_direction(seed, index, i, d);
        w->sum[0] += d[0];
        w->sum[1] += d[1];
        w->sum[2] += d[2];
    }
    w->steps = steps;
    memcpy(sum, w->sum, sizeof w->sum);
    pthread_mutex_unlock(&ms->lock);
}

/* The phase t / period as a fraction of a turn in [0, 1), exact for large t. */
static double turns(double t, double period)
{
    double f = fmod(t / period, 1.0);
    return f < 0 ? f + 1.0 : f;
}

static zt_status apply_one(zt_motions *ms, int index, uint64_t seed, double t,
                           zt_scene *s, zt_error *err)
{
    const zt_motion *m = &ms->items[index];
    double d[3] = {0, 0, 0};
    switch (m->type) {
    case ZT_MOTION_LINEAR: {
        double speed = sqrt(m->delta[0] * m->delta[0] + m->delta[1] * m->delta[1] +
                            m->delta[2] * m->delta[2]);
        double te = t;
        if (m->stop >= 0 && speed > 0 && speed * t > m->stop)
            te = m->stop / speed;
        for (int k = 0; k < 3; k++)
            d[k] = m->delta[k] * te;
        break;
    }
    case ZT_MOTION_ORBITING:
        return zt_scene_rotate_object(s, m->target_class, m->target, m->axis,
                                      TWO_PI * turns(t, m->period), err);
    case ZT_MOTION_OSCILLATING: {
        double w = 0.5 * (1.0 - cos(TWO_PI * turns(t, m->period)));
        for (int k = 0; k < 3; k++)
            d[k] = (m->end[k] - m->begin[k]) * w;
        break;
    }
    case ZT_MOTION_BROWNIAN: {
        if (t > MOTION_BROWNIAN_MAX_TIME)
            return zt_fail(err, ZT_ERR_ARGUMENT, "time %g s is too late for a "
                           "brownian motion (the limit is %g s)", t,
                           MOTION_BROWNIAN_MAX_TIME);
        double x = t / MOTION_BROWNIAN_STEP;
        int64_t n = (int64_t)floor(x);
        double frac = x - (double)n, sum[3], next[3];
        brownian_sum(ms, index, seed, n, sum);
        motion_brownian_direction(seed, index, n, next);
        double len = m->scale * MOTION_BROWNIAN_STEP;
        for (int k = 0; k < 3; k++)
            d[k] = len * (sum[k] + frac * next[k]);
        break;
    }
    }
    return zt_scene_translate_object(s, m->target_class, m->target, d, err);
}

static zt_status check_time(double t, zt_error *err)
{
    if (!(t >= 0) || !isfinite(t))
        return zt_fail(err, ZT_ERR_ARGUMENT, "motion time must be a number >= 0, not %g", t);
    return ZT_OK;
}

/* The camera path's camera at t on the grid of scene0's camera. */
static zt_status path_camera(const zt_motions *ms, const zt_scene *scene0, double t,
                             zt_camera *out, zt_error *err)
{
    zt_camera cam = scene0->camera;
    if (!scene0->has_camera || cam.width < 1 || cam.height < 1)
        return zt_fail(err, ZT_ERR_ARGUMENT, "the camera path needs the scene's pixel grid, "
                       "and the scene has no camera");
    double pos[3], at[3], up[3], fov;
    camera_path_at(&ms->path, t, pos, at, up, &fov);
    zt_error why;
    zt_error_clear(&why);
    if (zt_camera_look_at(&cam, pos, at, up, fov, cam.width, cam.height, &why) == ZT_OK) {
        *out = cam;
        return ZT_OK;
    }
    /* The keys themselves were checked: t lies between two of them, and the
     * file is at fault. */
    int i = camera_path_segment(&ms->path, t);
    const zt_camera_key *k = &ms->path.keys[i < 0 ? 0 : i];
    return zt_fail(err, ZT_ERR_PARSE, "%s:%d:%d: the camera path between this key and the "
                   "next is degenerate at %g s: %s", ms->name, k->line, k->column, t,
                   why.message);
}

zt_status zt_motions_camera(const zt_motions *motions, const zt_scene *scene0, double t,
                            zt_camera *out, zt_error *err)
{
    zt_error_clear(err);
    if (!motions || !scene0 || !out)
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_motions_camera: no motions, scene or camera");
    zt_status st = check_time(t, err);
    if (st != ZT_OK)
        return st;
    if (!motions->path.count) {
        *out = scene0->camera;
        return ZT_OK;
    }
    return path_camera(motions, scene0, t, out, err);
}

zt_status zt_motions_apply(const zt_motions *motions,
                           const zt_scene *scene0, double t, uint64_t seed,
                           zt_scene *out, zt_error *err)
{
    zt_error_clear(err);
    if (!motions || !scene0 || !out)
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_motions_apply: no motions or no scene");
    zt_status st = check_time(t, err);
    if (st != ZT_OK)
        return st;
    if (out->object_count != scene0->object_count || out->part_count != scene0->part_count)
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_motions_apply: the output scene is "
                       "not a clone of the scene at time 0");
    if (out == scene0)
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_motions_apply: the output scene "
                       "must be a clone, not the scene at time 0 itself");
    if (scene0->object_count)
        memcpy(out->objects, scene0->objects, (size_t)scene0->object_count * sizeof(object));
    if (scene0->part_count)
        memcpy(out->parts, scene0->parts, (size_t)scene0->part_count * sizeof(part));
    out->light_count = scene0->light_count;
    out->thing_count = scene0->thing_count;
    out->sky = scene0->sky;
    out->has_sky = scene0->has_sky;
    /* The cache of the walks is the only state that changes. */
    zt_motions *ms = (zt_motions *)motions;
    for (int i = 0; i < ms->count; i++) {
        st = apply_one(ms, i, seed, t, out, err);
        if (st != ZT_OK)
            return st;
    }
    if (ms->path.count) {
        zt_camera cam;
        st = path_camera(ms, scene0, t, &cam, err);
        if (st != ZT_OK)
            return st;
        zt_scene_set_camera(out, &cam);
    }
    return ZT_OK;
}
