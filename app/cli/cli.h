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
