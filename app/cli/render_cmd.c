/* zonetrace render: load a scene, render it, write the image. */
#define _POSIX_C_SOURCE 200809L
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "cluster.h"
#include "parse.h"

static void render_usage(FILE *f)
{
    fprintf(f,
"usage: zonetrace render SCENE [options]\n"
"\n"
"Renders SCENE (a scene file in the Retra/Silence JSON format) to an image.\n"
"\n"
"Output:\n"
"  -o, --output FILE     image to write (default image.png); the format follows\n"
"                        the extension: .pfm .exr (linear HDR), .png .ppm (8-bit);\n"
"                        '-' writes PPM to standard output\n"
"      --size WxH        pixel grid (default: the scene's gridresolution); the\n"
"                        screen rectangle stays the same\n"
"      --exposure EV     8-bit outputs: scale by 2^EV (default: automatic, the\n"
"                        99th percentile of luminance maps to 0.9)\n"
"      --gamma G         8-bit outputs: x^(1/G) (default: the sRGB curve)\n"
"\n"
"Light transport:\n"
"      --method M        path (Monte Carlo reference, default) or zone\n"
"      --depth D         at most D scattering events (default 16 for path,\n"
"                        3 for zone)\n"
"      --level L         only light that scattered exactly L times\n"
"                        (0 = lights seen directly, 1 = direct light, ...)\n"
"      --lights-off LIST switch off lights by index, e.g. 0,2 (they stay as\n"
"                        black surfaces)\n"
"\n"
"Path tracer:\n"
"      --spp N           samples per pixel (default 64)\n"
"      --seed S          sampler seed (default 0); same seed, same image\n"
"\n"
"Zone tracer:\n"
"      --strategy S      pixel (default) or zone\n"
"      --cutoff X        prune zones whose power bound is at most X (default 0)\n"
"      --quality Q       discretisation level, higher is finer (default 2)\n"
"      --save-forest FILE\n"
"                        write the forest (Phase One: zones, occluder lists,\n"
"                        maps) to FILE; it does not depend on the camera\n"
"      --load-forest FILE\n"
"                        read the forest from FILE instead of building it: FILE\n"
"                        must be for this scene with the same depth/level,\n"
"                        cutoff, quality and lights-off (docs/zone-tracer.md)\n"
"\n"
"Animation (docs/viewer.md):\n"
"      --motions FILE    move objects and the camera as the motions file says;\n"
"                        renders the scene at --time (default 0)\n"
"      --frames N        render N frames, frame k at time T + k/F; -o must hold\n"
"                        a frame number such as frame_%%04d.png\n"
"      --fps F           frames per second of the animation (default 24)\n"
"      --time T          time of the first frame in seconds (default 0)\n"
"\n"
"Long renders (docs/long-renders.md):\n"
"      --time-limit S    finish within S seconds of starting, writing the image\n"
"                        then: the path tracer renders whole passes of samples\n"
"                        while the next fits (--spp is then an upper bound, at\n"
"                        least 1 is taken); the zone tracer builds the levels\n"
"                        that fit and says which depth it reached.  In an\n"
"                        animation, S is per frame\n"
"      --checkpoint FILE path tracer: save the running sums to FILE every few\n"
"                        minutes, when interrupted and at the end\n"
"      --checkpoint-every S\n"
"                        seconds between checkpoints (default 300)\n"
"      --resume FILE     continue the render saved in FILE (same scene, camera,\n"
"                        seed, depth, level, lights-off; --spp at least its\n"
"                        count) and keep checkpointing into it: the image is\n"
"                        the same, bit for bit, as an uninterrupted render\n"
"      --max-memory SIZE refuse, before any work, a render estimated to need\n"
"                        more than SIZE (e.g. 8G; default: the physical memory)\n"
"  Ctrl-C or SIGTERM once: the path tracer finishes its pass and writes the\n"
"  image of the samples done (and the checkpoint); the zone tracer builds no\n"
"  further level; an animation finishes its frame.  Twice: abort at once.\n"
"\n"
"Running:\n"
"      --threads T       threads (default: all cores)\n"
"  -v, --verbose         progress with ETA on stderr, and details\n"
"  -q, --quiet           no statistics line\n"
"  -h, --help            this text\n"
"  Under mpirun (docs/cluster.md) the render is split over the processes and\n"
"  the image is the one a single process writes; rank 0 alone prints and writes\n"
"  files, every process reads the scene; --threads is per process.\n"
"\n"
"Exit status: 0 done (also when a time limit cut it short), 1 bad arguments,\n"
"2 unreadable input, 3 invalid input (scene, model, forest or checkpoint\n"
"file), 4 unwritable output, 5 needs more memory than allowed (refused before\n"
"the work, or when the zone tracer's caustic photons outgrow their estimate),\n"
"6 not supported by this build, 7 other failure (or interrupted\n"
"before any image), 8 interrupted: the image so far was written, 130 or 143\n"
"interrupted twice (SIGINT, SIGTERM): nothing written.\n");
}

