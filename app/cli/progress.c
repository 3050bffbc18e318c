/* Progress display for -v. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"

double cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cli_progress_init(cli_progress *p, int verbose)
{
    p->verbose = verbose;
    p->tty = isatty(2);
    p->start = cli_now();
    p->start_frac = 0;
    p->stage[0] = '\0';
    p->last_print = 0;
    p->last_decile = -1;
}

static void format_duration(char *buf, size_t n, double s)
{
    if (s < 60)
        snprintf(buf, n, "%.0fs", s);
    else if (s < 3600)
        snprintf(buf, n, "%dm%02ds", (int)(s / 60), (int)s % 60);
    else
        snprintf(buf, n, "%dh%02dm", (int)(s / 3600), ((int)s / 60) % 60);
}

int cli_progress_callback(void *user, const char *stage, double done, double total)
{
    cli_progress *p = user;
    if (!p->verbose || total <= 0)
        return 0;
    double now = cli_now();
    if (strncmp(p->stage, stage, sizeof p->stage - 1) != 0) {
        snprintf(p->stage, sizeof p->stage, "%s", stage);
        p->start = now;
        p->start_frac = done / total;
        p->last_decile = -1;
    }
    double elapsed = now - p->start;
    double frac = done / total, run = frac - p->start_frac;
    char eta[32] = "?";
    if (run > 0.001)
        format_duration(eta, sizeof eta, elapsed * (1.0 - frac) / run);
    if (p->tty) {
        if (now - p->last_print < 0.1 && frac < 1.0)
            return 0;
        p->last_print = now;
        int width = 30, filled = (int)(frac * width + 0.5);
        char bar[64];
        for (int i = 0; i < width; i++)
            bar[i] = i < filled ? '#' : '.';
        bar[width] = '\0';
        fprintf(stderr, "\r%-6s [%s] %5.1f%%  ETA %-8s", stage, bar, 100.0 * frac, eta);
        fflush(stderr);
    } else {
        int decile = (int)(frac * 10);
        if (decile != p->last_decile) {
            p->last_decile = decile;
            fprintf(stderr, "%s: %3.0f%% done, %.1fs elapsed, ETA %s\n", stage,
                    100.0 * frac, elapsed, eta);
        }
    }
    return 0;
}

void cli_progress_finish(cli_progress *p)
{
    if (p->verbose && p->tty)
        fputc('\n', stderr);
}
