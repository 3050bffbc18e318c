/* SIGINT and SIGTERM: the first asks the render to stop and write what it
 * has, the second ends the process at once, with nothing more written. */
#define _POSIX_C_SOURCE 200809L
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

volatile sig_atomic_t cli_stop = 0;
static const char *notice;
static size_t notice_length;

static void on_signal(int sig)
{
    if (cli_stop) {
        /* The default action ends the process with the signal's status. */
        signal(sig, SIG_DFL);
        raise(sig);
        _exit(128 + sig);
    }
    cli_stop = 1;
    ssize_t ignored = write(2, notice, notice_length);
    (void)ignored;
}

void cli_interrupts_install(const char *message)
{
    notice = message;
    notice_length = strlen(message);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}