enum {
    OPT_SIZE = 256, OPT_SPP, OPT_DEPTH, OPT_LEVEL, OPT_SEED, OPT_THREADS,
    OPT_METHOD, OPT_GAMMA, OPT_EXPOSURE, OPT_STRATEGY, OPT_CUTOFF, OPT_QUALITY,
    OPT_LIGHTS_OFF, OPT_MOTIONS, OPT_FRAMES, OPT_FPS, OPT_TIME,
    OPT_SAVE_FOREST = 400, OPT_LOAD_FOREST,
    OPT_TIME_LIMIT = 500, OPT_CHECKPOINT, OPT_CHECKPOINT_EVERY, OPT_RESUME, OPT_MAX_MEMORY
};

static const struct option long_options[] = {
    {"output", required_argument, 0, 'o'},
    {"size", required_argument, 0, OPT_SIZE},
    {"spp", required_argument, 0, OPT_SPP},
    {"depth", required_argument, 0, OPT_DEPTH},
    {"level", required_argument, 0, OPT_LEVEL},
    {"seed", required_argument, 0, OPT_SEED},
    {"threads", required_argument, 0, OPT_THREADS},
    {"method", required_argument, 0, OPT_METHOD},
    {"gamma", required_argument, 0, OPT_GAMMA},
    {"exposure", required_argument, 0, OPT_EXPOSURE},
    {"strategy", required_argument, 0, OPT_STRATEGY},
    {"cutoff", required_argument, 0, OPT_CUTOFF},
    {"quality", required_argument, 0, OPT_QUALITY},
    {"lights-off", required_argument, 0, OPT_LIGHTS_OFF},
    {"save-forest", required_argument, 0, OPT_SAVE_FOREST},
    {"load-forest", required_argument, 0, OPT_LOAD_FOREST},
    {"motions", required_argument, 0, OPT_MOTIONS},
    {"frames", required_argument, 0, OPT_FRAMES},
    {"fps", required_argument, 0, OPT_FPS},
    {"time", required_argument, 0, OPT_TIME},
    {"time-limit", required_argument, 0, OPT_TIME_LIMIT},
    {"checkpoint", required_argument, 0, OPT_CHECKPOINT},
    {"checkpoint-every", required_argument, 0, OPT_CHECKPOINT_EVERY},
    {"resume", required_argument, 0, OPT_RESUME},
    {"max-memory", required_argument, 0, OPT_MAX_MEMORY},
    {"verbose", no_argument, 0, 'v'},
    {"quiet", no_argument, 0, 'q'},
    {"help", no_argument, 0, 'h'},
    {0, 0, 0, 0}
};

/* Whether the image can be written there, checked before a long render:
 * a known extension and a writable directory (writes go through a
 * temporary file beside the target). */
