/* Converged path-traced references at less cost: samples go where the
 * noise is.
 *
 *   bench_reference SCENE -o OUT.pfm [--size WxH] [--level L | --depth D]
 *                   [--spp N] [--seed S] [--noise NOISE.pfm] [--threads T]
 *                   [--motions FILE --time T [--motion-seed S]]
 *
 * A reference's error is the relative RMSE of the whole image, so what
 * matters is the sum over pixels of each pixel's variance.  A few pixels
 * (beside crossings, in corners, under small bright sources) hold most of
 * it: on triangletest's level 3 at 64 x 64 the 200 noisiest pixels (5%)
 * hold 72% of the image's variance.  With n_i samples at pixel i of standard deviation
 * sigma_i, sum sigma_i^2 / n_i at a fixed total is least when n_i is
 * proportional to sigma_i (Neyman's allocation).
 *
 * A pilot pass of N/8 samples per pixel estimates sigma_i; the rest of the
 * budget (N per pixel on average over the image, pilot included) is shared
 * in proportion to it, each pixel getting at least N/8 more.  The value
 * written is the mean of the second pass alone: its sample count depends on
 * the pilot, its samples do not, so it stays unbiased.  The second pass
 * runs in 16 batches per pixel, whose spread gives each pixel's variance of
 * the mean: --noise writes it (per channel), and the estimated relative
 * noise of the whole image is printed.
 *
 * The samples are the path tracer's own (path_trace_sample, the same
 * sampler and levels as `zonetrace render --method path`).  With --motions
 * the scene is the one `zonetrace render --motions FILE --time T` renders
 * (camera path included), so an animation's frames get references; the
 * brownian walks follow --motion-seed as render's follow its --seed. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camera.h"
#include "path/path_tracer.h"
#include "render/render_internal.h"
#include "util/sampler.h"
#include "zonetrace/zonetrace.h"

#define BATCHES 16

typedef struct job {
    const rscene *rs;
    const cam *c;
    path_params pp;
    uint64_t rays;
} job;

/* Samples [first, first + count) of pixel (x, y), summed per batch of
 * count / BATCHES (sum[b][rgb]; batches = 1 puts all in sum[0]). */
static void pixel_samples(job *j, int x, int y, uint32_t first, uint32_t count,
                          int batches, double (*sum)[3])
{
    path_pixel pix = path_pixel_make(sampler_hash3((uint32_t)x, (uint32_t)y, j->pp.seed));
    uint32_t per = count / (uint32_t)batches;
    uint64_t rays = 0;
    for (int b = 0; b < batches; b++) {
        sum[b][0] = sum[b][1] = sum[b][2] = 0.0;
        for (uint32_t k = 0; k < per; k++) {
            uint32_t s = first + (uint32_t)b * per + k;
            float u[2];
            uint32_t rev = sampler_reverse_bits(s);
            sampler_get2_seeded(pix.pair_seed[0], rev, u);
            vec3f org, dir;
            cam_ray(j->c, (float)x + u[0], (float)y + u[1], &org, &dir);
            vec3f l = path_trace_sample(j->rs, &j->pp, org, dir, &pix, s, rev, &rays);
            sum[b][0] += l.x;
            sum[b][1] += l.y;
            sum[b][2] += l.z;
        }
    }
#pragma omp atomic
    j->rays += rays;
}

static int usage(void)
{
    fprintf(stderr, "usage: bench_reference SCENE -o OUT.pfm [--size WxH] [--level L | --depth D]\n"
                    "                       [--spp N] [--seed S] [--noise NOISE.pfm] [--threads T]\n"
                    "                       [--motions FILE --time T [--motion-seed S]]\n");
    return 1;
}

/* The scene of `zonetrace render --motions FILE --time T` (its camera on
 * scene0's pixel grid), replacing scene0; NULL after a message. */
