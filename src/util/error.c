#include "util/error.h"

#include <stdarg.h>
#include <stdio.h>

void zt_error_clear(zt_error *err)
{
    if (!err)
        return;
    err->status = ZT_OK;
    err->message[0] = '\0';
}

const char *zt_status_name(zt_status status)
{
    switch (status) {
    case ZT_OK: return "ok";
    case ZT_ERR_ARGUMENT: return "bad argument";
    case ZT_ERR_READ: return "read error";
    case ZT_ERR_PARSE: return "parse error";
    case ZT_ERR_WRITE: return "write error";
    case ZT_ERR_MEMORY: return "out of memory";
    case ZT_ERR_UNSUPPORTED: return "unsupported";
    case ZT_ERR_CANCELLED: return "cancelled";
    case ZT_ERR_EXCHANGE: return "exchange between processes failed";
    }
    return "unknown error";
}

zt_status zt_fail(zt_error *err, zt_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}
