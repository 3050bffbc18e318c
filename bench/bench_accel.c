/* Acceleration backends compared: build time and million rays per second
 * for nearest-hit and visibility queries, on one thread and on all, for the
 * project's scenes and two synthetic scenes of about 100k triangles.  The
 * rays are a path tracer's: camera rays, diffuse bounces from their hits,
 * and visibility rays between hit points.  Then, on the scenes Embree
 * takes (above 1,000 primitives), the zone tracer's rays from one point,
 * one at a time against together (accel_intersect_n, accel_occluded_n):
 * 64 directions over a hit point's hemisphere, and 64 rays from a hit
 * point to a small patch (a light's pieces). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "render/prim.h"
#include "render/render_scene.h"
#include "scene/scene.h"
#include "bench_rays.h"

enum {
    CAMERA_RAYS = 1 << 16,
    BRUTE_MAX_PARTS = 2000 /* brute force only where it finishes quickly */
};
/* Each figure is the best of a few short runs: the machine may be shared. */
static const double MIN_SECONDS = 0.05;
enum { RUNS = 3 };

static const struct {
    accel_kind kind;
    const char *name;
} BACKENDS[] = {{ACCEL_BRUTE, "brute"}, {ACCEL_EMBREE, "embree"}, {ACCEL_BVH, "bvh"}};

static double throughput(const rscene *rs, const ray_set *set, int any, int threads)
{
    return bench_throughput(set, any, threads, bench_trace_accel, rs, RUNS, MIN_SECONDS);
}

static void bench_scene(const char *name, const zt_scene *scene)
{
    rscene rs;
    zt_error err = {0};
    if (rscene_build(&rs, scene, NULL, 0, ACCEL_BVH, &err) != ZT_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        return;
    }
    ray_set set;
    bench_make_rays(&rs, scene, CAMERA_RAYS, &set);
    int prims = rs.prim_count - rs.planes[0].count - rs.planes[1].count;
    int all = omp_get_max_threads();
    for (size_t k = 0; k < sizeof BACKENDS / sizeof BACKENDS[0]; k++) {
        if (BACKENDS[k].kind == ACCEL_BRUTE && rs.prim_count > BRUTE_MAX_PARTS)
            continue;
        accel_free(rs.accel);
        rs.accel = NULL;
        double t0 = omp_get_wtime();
        if (accel_build(&rs, BACKENDS[k].kind, &err) != ZT_OK) {
            fprintf(stderr, "%s, %s: %s\n", name, BACKENDS[k].name, err.message);
            continue;
        }
        double build_ms = 1e3 * (omp_get_wtime() - t0);
        printf("%-16s %7d %6d %-7s %9.2f %8.2f %8.2f %8.2f %8.2f\n", name, prims,
               set.n_nearest + set.n_any, BACKENDS[k].name, build_ms,
               throughput(&rs, &set, 0, 1), throughput(&rs, &set, 0, all),
               throughput(&rs, &set, 1, 1), throughput(&rs, &set, 1, all));
        fflush(stdout);
    }
    bench_free_rays(&set);
    rscene_free(&rs);
}

/* ---- rays from one point ---- */

enum { BUNDLE = 64, POINTS = 2048 };

typedef struct point_rays {
    vec3f o[POINTS], d[POINTS][BUNDLE];
    float dist[POINTS][BUNDLE];
} point_rays;

/* From the hit points of the set's first nearest rays: a hemisphere of
 * directions about the normal (hemi), or rays to points of a patch a
 * tenth of the scene's size away (not hemi). */
static int make_point_rays(const rscene *rs, const ray_set *set, int hemi, point_rays *pr)
{
    uint32_t seed = 99;
    int n = 0;
    for (int i = 0; i < set->n_nearest && n < POINTS; i++) {
        const bench_ray *r = &set->nearest[i];
        hit h = accel_intersect(rs, r->o, r->d);
        if (h.part < 0)
            continue;
        rs_part tmp;
        const rs_part *p = rs_prim(rs, h.part, &tmp);
        vec3f x = f3_madd(r->o, r->d, h.t), ng = shape_normal(p, x);
        if (f3_dot(ng, r->d) > 0.0f)
            ng = f3_neg(ng);
        pr->o[n] = ray_offset(x, ng);
        vec3f centre = f3_madd(x, ng, 5.0f);
        for (int j = 0; j < BUNDLE; j++) {
            vec3f d;
            if (hemi) {
                do
                    d = f3(2 * bench_rnd(&seed) - 1, 2 * bench_rnd(&seed) - 1,
                           2 * bench_rnd(&seed) - 1);
                while (f3_dot(d, d) > 1.0f || f3_dot(d, d) < 1e-4f);
                if (f3_dot(d, ng) < 0.0f)
                    d = f3_neg(d);
                pr->dist[n][j] = 3.4e38f;
            } else {
                vec3f q = f3_add(centre, f3(bench_rnd(&seed) - 0.5f, bench_rnd(&seed) - 0.5f,
                                            bench_rnd(&seed) - 0.5f));
                d = f3_sub(q, pr->o[n]);
                pr->dist[n][j] = f3_length(d) * 0.9999f;
            }
            pr->d[n][j] = f3_normalize(d);
        }
        n++;
    }
    return n;
}