static zt_scene *scene_at_time(zt_scene *scene0, const char *motions_path, double t,
                               uint64_t seed)
{
    zt_error err;
    zt_error_clear(&err);
    zt_motions *m = NULL;
    zt_scene *moved = NULL;
    if (zt_motions_load_file(motions_path, &m, &err) == ZT_OK &&
        zt_motions_check(m, scene0, &err) == ZT_OK) {
        moved = zt_scene_clone(scene0);
        if (!moved)
            snprintf(err.message, sizeof err.message, "out of memory");
        else if (zt_motions_apply(m, scene0, t, seed, moved, &err) != ZT_OK) {
            zt_scene_release(moved);
            moved = NULL;
        }
    }
    if (!moved)
        fprintf(stderr, "bench_reference: %s\n", err.message);
    zt_motions_release(m);
    zt_scene_release(scene0);
    return moved;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL, *noise_out = NULL, *motions_path = NULL;
    int width = 0, height = 0, level = -1, depth = 16, threads = 0;
    long spp = 4096;
    unsigned long long seed = 0, motion_seed = 0;
    double time = 0.0;
    int have_time = 0; /* --time goes with --motions (the motions check its value) */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "-o") && more)
            out = argv[++i];
        else if (!strcmp(a, "--noise") && more)
            noise_out = argv[++i];
        else if (!strcmp(a, "--size") && more) {
            if (sscanf(argv[++i], "%dx%d", &width, &height) != 2 || width < 1 || height < 1)
                return usage();
        } else if (!strcmp(a, "--level") && more)
            level = atoi(argv[++i]);
        else if (!strcmp(a, "--depth") && more)
            depth = atoi(argv[++i]);
        else if (!strcmp(a, "--spp") && more)
            spp = atol(argv[++i]);
        else if (!strcmp(a, "--seed") && more)
            seed = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(a, "--threads") && more)
            threads = atoi(argv[++i]);
        else if (!strcmp(a, "--motions") && more)
            motions_path = argv[++i];
        else if (!strcmp(a, "--time") && more) {
            time = atof(argv[++i]);
            have_time = 1;
        }
        else if (!strcmp(a, "--motion-seed") && more)
            motion_seed = strtoull(argv[++i], NULL, 10);
        else if (a[0] != '-' && !scene_path)
            scene_path = a;
        else
            return usage();
    }
    if (!scene_path || !out || spp < 8 * BATCHES || spp > (1L << 30) || depth < 0 || level > 64 ||
        !motions_path != !have_time)
        return usage();

    zt_error err;
    zt_error_clear(&err);
    zt_scene *scene = NULL;
    if (zt_scene_load_file(scene_path, &scene, &err) != ZT_OK) {
        fprintf(stderr, "bench_reference: %s\n", err.message);
        return 2;
    }
    zt_camera zc = zt_scene_get_camera(scene);
    if (width && zt_camera_set_resolution(&zc, width, height, &err) != ZT_OK) {
        fprintf(stderr, "bench_reference: %s\n", err.message);
        return 1;
    }
    zt_scene_set_camera(scene, &zc);
    if (motions_path && !(scene = scene_at_time(scene, motions_path, time, motion_seed)))
        return 3;
    zt_render_options o = zt_render_options_default();
    zt_renderer *r = NULL;
    if (zt_renderer_create(scene, &o, &r, &err) != ZT_OK) {
        fprintf(stderr, "bench_reference: %s\n", err.message);
        return 5;
    }
    if (threads > 0)
        omp_set_num_threads(threads);

    cam c;
    cam_init(&c, &r->scene->camera);
    int w = r->scene->camera.width, h = r->scene->camera.height;
    size_t npx = (size_t)w * h;
    job j = {&r->rs, &c, {0, 0, 0}, 0};
    j.pp.min_level = level >= 0 ? level : 0;
    j.pp.max_level = level >= 0 ? level : depth;
    j.pp.seed = sampler_hash((uint32_t)seed ^ sampler_hash((uint32_t)(seed >> 32) + 0x9e3779b9U));

    /* Pilot: sigma of one sample, per pixel (the three channels' variances
     * summed), from BATCHES batch means. */
    uint32_t pilot = (uint32_t)(spp / 8 / BATCHES * BATCHES);
    double *sigma = calloc(npx, sizeof *sigma);
    uint32_t *count = calloc(npx, sizeof *count);
    float *mean = calloc(npx * 3, sizeof *mean), *var = calloc(npx * 3, sizeof *var);
    if (!sigma || !count || !mean || !var) {
        fprintf(stderr, "bench_reference: out of memory\n");
        return 5;
    }
    double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 4)
    for (size_t p = 0; p < npx; p++) {
        double sum[BATCHES][3];
        pixel_samples(&j, (int)(p % w), (int)(p / w), 0, pilot, BATCHES, sum);
        double v = 0.0;
        for (int ch = 0; ch < 3; ch++) {
            double m = 0.0, ss = 0.0;
            for (int b = 0; b < BATCHES; b++)
                m += sum[b][ch] / (pilot / BATCHES);
            m /= BATCHES;
            for (int b = 0; b < BATCHES; b++) {
                double d = sum[b][ch] / (pilot / BATCHES) - m;
                ss += d * d;
            }
            /* variance of a batch mean, times the batch size: of one sample */
            v += ss / (BATCHES - 1) * (pilot / BATCHES);
        }
        sigma[p] = sqrt(v);
    }
    double t_pilot = omp_get_wtime() - t0;

    /* Neyman's allocation of what is left, each pixel at least spp / 8. */
    double total = (double)spp * npx - (double)pilot * npx, floor_n = (double)pilot;
    double sig_sum = 0.0;
    for (size_t p = 0; p < npx; p++)
        sig_sum += sigma[p];
    double share = total - floor_n * npx;
    for (size_t p = 0; p < npx; p++) {
        double n = floor_n + (sig_sum > 0 ? share * sigma[p] / sig_sum : share / npx);
        n = fmin(n, 3.5e9);
        count[p] = (uint32_t)(ceil(n / BATCHES) * BATCHES);
    }

