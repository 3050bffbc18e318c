/* The command line as one of several processes started by mpirun
 * (docs/cluster.md): rank 0 prints and writes, every rank renders its share
 * (zt_share), and a failure anywhere ends every process with the same
 * message and exit status.  A build without MPI is always one process. */
#ifndef ZT_APP_CLI_CLUSTER_H
#define ZT_APP_CLI_CLUSTER_H

#include <stddef.h>

#include "zonetrace/zonetrace.h"

/* Joins the job when the process was started by mpirun (its environment
 * says so); otherwise, or in a build without MPI, this is the only process.
 * On ranks other than 0, standard output and error go nowhere from here on:
 * their messages reach the user through rank 0 (cluster_agree) or
 * cluster_abort.  Returns EXIT_OK, or an exit code after a message. */
int cluster_start(int *argc, char ***argv);

/* Leaves the job; returns code. */
int cluster_finish(int code);

int cluster_rank(void);
int cluster_ranks(void);

/* A description of this build's MPI, for --version ("" without one). */
const char *cluster_library(void);

/* The share for the library (NULL for one process). */
const zt_share *cluster_share(void);

/* Remembers a message of this process (cli_error on ranks other than 0),
 * for cluster_agree to show when this process fails. */
void cluster_note(const char *message);

/* Called by every process at the same point with its exit code so far:
 * returns the code of the lowest-ranked process that failed (EXIT_OK when
 * none did), and rank 0 prints that process's message if it was not its
 * own.  The point where all go on, or all stop, together. */
int cluster_agree(int code);

/* Ends every process of the job with code, after printing message: for a
 * failure the other processes may not share (out of memory on one node),
 * which may leave them waiting inside the render.  On ranks other than 0
 * it waits a moment first, so that a failure rank 0 shares is reported
 * once, by rank 0.  Returns (after printing) only in a single process. */
void cluster_abort(int code, const char *message);

/* Rank 0 receives every process's `bytes` bytes into all (ranks * bytes,
 * rank by rank); the others pass all = NULL.  Returns 0, or -1 (message
 * printed) when the transfer failed. */
int cluster_gather(const void *mine, size_t bytes, void *all);

/* The library's merges so far on this process: how many, their bytes, and
 * the seconds spent in them (waiting for the other processes included). */
void cluster_exchanges(long *count, double *bytes, double *seconds);

#endif
