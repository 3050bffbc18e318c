/* zonetrace: error values.
 *
 * Every library call that can fail returns a zt_status and, when given a
 * non-NULL zt_error, fills it with a one-line human-readable message that
 * names the file, line and column where that is known.  The library never
 * prints and never exits; the caller decides what to do with the message.
 */
#ifndef ZONETRACE_ERROR_H
#define ZONETRACE_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

/* The numeric values up to 7 double as the command line's exit codes (it
 * reports ZT_ERR_EXCHANGE as 7, other failure: its 8 is an interrupt). */
typedef enum zt_status {
    ZT_OK = 0,
    ZT_ERR_ARGUMENT = 1,    /* a bad option or parameter from the caller */
    ZT_ERR_READ = 2,        /* an input file cannot be opened or read */
    ZT_ERR_PARSE = 3,       /* an input file is malformed or invalid */
    ZT_ERR_WRITE = 4,       /* an output file cannot be written */
    ZT_ERR_MEMORY = 5,      /* out of memory */
    ZT_ERR_UNSUPPORTED = 6, /* a valid request this build cannot do */
    ZT_ERR_CANCELLED = 7,   /* a progress callback asked to stop */
    ZT_ERR_EXCHANGE = 9     /* the processes of a shared render (zt_share)
                               could not exchange their work */
} zt_status;

#define ZT_ERROR_MESSAGE_MAX 512

/* A status with its message.  Zero-initialise it (or call zt_error_clear). */
typedef struct zt_error {
    zt_status status;
    char message[ZT_ERROR_MESSAGE_MAX];
} zt_error;

/* Resets err to ZT_OK with an empty message.  err may be NULL. */
void zt_error_clear(zt_error *err);

/* A short fixed name for a status ("parse error", ...). Never NULL. */
const char *zt_status_name(zt_status status);

#ifdef __cplusplus
}
#endif
#endif
