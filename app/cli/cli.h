/* The zonetrace command line: shared declarations of its sub-commands. */
#ifndef ZT_APP_CLI_H
#define ZT_APP_CLI_H

#include "zonetrace/zonetrace.h"

/* Exit codes, as the original programs had them. */
enum {
    EXIT_OK = 0,
    EXIT_USAGE = 1,
    EXIT_UNREADABLE = 2,
    EXIT_UNPARSEABLE = 3,
    EXIT_UNWRITABLE = 4,
    EXIT_FAILURE_OTHER = 5
};

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
    double start;
    double last_print;
    int last_decile;
} cli_progress;

void cli_progress_init(cli_progress *p, int verbose);
int cli_progress_callback(void *user, const char *stage, double done, double total);
void cli_progress_finish(cli_progress *p);
double cli_now(void);

#endif