/* Million rays a second on one thread, the best of RUNS: one query a ray
 * (together = 0) or the point's 64 together. */
static double point_throughput(const rscene *rs, const point_rays *pr, int n, int hemi,
                               int together)
{
    double best = 0;
    long sink = 0;
    for (int run = 0; run < RUNS; run++) {
        long rays = 0;
        double t0 = omp_get_wtime(), t;
        do {
            for (int i = 0; i < n; i++) {
                if (hemi && together) {
                    hit h[BUNDLE];
                    accel_intersect_n(rs, pr->o[i], pr->d[i], BUNDLE, h);
                    sink += h[BUNDLE - 1].part;
                } else if (hemi) {
                    for (int j = 0; j < BUNDLE; j++)
                        sink += accel_intersect(rs, pr->o[i], pr->d[i][j]).part;
                } else if (together) {
                    unsigned char hidden[BUNDLE];
                    accel_occluded_n(rs, pr->o[i], pr->d[i], pr->dist[i], BUNDLE, 0, hidden);
                    sink += hidden[BUNDLE - 1];
                } else {
                    for (int j = 0; j < BUNDLE; j++)
                        sink += accel_occluded(rs, pr->o[i], pr->d[i][j], pr->dist[i][j], 0);
                }
            }
            rays += (long)n * BUNDLE;
            t = omp_get_wtime() - t0;
        } while (t < MIN_SECONDS);
        double mrays = rays / t * 1e-6;
        best = mrays > best ? mrays : best;
    }
    if (sink == 42)
        printf(" ");
    return best;
}

static void bench_points(const char *name, const zt_scene *scene)
{
    rscene rs;
    zt_error err = {0};
    if (rscene_build(&rs, scene, NULL, 0, ACCEL_EMBREE, &err) != ZT_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        return;
    }
    if (rs.prim_count - rs.planes[0].count - rs.planes[1].count <= 1000) {
        rscene_free(&rs);
        return;
    }
    ray_set set;
    bench_make_rays(&rs, scene, CAMERA_RAYS, &set);
    point_rays *pr = malloc(sizeof *pr);
    if (!pr)
        exit(1);
    for (int hemi = 1; hemi >= 0; hemi--) {
        int n = make_point_rays(&rs, &set, hemi, pr);
        double one = point_throughput(&rs, pr, n, hemi, 0);
        double together = point_throughput(&rs, pr, n, hemi, 1);
        printf("%-16s %-22s %8.2f %8.2f %6.2f\n", name,
               hemi ? "hemisphere, nearest" : "to a patch, visibility", one, together,
               together / one);
    }
    free(pr);
    bench_free_rays(&set);
    rscene_free(&rs);
}

/* ---- synthetic scenes: a room of background planes around a mesh ---- */

static void add_object(zt_scene *s, int background, int culled)
{
    object o;
    memset(&o, 0, sizeof o);
    o.background = background;
    o.backculled = culled;
    o.mat = material_default();
    scene_add_object(s, &o);
}

static void add_triangle(zt_scene *s, vec3 a, vec3 b, vec3 c)
{
    part p;
    memset(&p, 0, sizeof p);
    p.shape = SHAPE_TRIANGLE;
    p.p[0] = a;
    p.p[1] = b;
    p.p[2] = c;
    scene_add_part(s, &p);
}

static zt_scene *room(void)
{
    zt_scene *s = scene_create();
    if (!s)
        exit(1);
    add_object(s, 1, 1);
    for (int a = 0; a < 6; a++) {
        part p;
        memset(&p, 0, sizeof p);
        p.shape = SHAPE_PLANE;
        double n[3] = {0, 0, 0};
        n[a / 2] = a % 2 ? -1 : 1;
        p.normal = v3(n[0], n[1], n[2]);
        p.offset = a == 5 ? -22 : -10; /* the wall behind the camera at z = 22 */
        scene_add_part(s, &p);
    }
    zt_camera c = {{0, 0, 20}, {{-1, 1, 19}, {1, 1, 19}, {-1, -1, 19}, {1, -1, 19}}, 512, 512};
    zt_scene_set_camera(s, &c);
    return s;
}