#pragma omp parallel for schedule(dynamic, 1)
    for (size_t p = 0; p < npx; p++) {
        double sum[BATCHES][3];
        uint32_t n = count[p];
        pixel_samples(&j, (int)(p % w), (int)(p / w), pilot, n, BATCHES, sum);
        for (int ch = 0; ch < 3; ch++) {
            double m = 0.0, ss = 0.0;
            for (int b = 0; b < BATCHES; b++)
                m += sum[b][ch];
            m /= n;
            for (int b = 0; b < BATCHES; b++) {
                double d = sum[b][ch] / (n / BATCHES) - m;
                ss += d * d;
            }
            mean[p * 3 + ch] = (float)m;
            var[p * 3 + ch] = (float)(ss / (BATCHES - 1) / BATCHES);
        }
    }
    double seconds = omp_get_wtime() - t0;

    /* The image's relative noise: sqrt(mean variance) / mean value. */
    double msum = 0.0, vsum = 0.0;
    for (size_t k = 0; k < npx * 3; k++) {
        msum += mean[k];
        vsum += var[k];
    }
    double mean_all = msum / (npx * 3);
    double noise = mean_all > 0 ? sqrt(vsum / (npx * 3)) / mean_all : 0.0;
    uint32_t nmax = 0;
    for (size_t p = 0; p < npx; p++)
        nmax = count[p] > nmax ? count[p] : nmax;

    zt_image *img = zt_image_create(w, h), *nimg = noise_out ? zt_image_create(w, h) : NULL;
    if (!img || (noise_out && !nimg)) {
        fprintf(stderr, "bench_reference: out of memory\n");
        return 5;
    }
    for (size_t p = 0; p < npx; p++) {
        float *px = zt_image_pixel(img, (int)(p % w), (int)(p / w));
        for (int ch = 0; ch < 3; ch++)
            px[ch] = mean[p * 3 + ch];
        if (nimg) {
            float *q = zt_image_pixel(nimg, (int)(p % w), (int)(p / w));
            for (int ch = 0; ch < 3; ch++)
                q[ch] = var[p * 3 + ch];
        }
    }
    if (zt_image_write(img, out, NULL, &err) != ZT_OK ||
        (nimg && zt_image_write(nimg, noise_out, NULL, &err) != ZT_OK)) {
        fprintf(stderr, "bench_reference: %s\n", err.message);
        return 4;
    }
    printf("%s %dx%d %s %d: %ld spp on average (pilot %u, most %u), %.1f s (pilot %.1f s), "
           "%.2f Mrays/s, estimated relative noise %.4f%%\n",
           scene_path, w, h, level >= 0 ? "level" : "depth", level >= 0 ? level : depth, spp,
           pilot, nmax, seconds, t_pilot, j.rays / seconds * 1e-6, 100.0 * noise);
    zt_image_release(img);
    zt_image_release(nimg);
    zt_renderer_release(r);
    zt_scene_release(scene);
    free(sigma);
    free(count);
    free(mean);
    free(var);
    return 0;
}
