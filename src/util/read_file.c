#define _POSIX_C_SOURCE 200809L
#include "util/read_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "util/error.h"

static zt_status too_large(zt_error *err, const char *path, size_t max_bytes)
{
    return zt_fail(err, ZT_ERR_READ, "%s: too large (the limit is %zu MiB)", path,
                   max_bytes >> 20);
}

static zt_status read_all(FILE *f, const char *path, size_t max_bytes, char **text,
                          size_t *length, zt_error *err)
{
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    if (!buf)
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
    for (;;) {
        if (n == cap) {
            size_t limit = max_bytes + 1;
            cap = cap * 2 < limit ? cap * 2 : limit;
            char *p = n < cap ? realloc(buf, cap) : NULL;
            if (!p) {
                free(buf);
                if (n > max_bytes)
                    return too_large(err, path, max_bytes);
                return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
            }
            buf = p;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0)
            break;
    }
    if (ferror(f)) {
        int e = errno;
        free(buf);
        return zt_fail(err, ZT_ERR_READ, "%s: cannot read: %s", path, strerror(e));
    }
    if (n > max_bytes) {
        free(buf);
        return too_large(err, path, max_bytes);
    }
    *text = buf;
    *length = n;
    return ZT_OK;
}

zt_status read_text_file(const char *path, const char *what, size_t max_bytes,
                         char **text, size_t *length, zt_error *err)
{
    *text = NULL;
    *length = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return zt_fail(err, ZT_ERR_READ, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    zt_status status = ZT_OK;
    if (fstat(fileno(f), &st) != 0)
        status = zt_fail(err, ZT_ERR_READ, "%s: cannot read: %s", path, strerror(errno));
    else if (S_ISDIR(st.st_mode))
        status = zt_fail(err, ZT_ERR_READ, "%s: is a directory, not a %s", path, what);
    else if (S_ISREG(st.st_mode) && (unsigned long long)st.st_size > max_bytes)
        status = zt_fail(err, ZT_ERR_READ, "%s: too large: %lld bytes (the limit is %zu MiB)",
                         path, (long long)st.st_size, max_bytes >> 20);
    if (!status)
        status = read_all(f, path, max_bytes, text, length, err);
    fclose(f);
    return status;
}
