/* Where a zone image's error comes from: the irradiance maps a pixel reads,
 * against Monte Carlo estimates of the same irradiance at the same points.
 *
 *   bench_zone_probe SCENE FOREST --level L --pixel X Y [--size WxH]
 *                    [--grid N] [--paths N] [--across-crossing STEPS RANGE]
 *
 * FOREST is a forest saved by `zonetrace render --method zone --level L
 * --save-forest` (its quality is read from the file).  A level-L pixel over
 * a flat diffuse surface shows w_d rho/pi E_{L-1}, read from the map; this
 * program reads the same map at N x N points of the pixel and estimates
 * E_{L-1} there by paths of L-1 cosine-sampled bounces ending in the exact
 * direct light of every light part (the zone tracer's direct.c) plus one
 * sky ray.  That estimate shares no map with the zone tracer, so it
 * separates the maps' error from the pixel's sampling.
 *
 * --across-crossing STEPS RANGE instead walks from the pixel's centre
 * towards the nearest crossing on its surface (where another triangle
 * pierces it): points at RANGE, RANGE/2, ... (STEPS halvings) from the
 * crossing's line on the centre's side (a negative RANGE: on the other
 * side), where the light changes fastest.
 * At each point the estimate is also split by the surface the first bounce
 * meets, which tells which source's map is wrong.
 *
 * Flat diffuse scenes only (what the maps' refinement covers): a first
 * bounce onto a specular or curved surface is counted as black. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camera.h"
#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "render/render_internal.h"
#include "util/vec3_convert.h"
#include "zone/zone_internal.h"
#include "zonetrace/zonetrace.h"

#define ZT_PROBE_PARTS 64 /* parts split out in the first bounce's breakdown */
#define PI 3.14159265358979323846

typedef struct probe {
    const zt_renderer *r;
    const zone_forest *f;
} probe;

static uint64_t mix_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *s)
{
    return (double)(mix_next(s) >> 11) * (1.0 / 9007199254740992.0);
}

static vec3 cosine_direction(vec3 n, uint64_t *s)
{
    double u1 = uniform(s), u2 = uniform(s), r = sqrt(u1), ph = 2.0 * PI * u2;
    vec3 a = fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0);
    vec3 t = v3_normalize(v3_cross(a, n)), b = v3_cross(n, t);
    return v3_add(v3_add(v3_scale(t, r * cos(ph)), v3_scale(b, r * sin(ph))),
                  v3_scale(n, sqrt(fmax(0.0, 1.0 - u1))));
}

static double mean3(vec3 a)
{
    return (a.x + a.y + a.z) / 3.0;
}

/* A flat part's plane normal (from its map) and x moved onto the plane. */
static vec3 on_plane(const part_map *m, vec3 *x)
{
    vec3 ns = v3_normalize(v3_cross(m->layout.du, m->layout.dv));
    *x = v3_sub(*x, v3_scale(ns, v3_dot(ns, v3_sub(*x, m->layout.origin))));
    return ns;
}

static vec3 diffuse_albedo(const probe *p, int part)
{
    const object *ob = &p->r->scene->objects[p->r->scene->parts[part].object];
    return v3_scale(ob->mat.color, ob->mat.weight[LOBE_DIFFUSE]);
}

/* E_0 at y: every light part exactly, the sky by one cosine ray. */
static vec3 direct_light(const probe *p, int part, vec3 y, vec3 n, uint64_t *s)
{
    const rscene *rs = &p->r->rs;
    zone_trace t = {p->f, p->r, 0, 0.0f};
    vec3 e = forest_lights_at(&t, part, y, n);
    vec3 d = cosine_direction(n, s);
    hit h = accel_intersect(rs, ray_offset(v3_to_f3(y), v3_to_f3(n)), v3_to_f3(d));
    if (h.part < 0)
        e = v3_add(e, v3_scale(v3(rs->sky.x, rs->sky.y, rs->sky.z), PI));
    return e;
}

/* One estimate of E_k at x (normal n, on part): k cosine bounces.  *first
 * gets the part the first bounce met (-1: none). */
