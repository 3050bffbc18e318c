/* Gathering a level's light at a node (bounce_gather.h). */
#include "zone/transfer/bounce_gather.h"

#include <math.h>
#include <stdlib.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "util/sampler.h"
#include "util/vec3_convert.h"

#define PI 3.14159265358979323846
/* The fewest directions whose spread says whether the rest are worth
 * casting. */
#define FIRST_MIN 16

/* Directions traced together. */
#define BATCH 64

int bounce_gather_count(int n_dirs, int div)
{
    /* Fewer than four times FIRST_MIN would leave no first quarter to
     * test, and a few directions' spread says little: with 16, a sunlit
     * patch that none of them meets looks like no light at all. */
    int least = n_dirs < 4 * FIRST_MIN ? n_dirs : 4 * FIRST_MIN;
    return n_dirs / div > least ? n_dirs / div : least;
}

/* Sobol's second dimension: the direction numbers of x + 1, each the one
 * before xor itself shifted by one. */
static uint32_t sobol_second(uint32_t i)
{
    uint32_t r = 0, v = 1u << 31;
    for (; i; i >>= 1, v ^= v >> 1)
        if (i & 1)
            r ^= v;
    return r;
}

vec3 *bounce_directions(int n)
{
    vec3 *d = malloc((size_t)(n > 0 ? n : 1) * sizeof *d);
    if (!d)
        return NULL;
    for (int i = 0; i < n; i++) {
        double u1 = sampler_reverse_bits((uint32_t)i) * (1.0 / 4294967296.0);
        double u2 = sobol_second((uint32_t)i) * (1.0 / 4294967296.0);
        /* (Half a step up from 0: the first direction is not the normal
         * exactly, which a grid's neighbour would hit edge-on.) */
        u1 += 0.5 / n;
        double r = sqrt(u1), phi = 2 * PI * u2;
        d[i] = v3(r * cos(phi), r * sin(phi), sqrt(fmax(0.0, 1.0 - u1)));
    }
    return d;
}

static double lum(vec3 v)
{
    return 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
}

/* Whether the mean of `count` samples (sum s1, sum of squares s2) is known
 * well enough for the whole gather of n_dirs. */
static int good_enough(double s1, double s2, int count, int n_dirs, const bounce_limit *lim)
{
    double mean = s1 / count, var = fmax(0.0, s2 / count - mean * mean);
    double err = PI * sqrt(var / n_dirs);
    return err <= lim->eps * fmax(lim->lower + PI * mean, lim->floor);
}

/* The count a gather that has cast k directions goes on to: the
 * smallest of least, 4 least, ... n_dirs above k at which its error
 * would be within the limit; 0 when none would (the cut's node). */
static int next_count(double s1, double s2, int k, int least, int n_dirs,
                      const bounce_limit *lim)
{
    if (least < 1)
        least = 1;
    for (int c = least;; c = c * 4 < n_dirs ? c * 4 : n_dirs) {
        if (c > k && good_enough(s1, s2, k, c, lim))
            return c;
        if (c >= n_dirs)
            return 0;
    }
}

int bounce_gather(zone_trace *t, const vec3 *dirs, int least, int n_dirs, vec3 x, vec3 n,
                  int level, const bounce_limit *lim, vec3 *e)
{
    vec3 tt, bb;
    v3_frame(n, &tt, &bb);
    /* A mesh node's set, turned apart from its neighbours' (zone.h). */
    if (t->node_draw)
        v3_turn_frame(&tt, &bb, zone_node_turn(t->node_draw));
    vec3f o = ray_offset(v3_to_f3(x), v3_to_f3(n));
    vec3 sum = v3(0, 0, 0);
    double s1 = 0, s2 = 0;
    int target = least / 4 >= FIRST_MIN ? least / 4 : least;
    /* The rays go to the scene a batch at a time (packets from one
     * point), their hits then read one by one. */
    vec3f dir[BATCH];
    hit hits[BATCH];
    int k = 0;
    for (;;) {
        while (k < target) {
            int end = target - k < BATCH ? target : k + BATCH;
            for (int j = k; j < end; j++) {
                vec3 d = v3_add(v3_add(v3_scale(tt, dirs[j].x), v3_scale(bb, dirs[j].y)),
                                v3_scale(n, dirs[j].z));
                dir[j - k] = v3_to_f3(v3_normalize(d));
            }
            accel_intersect_n(&t->r->rs, o, dir, end - k, hits);
            t->rays += (uint64_t)(end - k);
            for (int j = k; j < end; j++) {
                t->first_hit = &hits[j - k];
                vec3 l = zone_radiance(t, o, dir[j - k], level, level,
                                       ZR_NO_GLINT | ZR_NO_CAUSTIC, NULL, 0);
                double y = lum(l);
                s1 += y;
                s2 += y * y;
                sum = v3_add(sum, l);
            }
            k = end;
        }
        if (k >= least && good_enough(s1, s2, k, k, lim))
            break;
        target = next_count(s1, s2, k, least, n_dirs, lim);
        if (!target)
            return 0;
    }
    *e = v3_scale(sum, PI / k);
    return 1;
}
