/* A large model from a file, as the path tracer meets it: the time Assimp
 * takes to read the file, then the project's own load (checks, flat
 * arrays, materials) and acceleration build, the memory held per triangle,
 * and ray throughput through the renderers' query interface against
 * Embree's own rtcIntersect1 / rtcOccluded1 on the very same rays, and
 * the whole path tracer's rays per second on its own rays.
 *
 *   bench_mesh MODEL [THREADS]
 *
 * MODEL is any file Assimp reads; bench/gen_mesh makes large ones. */
#define _GNU_SOURCE
#include <embree3/rtcore.h>
#include <malloc.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_rays.h"
#include "geom/accel.h"
#include "render/render_scene.h"
#include "scene/mesh.h"
#include "scene/model_import.h"
#include "scene/scene.h"
#include "zonetrace/render.h"

enum { CAMERA_RAYS = 1 << 18, RUNS = 3 };
static const double MIN_SECONDS = 0.2;

/* A line of /proc/self/status ("VmRSS:", "VmHWM:") in bytes. */
static double proc_bytes(const char *key)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double kb = 0;
    size_t n = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, key, n) == 0)
            kb = atof(line + n);
    if (f)
        fclose(f);
    return kb * 1024.0;
}

/* Resident bytes with the allocator's free memory handed back. */
static double resident(void)
{
    malloc_trim(0);
    return proc_bytes("VmRSS:");
}

typedef struct raw_embree {
    RTCDevice device;
    RTCScene scene;
} raw_embree;

/* Embree alone on the mesh's arrays, its default settings. */
static double raw_build(raw_embree *e, const mesh *m)
{
    double t0 = omp_get_wtime();
    e->device = rtcNewDevice(NULL);
    e->scene = rtcNewScene(e->device);
    RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m->position, 0,
                               3 * sizeof(float), (size_t)m->vertex_count);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->index, 0,
                               3 * sizeof(unsigned), (size_t)m->triangle_count);
    rtcCommitGeometry(g);
    rtcAttachGeometry(e->scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(e->scene);
    return omp_get_wtime() - t0;
}

static long raw_trace(const void *raw, const bench_ray *r, int any)
{
    const raw_embree *e = raw;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    rh.ray.org_x = r->o.x; rh.ray.org_y = r->o.y; rh.ray.org_z = r->o.z;
    rh.ray.dir_x = r->d.x; rh.ray.dir_y = r->d.y; rh.ray.dir_z = r->d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = any ? r->dist : INFINITY;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    if (any) {
        rtcOccluded1(e->scene, &ctx, &rh.ray);
        return rh.ray.tfar < 0.0f;
    }
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(e->scene, &ctx, &rh);
    return (long)rh.hit.primID;
}