static vec3 irradiance_path(const probe *p, vec3 x, vec3 n, int part, int k, uint64_t *s,
                            int *first)
{
    if (k == 0)
        return direct_light(p, part, x, n, s);
    const rscene *rs = &p->r->rs;
    vec3 d = cosine_direction(n, s);
    vec3f o = ray_offset(v3_to_f3(x), v3_to_f3(n));
    hit h = accel_intersect(rs, o, v3_to_f3(d));
    if (first)
        *first = h.part;
    if (h.part < 0 || p->r->scene->objects[p->r->scene->parts[h.part].object].is_light ||
        !p->f->maps[h.part].texels || p->f->maps[h.part].layout.shape == SHAPE_SPHERE)
        return v3(0, 0, 0);
    vec3 y = f3_to_v3(f3_madd(o, v3_to_f3(d), h.t));
    vec3 ns = on_plane(&p->f->maps[h.part], &y);
    vec3 ny = v3_dot(ns, d) < 0 ? ns : v3_scale(ns, -1);
    /* cosine sampling: pi/N sum L, L = rho/pi E */
    return v3_mul(irradiance_path(p, y, ny, h.part, k - 1, s, NULL), diffuse_albedo(p, h.part));
}

typedef struct estimate {
    vec3 e;
    double rel_sd;     /* of the mean */
    double by_part[ZT_PROBE_PARTS];
} estimate;

static estimate irradiance_mc(const probe *p, vec3 x, vec3 n, int part, int k, long paths,
                              uint64_t seed, int split)
{
    enum { CHUNKS = 16 };
    vec3 chunk[CHUNKS];
    double by[CHUNKS][ZT_PROBE_PARTS];
    memset(by, 0, sizeof by);
#pragma omp parallel for schedule(dynamic, 1)
    for (int c = 0; c < CHUNKS; c++) {
        uint64_t s = seed * 0x632be59bd9b4e019ull + (uint64_t)c * 0x9e3779b97f4a7c15ull;
        vec3 sum = v3(0, 0, 0);
        long n_c = paths / CHUNKS;
        for (long i = 0; i < n_c; i++) {
            int first = -1;
            vec3 e = irradiance_path(p, x, n, part, k, &s, &first);
            sum = v3_add(sum, e);
            if (split && first >= 0 && first < ZT_PROBE_PARTS)
                by[c][first] += mean3(e);
        }
        chunk[c] = v3_scale(sum, 1.0 / n_c);
        for (int q = 0; q < ZT_PROBE_PARTS && split; q++)
            by[c][q] /= n_c;
    }
    estimate est;
    memset(&est, 0, sizeof est);
    for (int c = 0; c < CHUNKS; c++) {
        est.e = v3_add(est.e, v3_scale(chunk[c], 1.0 / CHUNKS));
        for (int q = 0; q < ZT_PROBE_PARTS; q++)
            est.by_part[q] += by[c][q] / CHUNKS;
    }
    double ss = 0.0;
    for (int c = 0; c < CHUNKS; c++)
        ss += (mean3(chunk[c]) - mean3(est.e)) * (mean3(chunk[c]) - mean3(est.e));
    est.rel_sd = mean3(est.e) > 0 ? sqrt(ss / (CHUNKS - 1) / CHUNKS) / mean3(est.e) : 0.0;
    return est;
}

/* The crossing of map m nearest x, and its in-plane unit normal pointing
 * from the crossing's line towards x (the distance in *dist). */
static int nearest_crossing(const part_map *m, vec3 x, vec3 ns, vec3 *towards, double *dist)
{
    int best = -1;
    double bd = 1e300;
    for (int k = 0; k < m->crossings; k++) {
        const map_crossing *c = &m->cross[k];
        vec3 t = v3_sub(c->n, v3_scale(ns, v3_dot(c->n, ns)));
        double tl = v3_length(t);
        if (tl < 1e-9)
            continue;
        double d = (v3_dot(c->n, x) - c->d) / tl;
        if (fabs(d) < fabs(bd)) {
            bd = d;
            best = k;
            *towards = v3_scale(t, (d < 0 ? -1.0 : 1.0) / tl);
        }
    }
    *dist = fabs(bd);
    return best;
}