static int output_writable(const char *path)
{
    if (!strcmp(path, "-"))
        return 1;
    if (zt_image_format_from_path(path) == ZT_FORMAT_UNKNOWN) {
        cli_error("cannot tell the image format of '%s': use .png, .ppm, .pfm or .exr", path);
        return -1;
    }
    return cli_can_replace(path, "");
}

/* Where Phase Two's time went, in thread-seconds (-v). */
static void print_phase_two_split(const zt_render_stats *s)
{
    static const char *const kind[ZT_PIXEL_KINDS] = {
        "one surface", "curved 2x2", "mesh detail 8x8", "busy shadow 2x2", "edge", "fine edge"};
    double shaded = 0;
    for (int k = 0; k < ZT_PIXEL_KINDS; k++)
        shaded += s->p2_shade_seconds[k];
    double all = s->p2_lists_seconds + s->p2_records_seconds + shaded;
    if (!(all > 0))
        return;
    fprintf(stderr, "phase two split (thread-seconds): %.3f s: samples found %.3f (%.0f%%), "
                    "gathers at pixel centres %.3f (%.0f%%), shading %.3f (%.0f%%)\n",
            all, s->p2_lists_seconds, 100 * s->p2_lists_seconds / all, s->p2_records_seconds,
            100 * s->p2_records_seconds / all, shaded, 100 * shaded / all);
    for (int k = 0; k < ZT_PIXEL_KINDS; k++)
        if (s->p2_pixels[k])
            fprintf(stderr, "  shading %-16s %8llu pixels %9llu samples %8.3f s (%.0f%%)\n",
                    kind[k], (unsigned long long)s->p2_pixels[k],
                    (unsigned long long)s->p2_samples[k], s->p2_shade_seconds[k],
                    100 * s->p2_shade_seconds[k] / all);
}

/* The zone tracer's forest figures and phase times (-v). */
static void print_zone_stats(const zt_render_stats *s, const char *loaded_from)
{
    fprintf(stderr, "zones:");
    for (int l = 0; l < 32; l++)
        if (s->zones_per_level[l])
            fprintf(stderr, " level %d: %llu,", l, (unsigned long long)s->zones_per_level[l]);
    fprintf(stderr, " total %llu; pruned %llu\n", (unsigned long long)s->zones,
            (unsigned long long)s->zones_pruned);
    if (s->cuts || s->nodes_gathered)
        fprintf(stderr,
                "transfer: %llu nodes gathered; %llu cuts, %llu (%.1f%%) reached the cluster "
                "limit, %llu started from a neighbour's\n",
                (unsigned long long)s->nodes_gathered, (unsigned long long)s->cuts,
                (unsigned long long)s->cuts_capped,
                s->cuts ? 100.0 * (double)s->cuts_capped / (double)s->cuts : 0.0,
                (unsigned long long)s->cuts_shared);
    if (s->sky_portals)
        fprintf(stderr, "sky portals: %d windows of panes\n", s->sky_portals);
    fprintf(stderr,
            "forest memory: %llu bytes (%.1f MiB: zones, occluder lists, maps and photons)\n",
            (unsigned long long)s->memory_bytes, s->memory_bytes / 1048576.0);
    if (s->forest_loaded)
        fprintf(stderr, "phase one: read from %s in %.3f s; phase two: %.3f s\n",
                loaded_from, s->phase_one_seconds, s->phase_two_seconds);
    else
        fprintf(stderr, "phase one: %.3f s; phase two: %.3f s\n", s->phase_one_seconds,
                s->phase_two_seconds);
    print_phase_two_split(s);
}

/* zt_render, keeping the renderer long enough to save its forest (written
 * right after Phase One, so a cancelled render still leaves it). */
