/* Reading a whole input file that nobody vouches for. */
#ifndef ZT_UTIL_READ_FILE_H
#define ZT_UTIL_READ_FILE_H

#include <stddef.h>

#include "zonetrace/error.h"

/* Reads path into *text (malloc'd, the caller's; not NUL-terminated) and
 * *length.  what names the kind of file in messages ("scene file").
 * Refuses directories and files over max_bytes with ZT_ERR_READ, and never
 * reads more than max_bytes + 1 bytes, so a pipe cannot run away. */
zt_status read_text_file(const char *path, const char *what, size_t max_bytes,
                         char **text, size_t *length, zt_error *err);

#endif