static int usage(void)
{
    fprintf(stderr, "usage: bench_zone_probe SCENE FOREST --level L --pixel X Y [--size WxH]\n"
                    "                        [--grid N] [--paths N] [--across-crossing STEPS RANGE]\n");
    return 1;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *forest = NULL;
    int level = -1, px = -1, py = -1, width = 0, height = 0, grid = 8, steps = 0;
    long paths = 100000;
    double range = 0.0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--level") && more)
            level = atoi(argv[++i]);
        else if (!strcmp(a, "--pixel") && i + 2 < argc) {
            px = atoi(argv[++i]);
            py = atoi(argv[++i]);
        } else if (!strcmp(a, "--size") && more) {
            if (sscanf(argv[++i], "%dx%d", &width, &height) != 2)
                return usage();
        } else if (!strcmp(a, "--grid") && more)
            grid = atoi(argv[++i]);
        else if (!strcmp(a, "--paths") && more)
            paths = atol(argv[++i]);
        else if (!strcmp(a, "--across-crossing") && i + 2 < argc) {
            steps = atoi(argv[++i]);
            range = atof(argv[++i]);
        } else if (a[0] != '-' && !scene_path)
            scene_path = a;
        else if (a[0] != '-' && !forest)
            forest = a;
        else
            return usage();
    }
    if (!scene_path || !forest || level < 2 || px < 0 || py < 0 || grid < 1 || paths < 16)
        return usage();

    zt_error err;
    zt_error_clear(&err);
    zt_scene *scene = NULL;
    if (zt_scene_load_file(scene_path, &scene, &err) != ZT_OK) {
        fprintf(stderr, "bench_zone_probe: %s\n", err.message);
        return 2;
    }
    zt_camera zc = zt_scene_get_camera(scene);
    if (width && zt_camera_set_resolution(&zc, width, height, &err) != ZT_OK) {
        fprintf(stderr, "bench_zone_probe: %s\n", err.message);
        return 1;
    }
    zt_scene_set_camera(scene, &zc);
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.level = level;
    o.forest_file = forest;
    /* The quality is the i32 at offset 52 of the file (docs/zone-tracer.md). */
    FILE *ff = fopen(forest, "rb");
    unsigned char qb[4] = {0, 0, 0, 0};
    int header_read = ff && fseek(ff, 52, SEEK_SET) == 0 && fread(qb, 1, 4, ff) == 4;
    if (ff)
        fclose(ff);
    if (!header_read) {
        fprintf(stderr, "bench_zone_probe: cannot read %s\n", forest);
        return 2;
    }
    o.quality = (int)((uint32_t)qb[0] | (uint32_t)qb[1] << 8 | (uint32_t)qb[2] << 16 |
                      (uint32_t)qb[3] << 24);
    zt_renderer *r = NULL;
    if (zt_renderer_create(scene, &o, &r, &err) != ZT_OK) {
        fprintf(stderr, "bench_zone_probe: %s\n", err.message);
        return 2;
    }
    probe p = {r, r->forest};
    if (r->rs.part_count > ZT_PROBE_PARTS)
        fprintf(stderr, "bench_zone_probe: only the first %d parts are split out\n",
                ZT_PROBE_PARTS);
    cam c;
    cam_init(&c, &r->scene->camera);

    if (steps > 0) {
        vec3f org, dir;
        cam_ray(&c, px + 0.5f, py + 0.5f, &org, &dir);
        hit h = accel_intersect(&r->rs, org, dir);
        if (h.part < 0 || !p.f->maps[h.part].crossings) {
            fprintf(stderr, "bench_zone_probe: the pixel's centre sees no surface with crossings\n");
            return 1;
        }
        const part_map *m = &p.f->maps[h.part];
        vec3 x0 = f3_to_v3(f3_madd(org, dir, h.t));
        vec3 ns = on_plane(m, &x0);
        int side = v3_dot(ns, f3_to_v3(dir)) > 0;
        vec3 n = side ? v3_scale(ns, -1) : ns, t;
        double d0;
        int k = nearest_crossing(m, x0, ns, &t, &d0);
        vec3 foot = v3_sub(x0, v3_scale(t, d0));
        if (range < 0) {
            t = v3_scale(t, -1.0);
            range = -range;
        }
        vec3 rho = v3_scale(diffuse_albedo(&p, h.part), 1.0 / PI);
        printf("part %d, crossing %d (part %d) %.4f from the centre; radiance x 1e4 (mean of rgb)\n",
               h.part, k, m->cross[k].part, d0);
        for (int i = 0; i <= steps; i++) {
            double d = range * pow(0.5, i);
            vec3 x = v3_add(foot, v3_scale(t, d));
            vec3 map = v3_mul(map_lookup_wide(m, level - 1, side, x, 0.0), rho);
            estimate e = irradiance_mc(&p, x, n, h.part, level - 1, paths, 1000 + i, 1);
            vec3 mc = v3_mul(e.e, rho);
            printf("distance %.5f: map %9.4f  paths %9.4f (+-%.2f%%)  map/paths %.4f\n", d,
                   1e4 * mean3(map), 1e4 * mean3(mc), 100 * e.rel_sd, mean3(map) / mean3(mc));
            for (int q = 0; q < r->rs.part_count && q < ZT_PROBE_PARTS; q++)
                if (e.by_part[q] > 1e-3 * mean3(e.e))
                    printf("    by way of part %2d: %5.1f%%\n", q,
                           100.0 * e.by_part[q] / mean3(e.e));
        }
    } else {
        double sum_map = 0.0, sum_mc = 0.0;
        int seen = 0;
        for (int sy = 0; sy < grid; sy++)
            for (int sx = 0; sx < grid; sx++) {
                vec3f org, dir;
                cam_ray(&c, px + (sx + 0.5f) / grid, py + (sy + 0.5f) / grid, &org, &dir);
                hit h = accel_intersect(&r->rs, org, dir);
                if (h.part < 0 || !p.f->maps[h.part].texels ||
                    p.f->maps[h.part].layout.shape == SHAPE_SPHERE)
                    continue;
                const part_map *m = &p.f->maps[h.part];
                vec3 x = f3_to_v3(f3_madd(org, dir, h.t));
                vec3 ns = on_plane(m, &x);
                int side = v3_dot(ns, f3_to_v3(dir)) > 0;
                vec3 n = side ? v3_scale(ns, -1) : ns, t;
                vec3 rho = v3_scale(diffuse_albedo(&p, h.part), 1.0 / PI);
                vec3 map = v3_mul(map_lookup_wide(m, level - 1, side, x, 0.0), rho);
                estimate e = irradiance_mc(&p, x, n, h.part, level - 1, paths,
                                           (uint64_t)(sy * grid + sx), 0);
                vec3 mc = v3_mul(e.e, rho);
                double dc = -1.0;
                if (m->crossings)
                    nearest_crossing(m, x, ns, &t, &dc);
                printf("%3d %3d part %2d crossing at %8.4f: map %9.4f  paths %9.4f (+-%.2f%%)\n", sx,
                       sy, h.part, dc, 1e4 * mean3(map), 1e4 * mean3(mc), 100 * e.rel_sd);
                sum_map += mean3(map);
                sum_mc += mean3(mc);
                seen++;
            }
        printf("pixel (%d, %d), %d x %d points, %d on mapped surfaces: map %.4f, paths %.4f, "
               "map/paths %.4f\n",
               px, py, grid, grid, seen, 1e4 * sum_map / (grid * grid), 1e4 * sum_mc / (grid * grid),
               sum_mc > 0 ? sum_map / sum_mc : 0.0);
    }
    zt_renderer_release(r);
    zt_scene_release(scene);
    return 0;
}