static zt_status render_saving_forest(const zt_scene *scene, const zt_render_options *opt,
                                      const char *forest_out, zt_image **out,
                                      zt_render_stats *stats, zt_error *err)
{
    memset(stats, 0, sizeof *stats);
    *out = NULL;
    double t0 = cli_now();
    zt_renderer *r = NULL;
    zt_status st = zt_renderer_create(scene, opt, &r, err);
    if (st == ZT_OK && cluster_rank() == 0)
        st = zt_renderer_save_forest(r, forest_out, err);
    zt_image *img = NULL;
    if (st == ZT_OK) {
        zt_camera cam = zt_scene_get_camera(scene);
        img = zt_image_create(cam.width, cam.height);
        if (!img) {
            st = ZT_ERR_MEMORY;
            snprintf(err->message, sizeof err->message, "out of memory for the image");
        }
    }
    if (st == ZT_OK)
        st = zt_renderer_accumulate(r, 0, 1, img, stats, err);
    zt_renderer_release(r);
    if (st != ZT_OK) {
        zt_image_release(img);
        return st;
    }
    stats->seconds = cli_now() - t0;
    *out = img;
    return ZT_OK;
}

/* A render as the command line asked for it, and its loaded scene. */
typedef struct render_job {
    zt_render_options opt;
    zt_tonemap tm;
    const char *output, *scene_path, *forest_out;
    int width, height, verbose, quiet, help;
    double time_limit;
    cli_animation anim;
    zt_scene *scene; /* NULL for an animation, which loads its own */
} render_job;

/* Reads the options and loads the scene: everything that can fail before
 * the work.  Returns an exit code (after a message). */
