/* Writing a file so that its name never refers to a partial file.
 *
 * The data goes to "<target>.tmp.XXXXXX" in the target's directory (so the
 * final rename stays on one file system and is atomic); commit flushes,
 * fsyncs, closes and renames it over the target; abort deletes it.  The
 * target, if it exists, is untouched until the rename.
 */
#ifndef ZT_IMAGE_ATOMIC_FILE_H
#define ZT_IMAGE_ATOMIC_FILE_H

#include <stdio.h>
#include "zonetrace/error.h"

typedef struct atomic_file {
    FILE *stream;   /* write here (or to fileno(stream)) */
    char *target;   /* the final name */
    char *tmp_path; /* the temporary's name */
} atomic_file;

/* Creates the temporary beside target.  On failure (ZT_ERR_WRITE, or
 * ZT_ERR_MEMORY) nothing is left behind and *file holds no resources. */
zt_status atomic_file_open(atomic_file *file, const char *target, zt_error *err);

/* Flushes, fsyncs, closes and renames the temporary onto the target.  On
 * failure the temporary is removed and ZT_ERR_WRITE names the reason.
 * Either way *file is released. */
zt_status atomic_file_commit(atomic_file *file, zt_error *err);

/* Closes and removes the temporary, releasing *file.  Safe to call on a
 * file that was already committed or aborted. */
void atomic_file_abort(atomic_file *file);

#endif
