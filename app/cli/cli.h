/* The zonetrace command line: shared declarations of its sub-commands. */
#ifndef ZT_APP_CLI_H
#define ZT_APP_CLI_H

#include <signal.h>

#include "zonetrace/zonetrace.h"

/* Exit codes: 0-4 as the original programs had them, then the library's
 * statuses (zonetrace/error.h), then an interrupted render; a second
 * interrupt ends the process at once with 128 + the signal's number. */
enum {
    EXIT_OK = 0,
    EXIT_USAGE = 1,
    EXIT_UNREADABLE = 2,
    EXIT_UNPARSEABLE = 3,
    EXIT_UNWRITABLE = 4,
    EXIT_MEMORY = 5,        /* refused up front: needs more memory than allowed */
    EXIT_UNSUPPORTED = 6,   /* this build cannot do it */
    EXIT_FAILURE_OTHER = 7, /* anything else, or interrupted before any image */
    EXIT_INTERRUPTED = 8    /* interrupted: the image so far was written */
};

/* Interrupts (interrupt.c).  After cli_interrupts_install, the first SIGINT
 * or SIGTERM sets cli_stop and prints message (renders finish their pass
 * and write what they have); the second ends the process at once with
 * 128 + its number. */
extern volatile sig_atomic_t cli_stop;
void cli_interrupts_install(const char *message);

/* The exit code for a library status. */
int cli_exit_code(zt_status status);

/* Prints "zonetrace: message" to stderr. */
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

int cli_render(int argc, char **argv);
int cli_compare(int argc, char **argv);
int cli_view(int argc, char **argv);

/* Offline animation (render --motions FILE --frames N --fps F --time T). */
typedef struct cli_animation {
    const char *motions; /* motions file, or NULL */
    int frames;          /* frames to render (default 1) */
    double fps;          /* frame k is at time + k/fps (default 24) */
    double time;         /* time of frame 0 in seconds (default 0) */
    int given;           /* any of the four options was given */
} cli_animation;

/* Loads the scene and the motions and renders the frames to output (a
 * name with a %d frame number when frames > 1).  Returns an exit code. */
int cli_animate(const char *scene_path, const zt_render_options *options,
                const zt_tonemap *tonemap, const char *output, int width, int height,
                const cli_animation *anim, int verbose, int quiet);

/* Progress display on stderr: a bar with ETA on a terminal, plain lines
 * otherwise. */
typedef struct cli_progress {
    int verbose;
    int tty;
    double start;       /* when the stage being reported was first heard */
    double start_frac;  /* and how far along it was then */
    char stage[32];     /* its name: a new one restarts the clock, so the
                           zone stage's ETA leaves Phase One out */
    double last_print;
    int last_decile;
} cli_progress;

void cli_progress_init(cli_progress *p, int verbose);
int cli_progress_callback(void *user, const char *stage, double done, double total);
void cli_progress_finish(cli_progress *p);
double cli_now(void);

/* Whether path can be written (the library writes beside it and renames):
 * not a directory, and its directory takes new files.  Otherwise says why,
 * naming it "cannot write WHAT'path'", and returns 0. */
int cli_can_replace(const char *path, const char *what);

/* When the process started (cli_now), for --time-limit. */
extern double cli_start;

/* Long renders (long_render.c).  Checks and applies --time-limit,
 * --checkpoint, --resume and --max-memory to opt (the time limit as is for
 * an animation, whose frames each get it); EXIT_USAGE with a message when
 * they do not go together. */
int long_render_options(zt_render_options *opt, const char *checkpoint, const char *resume,
                        double time_limit, unsigned long long max_memory,
                        const cli_animation *anim, int saves_forest);
/* What is left of limit seconds since the process started, less the time
 * to write an image of that many pixels (at least a millisecond). */
double cli_time_left(double limit, long long pixels);
/* Says (on stderr) what a render cut short or resumed reached. */
void cli_report_stop(const zt_render_options *opt, const zt_render_stats *stats, int quiet);

#endif
