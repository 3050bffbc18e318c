#define _POSIX_C_SOURCE 200809L
/* Path tracer benchmark: speed on every scene, and the Cornell box's error
 * against the independent reference as a function of time.
 *
 *   bench_path [--scenes DIR]... [--reference FILE] [--quick]
 *
 * Prints tables; figures are recorded in BENCHMARKS.md with the command
 * line.  Compare figures as ratios within one run: the machine is noisy. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>

#include "zonetrace/zonetrace.h"

static zt_scene *load(const char *path)
{
    zt_error err;
    zt_error_clear(&err);
    zt_scene *s = NULL;
    if (zt_scene_load_file(path, &s, &err) != ZT_OK) {
        fprintf(stderr, "bench_path: %s\n", err.message);
        return NULL;
    }
    return s;
}

static zt_image *render(const zt_scene *s, int spp, int depth, zt_render_stats *st)
{
    zt_render_options o = zt_render_options_default();
    o.spp = spp;
    o.depth = depth;
    zt_image *img = NULL;
    zt_error err;
    zt_error_clear(&err);
    if (zt_render(s, &o, &img, st, &err) != ZT_OK) {
        fprintf(stderr, "bench_path: %s\n", err.message);
        return NULL;
    }
    return img;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void scene_table(const char *dir, int size, int spp)
{
    DIR *d = opendir(dir);
    if (!d) {
        printf("(%s: not found, skipped)\n", dir);
        return;
    }
    char *names[256];
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) && n < 256) {
        const char *dot = strrchr(e->d_name, '.');
        if (dot && !strcmp(dot, ".json") && !strstr(e->d_name, "motions"))
            names[n++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(names, (size_t)n, sizeof names[0], by_name);
    printf("\n%s at %dx%d, %d spp, depth 16\n", dir, size, size, spp);
    printf("%-42s %8s %10s %10s %8s\n", "scene", "seconds", "Msamples/s", "Mrays/s", "rays/smp");
    for (int i = 0; i < n; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        zt_scene *s = load(path);
        free(names[i]);
        if (!s)
            continue;
        zt_camera c = zt_scene_get_camera(s);
        zt_camera_set_resolution(&c, size, size, NULL);
        zt_scene_set_camera(s, &c);
        zt_render_stats st;
        zt_image *img = render(s, spp, 16, &st);
        if (img)
            printf("%-42s %8.3f %10.3f %10.2f %8.2f\n", path + strlen(dir) + 1, st.seconds,
                   st.samples / st.seconds / 1e6, st.rays / st.seconds / 1e6,
                   (double)st.rays / (double)st.samples);
        zt_image_release(img);
        zt_scene_release(s);
    }
}

static void error_curve(const char *scene_path, const char *ref_path, int max_spp)
{
    zt_error err;
    zt_error_clear(&err);
    zt_image *ref = NULL;
    if (zt_image_read(ref_path, &ref, &err) != ZT_OK) {
        printf("\n(reference %s unavailable: %s; error curve skipped)\n", ref_path, err.message);
        return;
    }
    zt_image *ref4 = zt_image_downsample(ref, 4);
    zt_scene *s = load(scene_path);
    if (!s || !ref4)
        return;
    printf("\n%s against %s (512x512, depth 16)\n", scene_path, ref_path);
    printf("%6s %8s %10s %10s %14s %10s %10s %10s\n", "spp", "seconds", "Mpaths/s", "Mrays/s",
           "rel_rmse", "rel_rmse4", "mean_r", "mean_ref_r");
    for (int spp = 1; spp <= max_spp; spp *= 2) {
        zt_render_stats st;
        zt_image *img = render(s, spp, 16, &st);
        if (!img)
            break;
        zt_compare_result r, r4;
        zt_image *img4 = zt_image_downsample(img, 4);
        zt_image_compare(img, ref, &r, NULL);
        zt_image_compare(img4, ref4, &r4, NULL);
        printf("%6d %8.3f %10.3f %10.2f %13.4f%% %9.4f%% %10.4f %10.4f\n", spp, st.seconds,
               st.samples / st.seconds / 1e6, st.rays / st.seconds / 1e6, 100 * r.rel_rmse,
               100 * r4.rel_rmse, r.mean_a[0], r.mean_b[0]);
        zt_image_release(img);
        zt_image_release(img4);
    }
    zt_scene_release(s);
    zt_image_release(ref);
    zt_image_release(ref4);
}

int main(int argc, char **argv)
{
    const char *dirs[8];
    int ndirs = 0, quick = 0, max_spp = 256;
    const char *ref = ZT_BENCH_SHARED "/reference/cornell-cycles-2048spp.pfm";
    const char *cornell = ZT_BENCH_SOURCE "/scenes/cornell.json";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--scenes") && i + 1 < argc && ndirs < 8)
            dirs[ndirs++] = argv[++i];
        else if (!strcmp(argv[i], "--reference") && i + 1 < argc)
            ref = argv[++i];
        else if (!strcmp(argv[i], "--max-spp") && i + 1 < argc)
            max_spp = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--quick"))
            quick = 1;
        else {
            fprintf(stderr, "usage: bench_path [--scenes DIR]... [--reference FILE] "
                            "[--max-spp N] [--quick]\n");
            return 1;
        }
    }
    if (ndirs == 0) {
        dirs[ndirs++] = ZT_BENCH_SOURCE "/scenes";
        dirs[ndirs++] = ZT_BENCH_SHARED "/scenes/retra";
    }
    printf("zonetrace %s path tracer benchmark\n", zt_version());
    for (int i = 0; i < ndirs; i++)
        scene_table(dirs[i], quick ? 128 : 256, quick ? 4 : 16);
    error_curve(cornell, ref, quick ? 4 : max_spp);
    return 0;
}
