/* Evaluating a camera path: centripetal Catmull-Rom curves for the position
 * and the look-at point (Barry and Goldman's recursive form, with the knot
 * spacing of Yuksel, Schaefer and Keyser: |P_{i+1} - P_i|^0.5), and
 * monotone cubics over time (Fritsch and Butland's slopes) for the pace
 * along each curve, the up vector and the fov. */
#include "scene/camera_path.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/vec3.h"

static vec3 key_point(const camera_path *p, int which, int i)
{
    return v3_from(which == PATH_POSITION ? p->keys[i].position : p->keys[i].lookat);
}

/* Slopes at the keys of a monotone cubic through (time_k, y_k): the
 * weighted harmonic mean of the neighbouring secants where both have the
 * same sign, else 0.  Such a cubic never leaves the range of the two keys
 * it joins, so a curve parameter never runs backwards and the fov stays
 * between its keys' values.  The end slopes are 0: the camera comes to
 * rest at the first and the last key, where it then holds still. */
static void monotone_slopes(camera_path *p, int c)
{
    const zt_camera_key *k = p->keys;
    int n = p->count;
    p->slope[0][c] = p->slope[n - 1][c] = 0;
    for (int i = 1; i + 1 < n; i++) {
        double h0 = k[i].time - k[i - 1].time, h1 = k[i + 1].time - k[i].time;
        double d0 = (p->value[i][c] - p->value[i - 1][c]) / h0;
        double d1 = (p->value[i + 1][c] - p->value[i][c]) / h1;
        if (!(d0 * d1 > 0)) {
            p->slope[i][c] = 0;
            continue;
        }
        double w0 = 2 * h1 + h0, w1 = h1 + 2 * h0;
        p->slope[i][c] = (w0 + w1) / (w0 / d0 + w1 / d1);
    }
}

int camera_path_prepare(camera_path *p)
{
    p->value = calloc((size_t)p->count, sizeof *p->value);
    p->slope = calloc((size_t)p->count, sizeof *p->slope);
    if (!p->value || !p->slope)
        return 0;
    for (int i = 0; i < p->count; i++) {
        for (int which = PATH_POSITION; which <= PATH_LOOKAT; which++)
            p->value[i][which] = i == 0 ? 0.0
                                 : p->value[i - 1][which] +
                                       sqrt(v3_length(v3_sub(key_point(p, which, i),
                                                             key_point(p, which, i - 1))));
        vec3 up = v3_normalize(v3_from(p->keys[i].up));
        p->value[i][PATH_UP] = up.x;
        p->value[i][PATH_UP + 1] = up.y;
        p->value[i][PATH_UP + 2] = up.z;
        p->value[i][PATH_FOV] = p->keys[i].fov;
    }
    for (int c = 0; c < PATH_CHANNELS; c++)
        monotone_slopes(p, c);
    return 1;
}

void camera_path_free(camera_path *p)
{
    free(p->keys);
    free(p->value);
    free(p->slope);
    memset(p, 0, sizeof *p);
}

int camera_path_segment(const camera_path *p, double t)
{
    if (!(t >= p->keys[0].time))
        return -1;
    int lo = 0, hi = p->count - 1;
    if (t >= p->keys[hi].time)
        return hi;
    while (hi - lo > 1) { /* keys[lo].time <= t < keys[hi].time */
        int mid = lo + (hi - lo) / 2;
        if (t >= p->keys[mid].time)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Channel c between keys i and i + 1 at the fraction s of their interval
 * (cubic Hermite), kept between the two keys' values against rounding
 * (and against overflow for keys a denormal time apart). */
static double channel_at(const camera_path *p, int c, int i, double s)
{
    double h = p->keys[i + 1].time - p->keys[i].time;
    double y0 = p->value[i][c], y1 = p->value[i + 1][c];
    double u = 1 - s;
    double y = (1 + 2 * s) * u * u * y0 + s * u * u * h * p->slope[i][c] +
               s * s * (3 - 2 * s) * y1 - s * s * u * h * p->slope[i + 1][c];
    double lo = y0 < y1 ? y0 : y1, hi = y0 < y1 ? y1 : y0;
    return !(y >= lo) ? lo : y > hi ? hi : y;
}

/* The curve of `which` (position or look-at) between keys i and i + 1 at
 * its parameter x.  Where a neighbour is missing (the ends) or coincides
 * with the key next to it (a zero knot interval), it is replaced by the
 * reflection of the segment's far key, 2 P_i - P_{i+1}, whose interval
 * equals the segment's: the curve still passes through every key. */
static vec3 curve_at(const camera_path *p, int which, int i, double x)
{
    vec3 p1 = key_point(p, which, i), p2 = key_point(p, which, i + 1);
    double t1 = p->value[i][which], t2 = p->value[i + 1][which];
    if (!(t2 > t1))
        return p1; /* the point stands still between these keys */
    vec3 p0, p3;
    double t0, t3;
    if (i > 0 && p->value[i - 1][which] < t1) {
        p0 = key_point(p, which, i - 1);
        t0 = p->value[i - 1][which];
    } else {
        p0 = v3_sub(v3_scale(p1, 2), p2);
        t0 = t1 - (t2 - t1);
    }
    if (i + 2 < p->count && p->value[i + 2][which] > t2) {
        p3 = key_point(p, which, i + 2);
        t3 = p->value[i + 2][which];
    } else {
        p3 = v3_sub(v3_scale(p2, 2), p1);
        t3 = t2 + (t2 - t1);
    }
    vec3 a1 = v3_add(v3_scale(p0, (t1 - x) / (t1 - t0)), v3_scale(p1, (x - t0) / (t1 - t0)));
    vec3 a2 = v3_add(v3_scale(p1, (t2 - x) / (t2 - t1)), v3_scale(p2, (x - t1) / (t2 - t1)));
    vec3 a3 = v3_add(v3_scale(p2, (t3 - x) / (t3 - t2)), v3_scale(p3, (x - t2) / (t3 - t2)));
    vec3 b1 = v3_add(v3_scale(a1, (t2 - x) / (t2 - t0)), v3_scale(a2, (x - t0) / (t2 - t0)));
    vec3 b2 = v3_add(v3_scale(a2, (t3 - x) / (t3 - t1)), v3_scale(a3, (x - t1) / (t3 - t1)));
    return v3_add(v3_scale(b1, (t2 - x) / (t2 - t1)), v3_scale(b2, (x - t1) / (t2 - t1)));
}

void camera_path_at(const camera_path *p, double t, double position[3], double lookat[3],
                    double up[3], double *fov)
{
    int i = camera_path_segment(p, t);
    if (i < 0 || i == p->count - 1 || t == p->keys[i].time) {
        const zt_camera_key *k = &p->keys[i < 0 ? 0 : i];
        memcpy(position, k->position, sizeof k->position);
        memcpy(lookat, k->lookat, sizeof k->lookat);
        memcpy(up, k->up, sizeof k->up);
        *fov = k->fov;
        return;
    }
    double s = (t - p->keys[i].time) / (p->keys[i + 1].time - p->keys[i].time);
    v3_store(curve_at(p, PATH_POSITION, i, channel_at(p, PATH_POSITION, i, s)), position);
    v3_store(curve_at(p, PATH_LOOKAT, i, channel_at(p, PATH_LOOKAT, i, s)), lookat);
    vec3 u = v3(channel_at(p, PATH_UP, i, s), channel_at(p, PATH_UP + 1, i, s),
                channel_at(p, PATH_UP + 2, i, s));
    v3_store(v3_normalize(u), up);
    *fov = channel_at(p, PATH_FOV, i, s);
}
