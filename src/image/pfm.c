/* PFM (portable float map): "PF" (RGB) or "Pf" (grey), width, height and a
 * scale whose sign gives the byte order (negative: little-endian), then
 * float32 rows from the BOTTOM of the image up.  We write RGB
 * little-endian; we read both byte orders and both channel counts.  The
 * scale's magnitude is ignored, as most programs do.  Headers come from
 * untrusted files, so every field is checked before anything is allocated;
 * NaN and infinite pixels are data and are kept. */
#include "image/image_io.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/error.h"

static int is_space(int c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Skips whitespace (at least one) and reads a token of at most size-1
 * characters into buf.  Returns 0 when there is no such token. */
static int read_token(FILE *stream, char *buf, size_t size)
{
    int c = getc(stream);
    if (!is_space(c))
        return 0;
    while (is_space(c))
        c = getc(stream);
    size_t n = 0;
    while (c != EOF && !is_space(c)) {
        if (n + 1 >= size)
            return 0;
        buf[n++] = (char)c;
        c = getc(stream);
    }
    if (c != EOF)
        ungetc(c, stream);
    buf[n] = '\0';
    return n > 0;
}

/* A decimal size: digits only, no sign, at most ZT_IMAGE_MAX_SIDE. */
static long parse_size(const char *token)
{
    long v = 0;
    if (!*token)
        return -1;
    for (const char *p = token; *p; p++) {
        if (*p < '0' || *p > '9')
            return -1;
        v = v * 10 + (*p - '0');
        if (v > ZT_IMAGE_MAX_SIDE)
            return -1;
    }
    return v;
}

static float decode_float(const unsigned char *b, int big_endian)
{
    uint32_t u = big_endian
        ? (uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | b[3]
        : (uint32_t)b[3] << 24 | (uint32_t)b[2] << 16 | (uint32_t)b[1] << 8 | b[0];
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

zt_status pfm_read(FILE *stream, const char *name, zt_image **out, zt_error *err)
{
    char magic[3] = {0}, wtok[16], htok[16], stok[32];
    *out = NULL;
    if (fread(magic, 1, 2, stream) != 2 || magic[0] != 'P' ||
        (magic[1] != 'F' && magic[1] != 'f'))
        return zt_fail(err, ZT_ERR_PARSE, "%s: not a PFM file (bad magic)", name);
    int channels = magic[1] == 'F' ? 3 : 1;
    if (!read_token(stream, wtok, sizeof wtok) || !read_token(stream, htok, sizeof htok) ||
        !read_token(stream, stok, sizeof stok))
        return zt_fail(err, ZT_ERR_PARSE, "%s: malformed PFM header", name);
    long width = parse_size(wtok), height = parse_size(htok);
    if (!image_size_ok(width, height))
        return zt_fail(err, ZT_ERR_PARSE,
                       "%s: PFM size %.15s x %.15s is invalid or too large "
                       "(at most %d per side and %ld pixels)",
                       name, wtok, htok, ZT_IMAGE_MAX_SIDE, ZT_IMAGE_MAX_PIXELS);
    char *end;
    double scale = strtod(stok, &end);
    if (*end != '\0' || !isfinite(scale) || scale == 0.0)
        return zt_fail(err, ZT_ERR_PARSE, "%s: bad PFM scale '%s'", name, stok);
    /* exactly one whitespace byte separates the header from the data */
    if (!is_space(getc(stream)))
        return zt_fail(err, ZT_ERR_PARSE, "%s: malformed PFM header", name);

    size_t row_bytes = (size_t)width * (size_t)channels * 4;
    long left = stream_bytes_left(stream);
    if (left >= 0 && (unsigned long)left < row_bytes * (size_t)height)
        return zt_fail(err, ZT_ERR_PARSE,
                       "%s: truncated PFM: %zu bytes of pixels expected, %ld found",
                       name, row_bytes * (size_t)height, left);

    zt_image *image = zt_image_create((int)width, (int)height);
    unsigned char *row = malloc(row_bytes);
    if (!image || !row) {
        zt_image_release(image);
        free(row);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    }
    int big_endian = scale > 0;
    zt_status st = ZT_OK;
    for (long y = height - 1; y >= 0; y--) {
        errno = 0;
        if (fread(row, 1, row_bytes, stream) != row_bytes) {
            st = ferror(stream)
                ? zt_fail(err, ZT_ERR_READ, "%s: %s", name, strerror(errno ? errno : EIO))
                : zt_fail(err, ZT_ERR_PARSE, "%s: truncated PFM", name);
            break;
        }
        float *dst = zt_image_pixel(image, 0, (int)y);
        for (long x = 0; x < width; x++) {
            for (int c = 0; c < 3; c++) {
                int src = channels == 3 ? c : 0;
                dst[x * 3 + c] = decode_float(row + (x * channels + src) * 4, big_endian);
            }
        }
    }
    free(row);
    if (st != ZT_OK) {
        zt_image_release(image);
        return st;
    }
    *out = image;
    return ZT_OK;
}

zt_status pfm_write(FILE *stream, const zt_image *image, const char *name, zt_error *err)
{
    size_t row_bytes = (size_t)image->width * 12;
    unsigned char *row = malloc(row_bytes);
    if (!row)
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    errno = 0;
    int ok = fprintf(stream, "PF\n%d %d\n-1.0\n", image->width, image->height) > 0;
    for (int y = image->height - 1; ok && y >= 0; y--) {
        const float *src = zt_image_pixel(image, 0, y);
        for (size_t i = 0; i < (size_t)image->width * 3; i++) {
            uint32_t u;
            memcpy(&u, &src[i], sizeof u);
            for (int b = 0; b < 4; b++)
                row[i * 4 + (size_t)b] = (unsigned char)(u >> (8 * b));
        }
        ok = fwrite(row, 1, row_bytes, stream) == row_bytes;
    }
    free(row);
    if (!ok)
        return zt_fail(err, ZT_ERR_WRITE, "%s: %s", name, strerror(errno ? errno : EIO));
    return ZT_OK;
}
