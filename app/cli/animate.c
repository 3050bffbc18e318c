/* zonetrace render --motions FILE: offline animation.  Frame k is the
 * scene at time T + k/F (T = --time, F = --fps), rendered with the same
 * options and seed, so the same command writes the same frames.  When only
 * the camera moves, one renderer serves all of a process's frames. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cluster.h"

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

/* What a process sends rank 0 with its frame of a round. */
typedef struct frame_report {
    double seconds, rays;
    int rendered;
    int pad;
} frame_report;

/* How a process makes its frames.  When no light and no thing moves, the
 * scene is the same at every time: the renderer (its acceleration
 * structure, the zone tracer's forest) is made at the process's first
 * frame and later frames only set their camera, each giving the image
 * zt_render gives for that camera.  Otherwise every frame renders the
 * moved scene from scratch. */
typedef struct frame_maker {
    const zt_scene *scene0;
    zt_scene *scene;           /* the scene at the frame's time */
    const zt_motions *motions;
    const cli_animation *anim;
    zt_render_options opt;     /* its progress reports go to prog */
    cli_progress prog;         /* as long-lived as a renderer keeping opt */
    int verbose;
    int keep;                  /* one renderer for every frame */
    zt_renderer *r;
    double build_seconds;      /* making r */
} frame_maker;

/* Renders frame k into *img.  The frame that makes the renderer counts the
 * time it took in its stats. */
static zt_status render_frame(frame_maker *fm, int k, zt_image **img, zt_render_stats *stats,
                              zt_error *err)
{
    double t = fm->anim->time + k / fm->anim->fps;
    cli_progress_init(&fm->prog, fm->verbose);
    zt_status st;
    if (!fm->keep) {
        st = zt_motions_apply(fm->motions, fm->scene0, t, fm->opt.seed, fm->scene, err);
        if (st == ZT_OK)
            st = zt_render(fm->scene, &fm->opt, img, stats, err);
    } else {
        zt_camera cam;
        double built = 0;
        st = zt_motions_camera(fm->motions, fm->scene0, t, &cam, err);
        if (st == ZT_OK && !fm->r) {
            double t0 = cli_now();
            zt_scene_set_camera(fm->scene, &cam);
            st = zt_renderer_create(fm->scene, &fm->opt, &fm->r, err);
            built = fm->build_seconds = cli_now() - t0;
        } else if (st == ZT_OK) {
            st = zt_renderer_set_camera(fm->r, &cam, err);
        }
        if (st == ZT_OK)
            st = zt_renderer_render(fm->r, img, stats, err);
        stats->seconds += built;
    }
    cli_progress_finish(&fm->prog);
    return st;
}

