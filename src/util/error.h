/* Filling zt_error values: the one way the library reports failures. */
#ifndef ZT_UTIL_ERROR_H
#define ZT_UTIL_ERROR_H

#include "zonetrace/error.h"

/* Records status and a printf-style message in err (if not NULL) and
 * returns status, so callers can write `return zt_fail(err, ...)`. */
zt_status zt_fail(zt_error *err, zt_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#endif
