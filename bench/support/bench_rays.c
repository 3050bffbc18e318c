/* The benchmarks' recorded rays (bench_rays.h). */
#include "bench_rays.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "render/prim.h"

float bench_rnd(uint32_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return (float)(*s >> 8) * (1.0f / 16777216.0f);
}

/* Cosine-weighted about n, as a diffuse bounce samples. */
static vec3f bounce(vec3f n, uint32_t *s)
{
    vec3f t, b;
    f3_basis(n, &t, &b);
    float r = sqrtf(bench_rnd(s)), phi = 6.2831853f * bench_rnd(s);
    float z = sqrtf(fmaxf(0.0f, 1.0f - r * r));
    return f3_add(f3_scale(n, z), f3_add(f3_scale(t, r * cosf(phi)), f3_scale(b, r * sinf(phi))));
}

typedef struct surface_point {
    vec3f x, n; /* n faces the side the ray came from */
    int bg;
} surface_point;

static int record_hit(const rscene *rs, vec3f o, vec3f d, surface_point *out)
{
    hit h = accel_intersect(rs, o, d);
    if (h.part < 0)
        return 0;
    rs_part tmp;
    const rs_part *p = rs_prim(rs, h.part, &tmp);
    out->x = f3_madd(o, d, h.t);
    out->n = shape_normal(p, out->x);
    if (f3_dot(out->n, d) > 0.0f)
        out->n = f3_neg(out->n);
    out->bg = p->background;
    return 1;
}

void bench_make_rays(const rscene *rs, const zt_scene *scene, int camera_rays, ray_set *set)
{
    uint32_t seed = 2024;
    zt_camera c = zt_scene_get_camera(scene);
    vec3f eye = f3((float)c.viewpoint[0], (float)c.viewpoint[1], (float)c.viewpoint[2]);
    set->nearest = malloc(2 * (size_t)camera_rays * sizeof *set->nearest);
    set->any = malloc(2 * (size_t)camera_rays * sizeof *set->any);
    surface_point *pts = malloc(2 * (size_t)camera_rays * sizeof *pts);
    if (!set->nearest || !set->any || !pts) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    int n = 0, hits = 0;
    for (int i = 0; i < camera_rays; i++) {
        float u = bench_rnd(&seed), v = bench_rnd(&seed), p[3];
        for (int k = 0; k < 3; k++)
            p[k] = (float)(c.screen[0][k] + u * (c.screen[1][k] - c.screen[0][k]) +
                           v * (c.screen[2][k] - c.screen[0][k]));
        bench_ray *r = &set->nearest[n++];
        r->o = f3(p[0], p[1], p[2]);
        r->d = f3_normalize(f3_sub(r->o, eye));
        hits += record_hit(rs, r->o, r->d, &pts[hits]);
    }
    int first_bounce = hits;
    for (int i = 0; i < first_bounce; i++) {
        bench_ray *r = &set->nearest[n++];
        r->d = bounce(pts[i].n, &seed);
        r->o = ray_offset(pts[i].x, pts[i].n);
        hits += record_hit(rs, r->o, r->d, &pts[hits]);
    }
    set->n_nearest = n;
    /* Visibility between random pairs of hit points, stopping just short
     * of the target as a shadow ray does. */
    set->n_any = 0;
    for (int i = 0; i < hits && hits > 1; i++) {
        const surface_point *a = &pts[i], *b = &pts[(int)(bench_rnd(&seed) * (float)hits)];
        vec3f to = f3_sub(b->x, a->x);
        float len = f3_length(to);
        if (len <= 0.0f)
            continue;
        bench_ray *r = &set->any[set->n_any++];
        r->d = f3_scale(to, 1.0f / len);
        r->o = ray_offset(a->x, f3_dot(r->d, a->n) >= 0.0f ? a->n : f3_neg(a->n));
        r->dist = 0.9999f * len;
        r->bg = b->bg;
    }
    free(pts);
}


void bench_free_rays(ray_set *set)
{
    free(set->nearest);
    free(set->any);
    set->nearest = set->any = NULL;
}

long bench_trace_accel(const void *rs, const bench_ray *r, int any)
{
    return any ? accel_occluded(rs, r->o, r->d, r->dist, r->bg)
               : accel_intersect(rs, r->o, r->d).part;
}

double bench_throughput(const ray_set *set, int any, int threads, bench_trace_fn trace,
                        const void *ctx, int runs, double min_seconds)
{
    const bench_ray *rays = any ? set->any : set->nearest;
    int n = any ? set->n_any : set->n_nearest;
    double best = 0.0;
    long sink = 0;
    for (int run = 0; run < runs && n > 0; run++) {
        long passes = 0;
        double t0 = omp_get_wtime(), t;
        do {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 512) reduction(+ : sink)
            for (int i = 0; i < n; i++)
                sink += trace(ctx, &rays[i], any);
            passes++;
            t = omp_get_wtime() - t0;
        } while (t < min_seconds);
        best = fmax(best, (double)passes * n / t / 1e6);
    }
    if (sink == 42) /* keeps the work from being optimised away */
        fputc(' ', stderr);
    return best;
}
