/* zonetrace render --motions FILE: offline animation.  Frame k is the
 * scene at time T + k/F (T = --time, F = --fps), rendered with the same
 * options and seed, so the same command writes the same frames. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

/* Checks that pattern holds exactly one frame-number conversion (%d, %4d,
 * %04d) and otherwise only %% escapes.  Returns 1 if it has one, 0 if it
 * has none, -1 (with a message) if it is malformed. */
static int check_pattern(const char *pattern)
{
    int found = 0;
    for (const char *p = pattern; *p; p++) {
        if (*p != '%')
            continue;
        p++;
        if (*p == '%')
            continue;
        while (*p == '0')
            p++;
        int digits = 0;
        while (*p >= '0' && *p <= '9' && digits < 3) {
            p++;
            digits++;
        }
        if (*p != 'd') {
            cli_error("-o '%s': only %%d, %%0Nd or %%Nd (the frame number) and %%%% "
                      "may follow a %% sign", pattern);
            return -1;
        }
        if (found) {
            cli_error("-o '%s': more than one frame number in the name", pattern);
            return -1;
        }
        found = 1;
    }
    return found;
}

/* The file name of frame k (pattern already checked). */
static void frame_name(char *out, size_t n, const char *pattern, int k)
{
    size_t o = 0;
    for (const char *p = pattern; *p && o + 1 < n; p++) {
        if (*p != '%') {
            out[o++] = *p;
            continue;
        }
        p++;
        if (*p == '%') {
            out[o++] = '%';
            continue;
        }
        int zero = 0, width = 0;
        while (*p == '0') {
            zero = 1;
            p++;
        }
        while (*p >= '0' && *p <= '9')
            width = width * 10 + (*p++ - '0');
        int w = snprintf(out + o, n - o, zero ? "%0*d" : "%*d", width, k);
        if (w > 0)
            o += (size_t)w < n - o ? (size_t)w : n - o - 1;
    }
    out[o < n ? o : n - 1] = '\0';
}

int cli_animate(const char *scene_path, const zt_render_options *options,
                const zt_tonemap *tonemap, const char *output, int width, int height,
                const cli_animation *anim, int verbose, int quiet)
{
    if (!anim->motions) {
        cli_error("--frames, --fps and --time need --motions FILE");
        return EXIT_USAGE;
    }
    if (!strcmp(output, "-") && anim->frames > 1) {
        cli_error("-o -: several frames cannot go to standard output; give a "
                  "name with a frame number such as frame_%%04d.png");
        return EXIT_USAGE;
    }
    int has_number = strcmp(output, "-") ? check_pattern(output) : 0;
    if (has_number < 0)
        return EXIT_USAGE;
    if (anim->frames > 1 && !has_number) {
        cli_error("-o '%s' has no frame number: with --frames %d give a pattern "
                  "such as frame_%%04d.png", output, anim->frames);
        return EXIT_USAGE;
    }

    zt_error err;
    zt_error_clear(&err);
    zt_scene *scene0 = NULL, *scene = NULL;
    zt_motions *motions = NULL;
    int code = EXIT_OK;
    zt_status st = zt_scene_load_file(scene_path, &scene0, &err);
    if (st == ZT_OK && width) {
        zt_camera cam = zt_scene_get_camera(scene0);
        if (zt_camera_set_resolution(&cam, width, height, &err) != ZT_OK) {
            cli_error("%s", err.message);
            zt_scene_release(scene0);
            return EXIT_USAGE;
        }
        zt_scene_set_camera(scene0, &cam);
    }
    if (st == ZT_OK)
        st = zt_motions_load_file(anim->motions, &motions, &err);
    if (st == ZT_OK)
        st = zt_motions_check(motions, scene0, &err);
    if (st == ZT_OK && !(scene = zt_scene_clone(scene0))) {
        st = ZT_ERR_MEMORY;
        snprintf(err.message, sizeof err.message, "out of memory");
    }
    if (st != ZT_OK) {
        fprintf(stderr, "zonetrace: %s\n", err.message);
        code = cli_exit_code(st);
        goto done;
    }

    /* An interrupt lets the frame under way finish (a frame cut short would
     * not match its neighbours) and starts no other. */
    zt_render_options opt = *options;
    opt.stop = NULL;
    cli_interrupts_install("\nzonetrace: finishing the current frame, then stopping "
                           "(interrupt again to abort it)\n");
    double total_seconds = 0;
    uint64_t total_rays = 0;
    int frames_done = 0;
    for (int k = 0; k < anim->frames; k++) {
        if (cli_stop) {
            cli_error("interrupted: %d of %d frames written", frames_done, anim->frames);
            code = EXIT_INTERRUPTED;
            break;
        }
        double t = anim->time + k / anim->fps;
        char name[4096];
        if (has_number)
            frame_name(name, sizeof name, output, k);
        else
            snprintf(name, sizeof name, "%s", output);
        st = zt_motions_apply(motions, scene0, t, options->seed, scene, &err);
        if (st != ZT_OK) {
            cli_error("%s", err.message);
            code = cli_exit_code(st);
            goto done;
        }
        if (!quiet || verbose)
            fprintf(stderr, "frame %d/%d (t = %.3f s) -> %s%s", k + 1, anim->frames, t,
                    strcmp(name, "-") ? name : "(stdout)", verbose ? "\n" : "");
        cli_progress prog;
        cli_progress_init(&prog, verbose);
        opt.progress = cli_progress_callback;
        opt.progress_user = &prog;
        zt_image *img = NULL;
        zt_render_stats stats;
        st = zt_render(scene, &opt, &img, &stats, &err);
        cli_progress_finish(&prog);
        if (st == ZT_OK) {
            st = zt_image_write(img, name, tonemap, &err);
            zt_image_release(img);
        }
        if (st != ZT_OK) {
            if (!quiet && !verbose)
                fputc('\n', stderr);
            cli_error("frame %d: %s", k, err.message);
            code = cli_exit_code(st);
            goto done;
        }
        total_seconds += stats.seconds;
        total_rays += stats.rays;
        frames_done++;
        if (!quiet && !verbose)
            fprintf(stderr, ", %.2f s\n", stats.seconds);
        cli_report_stop(&opt, &stats, quiet);
    }
    if (!quiet && frames_done)
        fprintf(stderr, "rendered %d frame%s in %.3f s: %llu rays, %.2f Mrays/s\n",
                frames_done, frames_done == 1 ? "" : "s", total_seconds,
                (unsigned long long)total_rays,
                total_seconds > 0 ? total_rays / total_seconds / 1e6 : 0.0);
done:
    zt_scene_release(scene);
    zt_scene_release(scene0);
    zt_motions_release(motions);
    return code;
}