static int render_prepare(int argc, char **argv, render_job *job)
{
    zt_render_options opt = zt_render_options_default();
    zt_tonemap tm = zt_tonemap_default();
    const char *output = "image.png";
    int width = 0, height = 0, verbose = 0, quiet = 0, depth_given = 0;
    const char *forest_out = NULL, *checkpoint = NULL, *resume = NULL;
    unsigned long long seed = 0, max_memory = 0;
    double time_limit = 0;
    cli_animation anim = {NULL, 1, 24.0, 0.0, 0};
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":o:vqh", long_options, NULL)) != -1) {
        int ok = 1;
        switch (c) {
        case 'o': output = optarg; break;
        case OPT_SIZE: ok = parse_size("--size", optarg, &width, &height); break;
        case OPT_SPP: ok = parse_int("--spp", optarg, 1, 1 << 24, &opt.spp); break;
        case OPT_DEPTH: ok = parse_int("--depth", optarg, 0, 1024, &opt.depth); depth_given = 1; break;
        case OPT_LEVEL: ok = parse_int("--level", optarg, 0, 1024, &opt.level); break;
        case OPT_SEED: ok = parse_u64("--seed", optarg, &seed); opt.seed = seed; break;
        case OPT_THREADS: ok = parse_int("--threads", optarg, 1, 1024, &opt.threads); break;
        case OPT_METHOD:
            if (!strcmp(optarg, "path")) opt.method = ZT_METHOD_PATH;
            else if (!strcmp(optarg, "zone")) opt.method = ZT_METHOD_ZONE;
            else { cli_error("--method expects 'path' or 'zone', not '%s'", optarg); ok = 0; }
            break;
        case OPT_STRATEGY:
            if (!strcmp(optarg, "pixel")) opt.strategy = ZT_STRATEGY_PIXEL;
            else if (!strcmp(optarg, "zone")) opt.strategy = ZT_STRATEGY_ZONE;
            else { cli_error("--strategy expects 'pixel' or 'zone', not '%s'", optarg); ok = 0; }
            break;
        case OPT_GAMMA: ok = parse_double("--gamma", optarg, 0.01, 100, &tm.gamma); break;
        case OPT_EXPOSURE:
            ok = parse_double("--exposure", optarg, -100, 100, &tm.exposure);
            tm.auto_exposure = 0;
            break;
        case OPT_CUTOFF: ok = parse_double("--cutoff", optarg, 0, 1e30, &opt.cutoff); break;
        case OPT_QUALITY: ok = parse_int("--quality", optarg, 0, 16, &opt.quality); break;
        case OPT_LIGHTS_OFF:
            ok = parse_int_list("--lights-off", optarg, opt.lights_off, ZT_MAX_LIGHTS_OFF,
                                &opt.lights_off_count);
            break;
        case OPT_SAVE_FOREST: forest_out = optarg; break;
        case OPT_LOAD_FOREST: opt.forest_file = optarg; break;
        case OPT_MOTIONS: anim.motions = optarg; anim.given = 1; break;
        case OPT_FRAMES: ok = parse_int("--frames", optarg, 1, 1000000, &anim.frames); anim.given = 1; break;
        case OPT_FPS: ok = parse_double("--fps", optarg, 1e-3, 1e6, &anim.fps); anim.given = 1; break;
        case OPT_TIME: ok = parse_double("--time", optarg, 0, 1e9, &anim.time); anim.given = 1; break;
        case OPT_TIME_LIMIT: ok = parse_double("--time-limit", optarg, 1e-3, 1e9, &time_limit); break;
        case OPT_CHECKPOINT: checkpoint = optarg; break;
        case OPT_CHECKPOINT_EVERY:
            ok = parse_double("--checkpoint-every", optarg, 1e-3, 1e9, &opt.checkpoint_seconds);
            break;
        case OPT_RESUME: resume = optarg; break;
        case OPT_MAX_MEMORY: ok = parse_bytes("--max-memory", optarg, &max_memory); break;
        case 'v': verbose = 1; break;
        case 'q': quiet = 1; break;
        case 'h': render_usage(stdout); job->help = 1; return EXIT_OK;
        case ':': cli_error("option '%s' needs a value", argv[optind - 1]); ok = 0; break;
        default: cli_error("unknown option '%s'", argv[optind - 1]); ok = 0; break;
        }
        if (!ok) {
            fprintf(stderr, "Try 'zonetrace render --help'.\n");
            return EXIT_USAGE;
        }
    }
    if (optind >= argc) {
        cli_error("no scene file given");
        fprintf(stderr, "Try 'zonetrace render --help'.\n");
        return EXIT_USAGE;
    }
    if (argc - optind > 1) {
        cli_error("one scene file at a time ('%s' and '%s' given)", argv[optind], argv[optind + 1]);
        return EXIT_USAGE;
    }
    const char *scene_path = argv[optind];
    if (opt.method == ZT_METHOD_ZONE && !depth_given)
        opt.depth = 3;
    if (opt.level > opt.depth) {
        if (depth_given) {
            cli_error("--level %d is deeper than --depth %d (levels count from 0)",
                      opt.level, opt.depth);
            return EXIT_USAGE;
        }
        opt.depth = opt.level;
    }
    if ((forest_out || opt.forest_file) && opt.method != ZT_METHOD_ZONE) {
        cli_error("--save-forest and --load-forest need --method zone");
        return EXIT_USAGE;
    }
    if ((forest_out || opt.forest_file) && anim.given) {
        cli_error("--save-forest and --load-forest render one image: objects that move "
                  "(--motions) need a forest per frame");
        return EXIT_USAGE;
    }
    if (long_render_options(&opt, checkpoint, resume, time_limit, max_memory, &anim,
                            forest_out != NULL) != EXIT_OK)
        return EXIT_USAGE;
    int w = output_writable(output);
    if (w <= 0)
        return w < 0 ? EXIT_USAGE : EXIT_UNWRITABLE;
    /* Only rank 0 speaks (cluster.h). */
    if (cluster_rank() > 0) {
        verbose = 0;
        quiet = 1;
    }
    *job = (render_job){opt, tm, output, scene_path, forest_out, width, height, verbose,
                        quiet, 0, time_limit, anim, NULL};
    if (anim.given)
        return EXIT_OK;

    zt_error err;
    zt_error_clear(&err);
    zt_status st = zt_scene_load_file(scene_path, &job->scene, &err);
    if (st != ZT_OK) {
        cli_error("%s", err.message);
        return cli_exit_code(st);
    }
    if (width) {
        zt_camera cam = zt_scene_get_camera(job->scene);
        if (zt_camera_set_resolution(&cam, width, height, &err) != ZT_OK) {
            cli_error("%s", err.message);
            return EXIT_USAGE;
        }
        zt_scene_set_camera(job->scene, &cam);
    }
    return EXIT_OK;
}

