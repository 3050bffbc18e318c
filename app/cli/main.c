/* zonetrace: command line entry point and sub-command dispatch. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "cluster.h"

static void print_usage(FILE *f)
{
    fprintf(f,
        "usage: zonetrace render SCENE [options]   render a scene to an image\n"
        "       zonetrace SCENE [options]          the same\n"
        "       zonetrace compare IMAGE REFERENCE  error figures of an image\n"
        "       zonetrace view SCENE [options]     interactive window\n"
        "       zonetrace --help | --version\n"
        "\n"
        "'zonetrace render --help' lists the render options.\n");
}

int cli_exit_code(zt_status status)
{
    switch (status) {
    case ZT_OK: return EXIT_OK;
    case ZT_ERR_ARGUMENT: return EXIT_USAGE;
    case ZT_ERR_READ: return EXIT_UNREADABLE;
    case ZT_ERR_PARSE: return EXIT_UNPARSEABLE;
    case ZT_ERR_WRITE: return EXIT_UNWRITABLE;
    case ZT_ERR_MEMORY: return EXIT_MEMORY;
    case ZT_ERR_UNSUPPORTED: return EXIT_UNSUPPORTED;
    default: return EXIT_FAILURE_OTHER;
    }
}

void cli_error(const char *fmt, ...)
{
    char message[ZT_ERROR_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    fprintf(stderr, "zonetrace: %s\n", message);
    cluster_note(message); /* a process other than rank 0 speaks through it */
}

double cli_start;

static int run(int argc, char **argv)
{
    if (argc < 2) {
        print_usage(stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        print_usage(stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "--version")) {
        printf("zonetrace %s%s%s\n", zt_version(), *cluster_library() ? ", with " : "",
               cluster_library());
        return EXIT_OK;
    }
    if (!strcmp(cmd, "render"))
        return cli_render(argc - 1, argv + 1);
    if (cluster_ranks() > 1 && cmd[0] != '-' && (!strcmp(cmd, "compare") || !strcmp(cmd, "view"))) {
        cli_error("'%s' runs in one process: only 'render' is shared out by mpirun", cmd);
        return EXIT_USAGE;
    }
    if (!strcmp(cmd, "compare"))
        return cli_compare(argc - 1, argv + 1);
    if (!strcmp(cmd, "view"))
        return cli_view(argc - 1, argv + 1);
    if (cmd[0] == '-') {
        cli_error("unknown option '%s' (expected a command or a scene file)", cmd);
        print_usage(stderr);
        return EXIT_USAGE;
    }
    /* "zonetrace SCENE ..." is "zonetrace render SCENE ...". */
    return cli_render(argc, argv);
}

int main(int argc, char **argv)
{
    cli_start = cli_now();
    int code = cluster_start(&argc, &argv);
    if (code != EXIT_OK)
        return code;
    return cluster_finish(run(argc, argv));
}