/* The model under a white sky, seen from the front-right and above. */
static zt_scene *scene_of(mesh *m)
{
    zt_scene *s = scene_create();
    object o;
    memset(&o, 0, sizeof o);
    o.mat = material_default();
    o.mat.color = v3(0.7, 0.7, 0.7);
    if (!s || scene_add_mesh_object(s, &o, mesh_retain(m)) < 0) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    s->sky = v3(1, 1, 1);
    s->has_sky = 1;
    vec3 lo, hi;
    mesh_bounds(m, &lo, &hi);
    vec3 c = v3_scale(v3_add(lo, hi), 0.5);
    double r = 0.5 * v3_length(v3_sub(hi, lo));
    double at[3] = {c.x, c.y, c.z}, up[3] = {0, 1, 0};
    double from[3] = {c.x + 1.6 * r, c.y + 1.2 * r, c.z + 2.2 * r};
    zt_camera cam;
    zt_error err = {0};
    if (zt_camera_look_at(&cam, from, at, up, 40, 512, 512, &err) != ZT_OK) {
        fprintf(stderr, "camera: %s\n", err.message);
        exit(1);
    }
    zt_scene_set_camera(s, &cam);
    return s;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: bench_mesh MODEL [THREADS]\n");
        return 1;
    }
    int threads = argc > 2 ? atoi(argv[2]) : omp_get_max_threads();
    if (threads < 1)
        threads = 1;
    double rss0 = resident();
    double read_s = 0;
    model_import_options opt = {.smooth = 1, .read_seconds = &read_s};
    mesh *m = NULL;
    zt_error err = {0};
    double t0 = omp_get_wtime();
    if (model_import(argv[1], &opt, &m, NULL, &err) != ZT_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    double import_s = omp_get_wtime() - t0;
    double peak_import = proc_bytes("VmHWM:");
    double rss_mesh = resident();
    zt_scene *s = scene_of(m);
    rscene rs;
    t0 = omp_get_wtime();
    if (rscene_build(&rs, s, NULL, 0, ACCEL_EMBREE, &err) != ZT_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    double build_s = omp_get_wtime() - t0;
    double rss_built = resident();
    double tris = m->triangle_count;

    printf("model %s: %d triangles, %d vertices, %d threads\n", argv[1], m->triangle_count,
           m->vertex_count, threads);
    printf("  Assimp reads the file:          %8.3f s (parse, apart)\n", read_s);
    printf("  zonetrace load (checks, arrays): %8.3f s\n", import_s - read_s);
    printf("  acceleration build (Embree):     %8.3f s\n", build_s);
    printf("  load + build after the parse:    %8.3f s\n", import_s - read_s + build_s);
    printf("  held after load:  %6.1f bytes/triangle (mesh arrays %.1f)\n",
           (rss_mesh - rss0) / tris, (double)mesh_memory(m) / tris);
    printf("  held after build: %6.1f bytes/triangle\n", (rss_built - rss0) / tris);
    printf("  peak while Assimp read:   %6.1f bytes/triangle\n", (peak_import - rss0) / tris);

    ray_set set;
    bench_make_rays(&rs, s, CAMERA_RAYS, &set);
    raw_embree raw;
    double raw_build_s = raw_build(&raw, m);
    printf("  Embree alone (default quality) builds in %.3f s\n", raw_build_s);
    printf("\n  %d nearest-hit rays (camera, bounce), %d visibility rays\n", set.n_nearest,
           set.n_any);
    printf("  %-28s %10s %10s %10s %10s\n", "Mrays/s", "near 1T", "near NT", "any 1T",
           "any NT");
    double ours[4], theirs[4];
    for (int k = 0; k < 4; k++) {
        int any = k >= 2, th = k % 2 ? threads : 1;
        ours[k] = bench_throughput(&set, any, th, bench_trace_accel, &rs, RUNS, MIN_SECONDS);
        theirs[k] = bench_throughput(&set, any, th, raw_trace, &raw, RUNS, MIN_SECONDS);
    }
    printf("  %-28s %10.2f %10.2f %10.2f %10.2f\n", "accel_intersect/occluded", ours[0],
           ours[1], ours[2], ours[3]);
    printf("  %-28s %10.2f %10.2f %10.2f %10.2f\n", "rtcIntersect1/rtcOccluded1", theirs[0],
           theirs[1], theirs[2], theirs[3]);
    printf("  %-28s %9.0f%% %9.0f%% %9.0f%% %9.0f%%\n", "ratio", 100 * ours[0] / theirs[0],
           100 * ours[1] / theirs[1], 100 * ours[2] / theirs[2], 100 * ours[3] / theirs[3]);

    /* The whole path tracer (sampling, shading, its own rays). */
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_PATH;
    o.spp = 16;
    o.threads = threads;
    zt_image *img = NULL;
    zt_render_stats st;
    if (zt_render(s, &o, &img, &st, &err) != ZT_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    /* Its rays are its own (most bounces leave a convex model for the sky
     * at once), so this is no ratio to the recorded rays above. */
    printf("\n  path tracer, 512x512 16 spp: %.2f Mrays/s on its own rays, sampling and "
           "shading included (%.3f s tracing)\n",
           (double)st.rays / st.trace_seconds / 1e6, st.trace_seconds);
    zt_image_release(img);
    rtcReleaseScene(raw.scene);
    rtcReleaseDevice(raw.device);
    bench_free_rays(&set);
    rscene_free(&rs);
    zt_scene_release(s);
    mesh_release(m);
    return 0;
}
