/* PPM: we write binary P6 with maxval 255 (values already tonemapped), top
 * row first.  We read P6 and plain-text P3 with any maxval up to 65535 (two
 * bytes per sample, big-endian, above 255), taking the values as sRGB and
 * linearising them, since a PPM carries no transfer curve of its own.
 * Headers are untrusted: sizes are capped and checked against the data
 * available before anything is allocated. */
#include "image/image_io.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "util/error.h"

zt_status ppm_write_rgb8(FILE *stream, const uint8_t *rgb, int width, int height,
                         const char *name, zt_error *err)
{
    size_t bytes = (size_t)width * (size_t)height * 3;
    errno = 0;
    if (fprintf(stream, "P6\n%d %d\n255\n", width, height) < 0 ||
        fwrite(rgb, 1, bytes, stream) != bytes)
        return zt_fail(err, ZT_ERR_WRITE, "%s: %s", name, strerror(errno ? errno : EIO));
    return ZT_OK;
}

static int is_space(int c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Skips whitespace and '#' comments, then reads a decimal number of at
 * most max.  Returns -1 if there is none, it is too big, or it is not
 * followed by whitespace or the end of the file. */
static long read_number(FILE *stream, long max)
{
    int c = getc(stream);
    for (;;) {
        if (c == '#') {
            while (c != '\n' && c != '\r' && c != EOF)
                c = getc(stream);
        } else if (is_space(c)) {
            c = getc(stream);
        } else {
            break;
        }
    }
    if (c < '0' || c > '9')
        return -1;
    long v = 0;
    for (; c >= '0' && c <= '9'; c = getc(stream)) {
        v = v * 10 + (c - '0');
        if (v > max)
            return -1;
    }
    if (c != EOF && !is_space(c))
        return -1;
    if (c != EOF)
        ungetc(c, stream);
    return v;
}

static zt_status read_samples(FILE *stream, int binary, long maxval, const float *lut,
                              zt_image *image, const char *name, zt_error *err)
{
    size_t count = (size_t)image->width * (size_t)image->height * 3;
    int wide = maxval > 255;
    for (size_t i = 0; i < count; i++) {
        long v;
        if (binary) {
            int hi = wide ? getc(stream) : 0;
            int lo = getc(stream);
            if (hi == EOF || lo == EOF)
                goto short_read;
            v = (long)hi << 8 | lo;
        } else {
            v = read_number(stream, 65535);
            if (v < 0) {
                if (feof(stream) || ferror(stream))
                    goto short_read;
                return zt_fail(err, ZT_ERR_PARSE, "%s: bad P3 sample", name);
            }
        }
        if (v > maxval)
            return zt_fail(err, ZT_ERR_PARSE, "%s: sample %ld exceeds maxval %ld",
                           name, v, maxval);
        image->pixels[i] = lut[v];
    }
    return ZT_OK;
short_read:
    if (ferror(stream))
        return zt_fail(err, ZT_ERR_READ, "%s: %s", name, strerror(errno ? errno : EIO));
    return zt_fail(err, ZT_ERR_PARSE, "%s: truncated PPM", name);
}

zt_status ppm_read(FILE *stream, const char *name, zt_image **out, zt_error *err)
{
    char magic[2];
    *out = NULL;
    if (fread(magic, 1, 2, stream) != 2 || magic[0] != 'P' ||
        (magic[1] != '3' && magic[1] != '6'))
        return zt_fail(err, ZT_ERR_PARSE, "%s: not a P3 or P6 file", name);
    int binary = magic[1] == '6';
    int c = getc(stream);
    if (!is_space(c) && c != '#')
        return zt_fail(err, ZT_ERR_PARSE, "%s: malformed PPM header", name);
    ungetc(c, stream);
    long width = read_number(stream, ZT_IMAGE_MAX_SIDE);
    long height = read_number(stream, ZT_IMAGE_MAX_SIDE);
    long maxval = read_number(stream, 65535);
    if (width < 0 || height < 0 || maxval < 0)
        return zt_fail(err, ZT_ERR_PARSE,
                       "%s: malformed PPM header (sizes at most %d, maxval at most 65535)",
                       name, ZT_IMAGE_MAX_SIDE);
    if (!image_size_ok(width, height) || maxval < 1)
        return zt_fail(err, ZT_ERR_PARSE, "%s: bad PPM size %ld x %ld or maxval %ld",
                       name, width, height, maxval);
    /* P6: exactly one whitespace byte before the samples */
    if (binary && !is_space(getc(stream)))
        return zt_fail(err, ZT_ERR_PARSE, "%s: malformed PPM header", name);

    size_t samples = (size_t)width * (size_t)height * 3;
    size_t need = binary ? samples * (maxval > 255 ? 2 : 1) : 2 * samples - 1;
    long left = stream_bytes_left(stream);
    if (left >= 0 && (unsigned long)left < need)
        return zt_fail(err, ZT_ERR_PARSE,
                       "%s: truncated PPM: at least %zu bytes of samples expected, %ld found",
                       name, need, left);

    zt_image *image = zt_image_create((int)width, (int)height);
    float *lut = malloc(((size_t)maxval + 1) * sizeof *lut);
    if (!image || !lut) {
        zt_image_release(image);
        free(lut);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    }
    for (long v = 0; v <= maxval; v++)
        lut[v] = (float)srgb_to_linear((double)v / (double)maxval);
    zt_status st = read_samples(stream, binary, maxval, lut, image, name, err);
    free(lut);
    if (st != ZT_OK) {
        zt_image_release(image);
        return st;
    }
    *out = image;
    return ZT_OK;
}
