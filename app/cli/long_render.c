/* zonetrace render: the options of long renders (time limit, checkpoints,
 * memory limit) and the report of a render that stopped early. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>

#include "cli.h"

int long_render_options(zt_render_options *opt, const char *checkpoint, const char *resume,
                        double time_limit, unsigned long long max_memory,
                        const cli_animation *anim, int saves_forest)
{
    if (checkpoint || resume) {
        if (opt->method != ZT_METHOD_PATH) {
            cli_error("--checkpoint and --resume are for the path tracer (the zone tracer "
                      "keeps its Phase One with --save-forest)");
            return EXIT_USAGE;
        }
        if (anim->given) {
            cli_error("--checkpoint and --resume are for one image, not an animation");
            return EXIT_USAGE;
        }
        if (checkpoint && resume && strcmp(checkpoint, resume) != 0) {
            cli_error("--resume %s keeps checkpointing into %s: --checkpoint cannot name "
                      "another file", resume, resume);
            return EXIT_USAGE;
        }
        opt->checkpoint_file = resume ? resume : checkpoint;
        opt->resume = resume != NULL;
        /* Found out now rather than at the first checkpoint. */
        if (!cli_can_replace(opt->checkpoint_file, "checkpoint "))
            return EXIT_USAGE;
    }
    if (time_limit > 0) {
        if (opt->method == ZT_METHOD_ZONE && opt->level >= 0) {
            cli_error("--time-limit cannot be kept with --level: the zone tracer reaches a "
                      "level only through all before it");
            return EXIT_USAGE;
        }
        if (saves_forest) {
            cli_error("--time-limit and --save-forest do not go together: a forest is "
                      "saved whole");
            return EXIT_USAGE;
        }
        if (anim->given)
            opt->time_limit = time_limit;
    }
    opt->max_memory = max_memory;
    return EXIT_OK;
}

double cli_time_left(double limit, long long pixels)
{
    /* Writing: about 40 ns a pixel for PNG (BENCHMARKS.md), and a margin. */
    double left = limit - (cli_now() - cli_start) - 0.02 - 4e-8 * (double)pixels;
    return left > 1e-3 ? left : 1e-3;
}

void cli_report_stop(const zt_render_options *opt, const zt_render_stats *s, int quiet)
{
    const char *why = s->stopped == ZT_STOP_TIME ? "the time limit" : "the interrupt";
    if (opt->method == ZT_METHOD_PATH) {
        if (s->spp_resumed && !quiet)
            fprintf(stderr, "resumed from %s at %d samples per pixel\n", opt->checkpoint_file,
                    s->spp_resumed);
        if (s->stopped)
            fprintf(stderr, "zonetrace: stopped by %s at %d of %d samples per pixel: the image "
                    "has %d%s\n", why, s->spp_done, opt->spp, s->spp_done,
                    opt->checkpoint_file ? " (and so has the checkpoint)" : "");
        else if (opt->checkpoint_file && !quiet)
            fprintf(stderr, "checkpoint %s: %d samples per pixel\n", opt->checkpoint_file,
                    s->spp_done);
    } else if (s->stopped) {
        fprintf(stderr, "zonetrace: stopped by %s: the zone tracer reached depth %d of %d "
                "(levels %d to %d dropped)\n", why, s->depth_done, opt->depth,
                s->depth_done + 1, opt->depth);
    }
}
