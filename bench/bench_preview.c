#define _POSIX_C_SOURCE 200809L
/* The zone tracer's preview against its full image: time per image on one
 * forest, and the preview's error against a reference (optional).
 *
 *   bench_preview SCENE [--size WxH] [--forest FILE] [--frames N]
 *                 [--reference FILE] [--out FILE] [--full 0]
 *
 * Builds (or loads) the forest once, then renders N previews and one full
 * image of the scene's camera, and prints the median preview time and the
 * full image's time (Phase Two only; --full 0 leaves it out).  With --reference, both images'
 * rel_rmse against it.  Compare figures as ratios within one run. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "zonetrace/zonetrace.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void report_error(const char *what, const zt_image *img, const zt_image *ref)
{
    zt_compare_result c;
    zt_error err;
    if (zt_image_compare(img, ref, &c, &err) != ZT_OK) {
        fprintf(stderr, "bench_preview: %s\n", err.message);
        return;
    }
    printf("%s: rel_rmse %.3f%% against the reference\n", what, 100 * c.rel_rmse);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_preview SCENE [--size WxH] [--forest FILE] [--frames N] "
                        "[--reference FILE] [--out FILE]\n");
        return 1;
    }
    const char *scene_path = argv[1], *forest = NULL, *reference = NULL, *out = NULL;
    int w = 0, h = 0, frames = 10, full_image = 1;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--size"))
            sscanf(argv[i + 1], "%dx%d", &w, &h);
        else if (!strcmp(argv[i], "--forest"))
            forest = argv[i + 1];
        else if (!strcmp(argv[i], "--frames"))
            frames = atoi(argv[i + 1]) > 0 ? atoi(argv[i + 1]) : 1;
        else if (!strcmp(argv[i], "--reference"))
            reference = argv[i + 1];
        else if (!strcmp(argv[i], "--full"))
            full_image = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--out"))
            out = argv[i + 1];
    }
    zt_error err;
    zt_error_clear(&err);
    zt_scene *scene = NULL;
    if (zt_scene_load_file(scene_path, &scene, &err) != ZT_OK) {
        fprintf(stderr, "bench_preview: %s\n", err.message);
        return 2;
    }
    zt_camera cam = zt_scene_get_camera(scene);
    if (w > 0 && h > 0 && zt_camera_set_resolution(&cam, w, h, &err) != ZT_OK) {
        fprintf(stderr, "bench_preview: %s\n", err.message);
        return 1;
    }
    zt_scene_set_camera(scene, &cam);
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 3;
    o.forest_file = forest;
    zt_renderer *r = NULL;
    double t0 = now();
    if (zt_renderer_create(scene, &o, &r, &err) != ZT_OK) {
        fprintf(stderr, "bench_preview: %s\n", err.message);
        return 3;
    }
    printf("%s %dx%d: forest %s in %.2f s\n", scene_path, cam.width, cam.height,
           forest ? "loaded" : "built", now() - t0);
    zt_image *pre = zt_image_create(cam.width, cam.height);
    double *times = malloc((size_t)frames * sizeof *times);
    if (!pre || !times)
        return 7;
    for (int k = 0; k < frames; k++) {
        memset(pre->pixels, 0, (size_t)cam.width * cam.height * 3 * sizeof(float));
        double t = now();
        if (zt_renderer_preview(r, pre, NULL, &err) != ZT_OK) {
            fprintf(stderr, "bench_preview: %s\n", err.message);
            return 7;
        }
        times[k] = now() - t;
    }
    qsort(times, (size_t)frames, sizeof *times, cmp_double);
    printf("preview: median %.4f s of %d (%.1f per second)\n", times[frames / 2], frames,
           1.0 / times[frames / 2]);
    zt_image *full = NULL;
    zt_render_stats st;
    double t = now();
    if (full_image && zt_renderer_render(r, &full, &st, &err) != ZT_OK) {
        fprintf(stderr, "bench_preview: %s\n", err.message);
        return 7;
    }
    if (full)
        printf("full image: %.3f s, %.1f times the preview\n", now() - t,
               (now() - t) / times[frames / 2]);
    if (reference) {
        zt_image *ref = NULL;
        if (zt_image_read(reference, &ref, &err) != ZT_OK) {
            fprintf(stderr, "bench_preview: %s\n", err.message);
            return 2;
        }
        report_error("preview", pre, ref);
        if (full)
            report_error("full image", full, ref);
        zt_image_release(ref);
    }
    if (out && zt_image_write(pre, out, NULL, &err) != ZT_OK)
        fprintf(stderr, "bench_preview: %s\n", err.message);
    zt_image_release(pre);
    zt_image_release(full);
    free(times);
    zt_renderer_release(r);
    zt_scene_release(scene);
    return 0;
}