int cli_animate(const char *scene_path, const zt_render_options *options,
                const zt_tonemap *tonemap, const char *output, int width, int height,
                const cli_animation *anim, int verbose, int quiet)
{
    int has_number = 0, code = EXIT_OK;
    if (!anim->motions) {
        cli_error("--frames, --fps and --time need --motions FILE");
        code = EXIT_USAGE;
    } else if (!strcmp(output, "-") && anim->frames > 1) {
        cli_error("-o -: several frames cannot go to standard output; give a "
                  "name with a frame number such as frame_%%04d.png");
        code = EXIT_USAGE;
    } else if ((has_number = strcmp(output, "-") ? check_pattern(output) : 0) < 0) {
        code = EXIT_USAGE;
    } else if (anim->frames > 1 && !has_number) {
        cli_error("-o '%s' has no frame number: with --frames %d give a pattern "
                  "such as frame_%%04d.png", output, anim->frames);
        code = EXIT_USAGE;
    }

    zt_error err;
    zt_error_clear(&err);
    zt_scene *scene0 = NULL, *scene = NULL;
    zt_motions *motions = NULL;
    zt_status st = code == EXIT_OK ? zt_scene_load_file(scene_path, &scene0, &err) : ZT_OK;
    if (code == EXIT_OK && st == ZT_OK && width) {
        zt_camera cam = zt_scene_get_camera(scene0);
        if (zt_camera_set_resolution(&cam, width, height, &err) != ZT_OK) {
            cli_error("%s", err.message);
            code = EXIT_USAGE;
        } else {
            zt_scene_set_camera(scene0, &cam);
        }
    }
    if (code == EXIT_OK && st == ZT_OK)
        st = zt_motions_load_file(anim->motions, &motions, &err);
    if (code == EXIT_OK && st == ZT_OK)
        st = zt_motions_check(motions, scene0, &err);
    /* A camera path that degenerates between keys is found before any work. */
    int has_path = code == EXIT_OK && st == ZT_OK && zt_motions_camera_path(motions, NULL);
    for (int k = 0; has_path && st == ZT_OK && k < anim->frames; k++) {
        zt_camera cam;
        st = zt_motions_camera(motions, scene0, anim->time + k / anim->fps, &cam, &err);
    }
    if (code == EXIT_OK && st == ZT_OK && !(scene = zt_scene_clone(scene0))) {
        st = ZT_ERR_MEMORY;
        snprintf(err.message, sizeof err.message, "out of memory");
    }
    if (code == EXIT_OK && st != ZT_OK) {
        cli_error("%s", err.message);
        code = cli_exit_code(st);
    }
    /* Under mpirun all processes go on from here, or none. */
    code = cluster_agree(code);
    if (code != EXIT_OK)
        goto done;

    /* Frames are dealt out to the processes in rounds, frame first + rank
     * to each, and rank 0 writes a round's frames in order.  An interrupt
     * lets the frames under way finish (a frame cut short would not match
     * its neighbours) and starts no other round.  Each frame is rendered
     * whole by one process, so it is the frame one process alone makes. */
    frame_maker fm = {scene0, scene, motions, anim, *options, {0}, verbose,
                      !zt_motions_moves_objects(motions), NULL, 0};
    fm.opt.stop = NULL;
    fm.opt.progress = cli_progress_callback;
    fm.opt.progress_user = &fm.prog;
    const zt_render_options *opt = &fm.opt;
    if (verbose && cluster_rank() == 0) {
        int keys = 0;
        char path[64] = "no camera path";
        if (zt_motions_camera_path(motions, &keys))
            snprintf(path, sizeof path, "a camera path of %d keys", keys);
        fprintf(stderr, "motions: %d of lights and things, %s: %s\n", zt_motions_count(motions),
                path, fm.keep ? "the scene stands still, one renderer for every frame"
                              : "the scene is prepared again for every frame");
    }
    cli_interrupts_install("\nzonetrace: finishing the current frame, then stopping "
                           "(interrupt again to abort it)\n");
    const int ranks = cluster_ranks(), rank = cluster_rank();
    zt_camera cam = zt_scene_get_camera(scene0);
    size_t floats = 3 * (size_t)cam.width * (size_t)cam.height;
    size_t bytes = sizeof(frame_report) + floats * sizeof(float);
    unsigned char *mine = ranks > 1 ? calloc(1, bytes) : NULL;
    unsigned char *all = ranks > 1 && rank == 0 ? malloc(bytes * (size_t)ranks) : NULL;
    if (ranks > 1 && (!mine || (rank == 0 && !all)))
        cluster_abort(EXIT_MEMORY, "out of memory for a round of frames");
    double total_seconds = 0;
    uint64_t total_rays = 0;
    int frames_done = 0;
    for (int first = 0; first < anim->frames && code == EXIT_OK; first += ranks) {
        if (cli_stop)
            cli_error("interrupted: %d of %d frames written", frames_done, anim->frames);
        if ((code = cluster_agree(cli_stop ? EXIT_INTERRUPTED : EXIT_OK)) != EXIT_OK)
            break;
        int k = first + rank;
        char name[4096];
        if (has_number)
            frame_name(name, sizeof name, output, k);
        else
            snprintf(name, sizeof name, "%s", output);
        if (ranks == 1 && (!quiet || verbose))
            fprintf(stderr, "frame %d/%d (t = %.3f s) -> %s%s", k + 1, anim->frames,
                    anim->time + k / anim->fps, strcmp(name, "-") ? name : "(stdout)",
                    verbose ? "\n" : "");
        zt_image *img = NULL;
        zt_render_stats stats;
        memset(&stats, 0, sizeof stats);
        st = k < anim->frames ? render_frame(&fm, k, &img, &stats, &err) : ZT_OK;
        if (st != ZT_OK) {
            if (ranks == 1 && !quiet && !verbose)
                fputc('\n', stderr);
            cli_error("frame %d: %s", k, err.message);
        }
        if ((code = cluster_agree(cli_exit_code(st))) != EXIT_OK) {
            zt_image_release(img);
            break;
        }
        if (ranks > 1) {
            frame_report rep = {stats.seconds, (double)stats.rays, img != NULL, 0};
            memcpy(mine, &rep, sizeof rep);
            if (img)
                memcpy(mine + sizeof rep, img->pixels, floats * sizeof(float));
            zt_image_release(img);
            img = NULL;
            if (cluster_gather(mine, bytes, all) != 0)
                cluster_abort(EXIT_FAILURE_OTHER, "could not send a frame to process 0");
        }
        /* Rank 0 writes the round's frames (one: its own, in one process). */
        for (int j = 0; rank == 0 && j < ranks && code == EXIT_OK && first + j < anim->frames;
             j++) {
            int kj = first + j;
            zt_image *out = img;
            if (ranks > 1) {
                frame_report rep;
                memcpy(&rep, all + (size_t)j * bytes, sizeof rep);
                stats.seconds = rep.seconds;
                stats.rays = (uint64_t)rep.rays;
                out = zt_image_create(cam.width, cam.height);
                if (!out) {
                    cli_error("out of memory for frame %d", kj);
                    code = EXIT_MEMORY;
                    break;
                }
                memcpy(out->pixels, all + (size_t)j * bytes + sizeof rep, floats * sizeof(float));
                if (has_number)
                    frame_name(name, sizeof name, output, kj);
                if (!quiet || verbose)
                    fprintf(stderr, "frame %d/%d (t = %.3f s) -> %s", kj + 1, anim->frames,
                            anim->time + kj / anim->fps, strcmp(name, "-") ? name : "(stdout)");
            }
            st = zt_image_write(out, name, tonemap, &err);
            zt_image_release(out);
            img = NULL;
            if (st != ZT_OK) {
                if (!quiet || verbose)
                    fputc('\n', stderr);
                cli_error("frame %d: %s", kj, err.message);
                code = cli_exit_code(st);
                break;
            }
            total_seconds += stats.seconds;
            total_rays += stats.rays;
            frames_done++;
            if ((!quiet && !verbose) || (ranks > 1 && verbose))
                fprintf(stderr, ", %.2f s\n", stats.seconds);
            else if (verbose) /* its name went before the progress lines */
                fprintf(stderr, "frame %d/%d: %.2f s\n", kj + 1, anim->frames, stats.seconds);
            cli_report_stop(opt, &stats, quiet);
        }
        zt_image_release(img);
        code = cluster_agree(code);
    }
    free(mine);
    free(all);
    if (!quiet && frames_done) {
        const char *what = opt->method == ZT_METHOD_ZONE ? "forest built" : "scene prepared";
        char how[160];
        if (fm.keep)
            snprintf(how, sizeof how, "%s once%s for %d frame%s (%.3f s%s)", what,
                     ranks > 1 ? " per process" : "", frames_done, frames_done == 1 ? "" : "s",
                     fm.build_seconds, ranks > 1 ? " on process 0" : "");
        else
            snprintf(how, sizeof how, "%s for every frame (lights or things move)", what);
        fprintf(stderr, "rendered %d frame%s in %.3f s%s: %llu rays, %.2f Mrays/s; %s\n",
                frames_done, frames_done == 1 ? "" : "s", total_seconds,
                ranks > 1 ? " of rendering over the processes" : "",
                (unsigned long long)total_rays,
                total_seconds > 0 ? total_rays / total_seconds / 1e6 : 0.0, how);
    }
    zt_renderer_release(fm.r);
done:
    zt_scene_release(scene);
    zt_scene_release(scene0);
    zt_motions_release(motions);
    return code;
}