static void print_scene(const render_job *job)
{
    const zt_render_options *o = &job->opt;
    zt_scene_info info;
    zt_scene_get_info(job->scene, &info);
    zt_camera cam = zt_scene_get_camera(job->scene);
    fprintf(stderr, "scene %s: %d lights (%d parts), %d things (%d parts), %dx%d\n",
            job->scene_path, info.lights, info.light_parts, info.things, info.thing_parts,
            cam.width, cam.height);
    if (info.meshes)
        fprintf(stderr, "meshes: %d, %lld triangles (%lld degenerate ones skipped)\n",
                info.meshes, info.mesh_triangles, info.skipped_triangles);
    if (info.replaced_normals)
        fprintf(stderr, "note: %lld vertex normals of the models were not finite or "
                "zero and were replaced by the faces' normals\n", info.replaced_normals);
    if (info.rough_materials)
        fprintf(stderr, "rough model materials: %d (GGX lobes)\n", info.rough_materials);
    if (info.rough_lobes)
        fprintf(stderr, "rough materials: %d (GGX lobes)\n", info.rough_lobes);
    if (info.panes)
        fprintf(stderr, "note: %d materials are thin panes: light crosses them undeviated "
                "(docs/scene-format.md, \"thin\")\n", info.panes);
    if (info.alpha_masks || info.alpha_blends)
        fprintf(stderr, "alpha: %d masked materials (holes below the cutoff), %d with partial "
                "coverage (light passes by the uncovered share)\n", info.alpha_masks,
                info.alpha_blends);
    if (info.alpha_fallbacks)
        fprintf(stderr, "note: %d model alpha cutoffs were not in [0, 1] and were clamped (%s)\n",
                info.alpha_fallbacks, info.alpha_problem);
    if (info.missing_textures)
        fprintf(stderr, "note: %d model textures are missing or unreadable and were left "
                "out (%s)\n", info.missing_textures, info.texture_problem);
    if (info.map_fallbacks)
        fprintf(stderr, "note: %d model normal, roughness, metal or emissive maps were left out, "
                "the materials' factors and the interpolated normals taking their place (%s)\n",
                info.map_fallbacks, info.map_problem);
    if (info.emissive_pieces)
        fprintf(stderr, "emissive textures: %lld triangles added, cutting emissive triangles "
                "where their texture varies\n", info.emissive_pieces);
    if (info.unused[0])
        fprintf(stderr, "note: model materials have what is not used yet: %s\n", info.unused);
    fprintf(stderr, "method %s, depth %d, level %s%d\n",
            o->method == ZT_METHOD_PATH ? "path" : "zone", o->depth,
            o->level < 0 ? "all up to " : "", o->level < 0 ? o->depth : o->level);
    if (o->method == ZT_METHOD_ZONE)
        fprintf(stderr, "zone tracer: strategy %s, quality %d, cutoff %g%s%s\n",
                o->strategy == ZT_STRATEGY_ZONE ? "zone" : "pixel", o->quality, o->cutoff,
                o->forest_file ? ", forest from " : "", o->forest_file ? o->forest_file : "");
    if (cluster_ranks() > 1)
        fprintf(stderr, "processes: %d (MPI); --threads is per process\n", cluster_ranks());
}

