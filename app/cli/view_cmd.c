/* zonetrace view: the interactive window, when built with SDL2. */
#include <stdio.h>

#include "cli.h"

#ifndef ZT_WITH_VIEWER
int cli_view(int argc, char **argv)
{
    (void)argc; (void)argv;
    cli_error("this build has no viewer (configure with -DZT_WITH_VIEWER=ON and SDL2)");
    return EXIT_USAGE;
}
#endif
