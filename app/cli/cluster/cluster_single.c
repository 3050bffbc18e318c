/* The command line's processes in a build without MPI: one.  Started by
 * mpirun anyway, it refuses, rather than have every process render the
 * whole image and write the same files. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../cli.h"
#include "../cluster.h"

int cluster_start(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    const char *vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
    for (int i = 0; i < 3; i++) {
        const char *v = getenv(vars[i]);
        if (v && atoi(v) > 1) {
            cli_error("started as one of %s processes (mpirun), but this zonetrace was "
                      "built without MPI: install Open MPI (scripts/install-deps.sh) and "
                      "build again", v);
            return EXIT_UNSUPPORTED;
        }
    }
    return EXIT_OK;
}

int cluster_finish(int code) { return code; }
int cluster_rank(void) { return 0; }
int cluster_ranks(void) { return 1; }
const char *cluster_library(void) { return ""; }
const zt_share *cluster_share(void) { return NULL; }
void cluster_note(const char *message) { (void)message; }
int cluster_agree(int code) { return code; }

void cluster_abort(int code, const char *message)
{
    (void)code;
    cli_error("%s", message);
}

int cluster_gather(const void *mine, size_t bytes, void *all)
{
    memcpy(all, mine, bytes);
    return 0;
}

void cluster_exchanges(long *count, double *bytes, double *seconds)
{
    *count = 0;
    *bytes = *seconds = 0;
}
