/* Checking, before a long render, that its output files can be written
 * (by the process that writes them: rank 0 under mpirun). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "cluster.h"

int cli_can_replace(const char *path, const char *what)
{
    if (cluster_rank() > 0)
        return 1; /* rank 0 alone writes files */
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        cli_error("cannot write %s'%s': it is a directory", what, path);
        return 0;
    }
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        strcpy(dir, ".");
    else if (slash == path)
        strcpy(dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    if (access(dir, W_OK | X_OK) != 0) {
        cli_error("cannot write %s'%s': directory '%s' is missing or not writable", what, path,
                  dir);
        return 0;
    }
    return 1;
}