/* A bumpy sphere of 2 * nu * (nv - 1) triangles. */
static vec3 bumpy(int i, int j, int nu, int nv)
{
    double th = 3.14159265358979 * j / nv, ph = 6.28318530717959 * i / nu;
    double r = 7.0 * (1.0 + 0.08 * sin(7 * th) * sin(9 * ph));
    return v3(r * sin(th) * cos(ph), r * cos(th), r * sin(th) * sin(ph));
}

static zt_scene *mesh_scene(void)
{
    zt_scene *s = room();
    add_object(s, 0, 1);
    const int nu = 320, nv = 157;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            vec3 a = bumpy(i, j, nu, nv), b = bumpy(i + 1, j, nu, nv);
            vec3 c = bumpy(i, j + 1, nu, nv), d = bumpy(i + 1, j + 1, nu, nv);
            if (j > 0)
                add_triangle(s, a, b, c);
            if (j < nv - 1)
                add_triangle(s, b, d, c);
        }
    return s;
}

static zt_scene *soup_scene(void)
{
    zt_scene *s = room();
    add_object(s, 0, 0);
    uint32_t seed = 7;
    for (int i = 0; i < 100000; i++) {
        vec3 a = v3(16 * bench_rnd(&seed) - 8, 16 * bench_rnd(&seed) - 8, 16 * bench_rnd(&seed) - 8);
        vec3 e[2];
        for (int k = 0; k < 2; k++)
            e[k] = v3(0.6 * bench_rnd(&seed) - 0.3, 0.6 * bench_rnd(&seed) - 0.3, 0.6 * bench_rnd(&seed) - 0.3);
        add_triangle(s, a, v3_add(a, e[0]), v3_add(a, e[1]));
    }
    return s;
}

/* The project's scenes folder: argv[1], or found from this file's path. */
static void scenes_dir(int argc, char **argv, char *out, size_t size)
{
    if (argc > 1) {
        snprintf(out, size, "%s", argv[1]);
        return;
    }
    snprintf(out, size, "%s", __FILE__);
    char *slash = strrchr(out, '/');
    if (slash)
        snprintf(slash, size - (size_t)(slash - out), "/../scenes");
    else
        snprintf(out, size, "scenes");
}

/* fn on each scene file of the listing (names, count: scandir's). */
static void each_scene(const char *dir, struct dirent **names, int count,
                       void (*fn)(const char *, const zt_scene *))
{
    for (int i = 0; i < count; i++) {
        const char *f = names[i]->d_name;
        size_t len = strlen(f);
        if (len <= 5 || strcmp(f + len - 5, ".json") != 0)
            continue;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, f);
        zt_scene *s = NULL;
        zt_error err = {0};
        if (zt_scene_load_file(path, &s, &err) == ZT_OK)
            fn(f, s);
        else
            fprintf(stderr, "%s\n", err.message);
        zt_scene_release(s);
    }
}

int main(int argc, char **argv)
{
    char dir[1024];
    scenes_dir(argc, argv, dir, sizeof dir);
    printf("Mrays/s on 1 and %d threads; build in ms; planes are not counted as "
           "primitives\n\n", omp_get_max_threads());
    printf("%-16s %7s %6s %-7s %9s %8s %8s %8s %8s\n", "scene", "prims", "rays",
           "backend", "build", "near 1T", "near NT", "any 1T", "any NT");
    struct dirent **names;
    int count = scandir(dir, &names, NULL, alphasort);
    if (count < 0)
        fprintf(stderr, "%s: cannot list the scenes\n", dir);
    each_scene(dir, names, count, bench_scene);
    zt_scene *synthetic[2] = {mesh_scene(), soup_scene()};
    const char *synthetic_name[2] = {"bumpy sphere", "random soup"};
    for (int k = 0; k < 2; k++)
        bench_scene(synthetic_name[k], synthetic[k]);
    printf("\nRays from one point, Embree, 1 thread: Mrays/s one at a time and %d "
           "together\n\n%-16s %-22s %8s %8s %6s\n", BUNDLE, "scene", "rays", "one", "together",
           "ratio");
    each_scene(dir, names, count, bench_points);
    for (int k = 0; k < 2; k++) {
        bench_points(synthetic_name[k], synthetic[k]);
        zt_scene_release(synthetic[k]);
    }
    for (int i = 0; i < count; i++)
        free(names[i]);
    if (count >= 0)
        free(names);
    return 0;
}