/* Renders the prepared scene and writes the image.  Returns an exit code. */
static int render_image(render_job *job)
{
    zt_render_options opt = job->opt;
    zt_error err;
    zt_error_clear(&err);
    cli_progress prog;
    cli_progress_init(&prog, job->verbose);
    opt.progress = cli_progress_callback;
    opt.progress_user = &prog;
    opt.share = cluster_share();
    if (job->verbose)
        print_scene(job);
    zt_image *img = NULL;
    zt_render_stats stats;
    cli_interrupts_install(opt.method == ZT_METHOD_PATH
                               ? "\nzonetrace: stopping after the current pass (interrupt "
                                 "again to abort with nothing written)\n"
                               : "\nzonetrace: building no further level, then rendering "
                                 "(interrupt again to abort with nothing written)\n");
    opt.stop = &cli_stop;
    if (job->time_limit > 0) {
        zt_camera cam = zt_scene_get_camera(job->scene);
        opt.time_limit = cli_time_left(job->time_limit, (long long)cam.width * cam.height);
    }
    zt_status st = job->forest_out ? render_saving_forest(job->scene, &opt, job->forest_out,
                                                          &img, &stats, &err)
                                   : zt_render(job->scene, &opt, &img, &stats, &err);
    cli_progress_finish(&prog);
    if (st != ZT_OK) {
        if (cluster_ranks() > 1) /* the others may be waiting inside the render */
            cluster_abort(cli_exit_code(st), err.message);
        cli_error("%s", err.message);
        if (st == ZT_ERR_MEMORY)
            fprintf(stderr, "zonetrace: (--max-memory SIZE sets the limit; the estimate is "
                    "in docs/long-renders.md)\n");
        if (st == ZT_ERR_CANCELLED && cli_stop)
            fprintf(stderr, "zonetrace: interrupted before any image: nothing written\n");
        return cli_exit_code(st);
    }
    if (cluster_rank() == 0)
        st = zt_image_write(img, job->output, &job->tm, &err);
    zt_image_release(img);
    if (st != ZT_OK) {
        cli_error("%s", err.message);
        return cli_exit_code(st);
    }
    if (!job->quiet) {
        /* The path tracer's rays per second count the tracing alone: on a
         * large model the acceleration build can take longer than the
         * image.  The zone tracer's rays include Phase One's. */
        double t = opt.method == ZT_METHOD_PATH ? stats.trace_seconds : stats.seconds;
        double rps = t > 0 ? stats.rays / t : 0;
        fprintf(stderr, "rendered %s in %.3f s (%.3f s preparing the scene): %llu samples, "
                "%llu rays, %.2f Mrays/s, %d threads%s\n",
                strcmp(job->output, "-") ? job->output : "(stdout)", stats.seconds,
                stats.seconds - stats.trace_seconds, (unsigned long long)stats.samples,
                (unsigned long long)stats.rays, rps / 1e6, stats.threads,
                cluster_ranks() > 1 ? " per process" : "");
    }
    if (job->verbose && opt.method == ZT_METHOD_ZONE)
        print_zone_stats(&stats, opt.forest_file);
    if (job->verbose)
        fprintf(stderr, "memory: %.1f MiB estimated before the work (docs/long-renders.md)\n",
                stats.memory_estimate / 1048576.0);
    if (job->verbose && cluster_ranks() > 1) {
        long n;
        double bytes, seconds;
        cluster_exchanges(&n, &bytes, &seconds);
        fprintf(stderr, "exchanges between the %d processes: %ld, %.2f MiB, %.3f s in them on "
                "process 0 (waiting for the others included)\n", cluster_ranks(), n,
                bytes / 1048576.0, seconds);
    }
    if (cluster_rank() == 0)
        cli_report_stop(&opt, &stats, job->quiet);
    return stats.stopped == ZT_STOP_INTERRUPT ? EXIT_INTERRUPTED : EXIT_OK;
}

int cli_render(int argc, char **argv)
{
    render_job job;
    memset(&job, 0, sizeof job);
    /* Under mpirun every process gets this far, and all go on, or all
     * stop with the first failure's message and status. */
    int code = cluster_agree(render_prepare(argc, argv, &job));
    if (code == EXIT_OK && !job.help) {
        if (job.anim.given)
            code = cli_animate(job.scene_path, &job.opt, &job.tm, job.output, job.width,
                               job.height, &job.anim, job.verbose, job.quiet);
        else
            code = cluster_agree(render_image(&job));
    }
    zt_scene_release(job.scene);
    return code;
}
