/* The command line's processes under MPI: the job's ranks, the merge the
 * library's zt_share calls (a bitwise OR across the ranks), agreement on
 * failures and the frames of an animation sent to rank 0. */
#define _POSIX_C_SOURCE 200809L
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../cli.h"
#include "../cluster.h"

static int joined, rank, ranks = 1;
static zt_share share;
static char note[ZT_ERROR_MESSAGE_MAX];
static int saved_stderr = -1; /* rank > 0: the real stderr, for cluster_abort */
static char library[MPI_MAX_LIBRARY_VERSION_STRING + 64];
static long merges;
static double merged_bytes, merge_seconds;

/* Whether mpirun (Open MPI, or a PMI launcher such as MPICH's or Slurm's)
 * started this process as one of several. */
static int launched(void)
{
    const char *vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
    for (int i = 0; i < 3; i++) {
        const char *v = getenv(vars[i]);
        if (v && atoi(v) > 1)
            return 1;
    }
    return 0;
}

/* Bitwise OR in chunks whose counts fit an int. */
static int merge(void *user, void *buffer, size_t bytes)
{
    (void)user;
    double t0 = MPI_Wtime();
    merges++;
    merged_bytes += (double)bytes;
    unsigned char *p = buffer;
    const size_t chunk = (size_t)1 << 27; /* 64-bit words: 1 GiB */
    size_t words = bytes / 8;
    for (size_t at = 0; at < words; at += chunk) {
        size_t n = words - at < chunk ? words - at : chunk;
        if (MPI_Allreduce(MPI_IN_PLACE, p + 8 * at, (int)n, MPI_UINT64_T, MPI_BOR,
                          MPI_COMM_WORLD) != MPI_SUCCESS)
            return -1;
    }
    size_t tail = bytes % 8;
    if (tail && MPI_Allreduce(MPI_IN_PLACE, p + 8 * words, (int)tail, MPI_UNSIGNED_CHAR,
                              MPI_BOR, MPI_COMM_WORLD) != MPI_SUCCESS)
        return -1;
    merge_seconds += MPI_Wtime() - t0;
    return 0;
}

void cluster_exchanges(long *count, double *bytes, double *seconds)
{
    *count = merges;
    *bytes = merged_bytes;
    *seconds = merge_seconds;
}

int cluster_start(int *argc, char ***argv)
{
    if (!launched())
        return EXIT_OK;
    int provided;
    /* MPI is called from the main thread alone, between the parallel
     * loops. */
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        cli_error("could not join the MPI job");
        return EXIT_FAILURE_OTHER;
    }
    joined = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    share = (zt_share){rank, ranks, merge, NULL};
    if (rank > 0) {
        /* Only rank 0 speaks; the others keep their stderr for aborts. */
        fflush(stdout);
        fflush(stderr);
        saved_stderr = dup(2);
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))
            return EXIT_FAILURE_OTHER;
    }
    return EXIT_OK;
}

int cluster_finish(int code)
{
    if (joined)
        MPI_Finalize();
    joined = 0;
    return code;
}

int cluster_rank(void) { return rank; }
int cluster_ranks(void) { return ranks; }
const zt_share *cluster_share(void) { return ranks > 1 ? &share : NULL; }

const char *cluster_library(void)
{
    char v[MPI_MAX_LIBRARY_VERSION_STRING];
    int n = 0;
    MPI_Get_library_version(v, &n);
    v[strcspn(v, ",\n")] = '\0';
    snprintf(library, sizeof library, "%s", v);
    return library;
}

void cluster_note(const char *message)
{
    snprintf(note, sizeof note, "%s", message);
}

typedef struct verdict {
    int code;
    char message[ZT_ERROR_MESSAGE_MAX];
} verdict;

int cluster_agree(int code)
{
    if (ranks == 1)
        return code;
    verdict mine = {code, ""};
    snprintf(mine.message, sizeof mine.message, "%s", note);
    verdict *all = rank == 0 ? calloc((size_t)ranks, sizeof *all) : NULL;
    if (rank == 0 && !all)
        cluster_abort(EXIT_MEMORY, "out of memory");
    MPI_Gather(&mine, (int)sizeof mine, MPI_BYTE, all, (int)sizeof mine, MPI_BYTE, 0,
               MPI_COMM_WORLD);
    int first = -1;
    for (int k = 0; rank == 0 && k < ranks && first < 0; k++)
        if (all[k].code != EXIT_OK)
            first = k;
    /* Rank 0 printed its own message; another's it prints now. */
    if (first > 0)
        fprintf(stderr, "zonetrace: process %d of %d: %s\n", first, ranks,
                all[first].message[0] ? all[first].message : "failed");
    int agreed = first < 0 ? EXIT_OK : all[first].code;
    free(all);
    MPI_Bcast(&agreed, 1, MPI_INT, 0, MPI_COMM_WORLD);
    note[0] = '\0';
    return agreed;
}

void cluster_abort(int code, const char *message)
{
    if (ranks == 1) {
        cli_error("%s", message);
        return;
    }
    if (rank > 0) {
        /* A failure rank 0 shares ends the job from there, before this
         * process speaks. */
        struct timespec t = {2, 0};
        nanosleep(&t, NULL);
        if (saved_stderr >= 0)
            dprintf(saved_stderr, "zonetrace: process %d of %d: %s\n", rank, ranks, message);
    } else {
        fprintf(stderr, "zonetrace: %s\n", message);
        fflush(stderr);
    }
    MPI_Abort(MPI_COMM_WORLD, code);
    exit(code);
}

int cluster_gather(const void *mine, size_t bytes, void *all)
{
    const size_t chunk = (size_t)1 << 30;
    if (rank == 0)
        memcpy(all, mine, bytes);
    for (int k = 1; k < ranks; k++)
        for (size_t at = 0; at < bytes; at += chunk) {
            int n = (int)(bytes - at < chunk ? bytes - at : chunk), rc = MPI_SUCCESS;
            if (rank == 0)
                rc = MPI_Recv((char *)all + (size_t)k * bytes + at, n, MPI_BYTE, k, 7,
                              MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            else if (rank == k)
                rc = MPI_Send((const char *)mine + at, n, MPI_BYTE, 0, 7, MPI_COMM_WORLD);
            if (rc != MPI_SUCCESS)
                return -1;
        }
    return 0;
}
