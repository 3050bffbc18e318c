/* Choosing a format: writers by the file name's extension, readers by the
 * file's first bytes (an extension can lie; a magic number rarely does). */
#include "image/image_io.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "image/atomic_file.h"
#include "util/error.h"

#define KNOWN_EXTENSIONS ".pfm .exr .png .ppm"

static int ascii_lower(int c)
{
    return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c;
}

static int same_ignoring_case(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (ascii_lower((unsigned char)*a) != ascii_lower((unsigned char)*b))
            return 0;
    return *a == *b;
}

zt_image_format zt_image_format_from_path(const char *path)
{
    if (!path)
        return ZT_FORMAT_UNKNOWN;
    if (strcmp(path, "-") == 0)
        return ZT_FORMAT_PPM;
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return ZT_FORMAT_UNKNOWN;
    static const struct { const char *ext; zt_image_format format; } table[] = {
        {".pfm", ZT_FORMAT_PFM}, {".exr", ZT_FORMAT_EXR},
        {".png", ZT_FORMAT_PNG}, {".ppm", ZT_FORMAT_PPM},
    };
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (same_ignoring_case(dot, table[i].ext))
            return table[i].format;
    return ZT_FORMAT_UNKNOWN;
}

static zt_status write_stdout(const uint8_t *rgb, const zt_image *image, zt_error *err)
{
    zt_status st = ppm_write_rgb8(stdout, rgb, image->width, image->height,
                                  "(stdout)", err);
    if (st == ZT_OK && fflush(stdout) != 0)
        st = zt_fail(err, ZT_ERR_WRITE, "(stdout): %s", strerror(errno));
    return st;
}

zt_status zt_image_write(const zt_image *image, const char *path,
                         const zt_tonemap *tonemap, zt_error *err)
{
    if (!path)
        return zt_fail(err, ZT_ERR_ARGUMENT, "no output path given");
    if (!image_valid(image))
        return zt_fail(err, ZT_ERR_ARGUMENT, "%s: not a valid image to write", path);
    zt_image_format format = zt_image_format_from_path(path);
    if (format == ZT_FORMAT_UNKNOWN)
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "%s: unknown image extension (known: " KNOWN_EXTENSIONS ")",
                       path);

    /* Tonemap first, so that a bad setting or no memory leaves no file. */
    uint8_t *rgb = NULL;
    zt_tonemap tm = tonemap ? *tonemap : zt_tonemap_default();
    if (format == ZT_FORMAT_PNG || format == ZT_FORMAT_PPM) {
        if (!isfinite(tm.exposure) || !isfinite(tm.gamma) || tm.gamma < 0)
            return zt_fail(err, ZT_ERR_ARGUMENT,
                           "%s: exposure must be finite and gamma finite and >= 0",
                           path);
        rgb = tonemap_to_rgb8(image, &tm);
        if (!rgb)
            return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
    }
    if (strcmp(path, "-") == 0) {
        zt_status st = write_stdout(rgb, image, err);
        free(rgb);
        return st;
    }

    atomic_file file;
    zt_status st = atomic_file_open(&file, path, err);
    if (st != ZT_OK) {
        free(rgb);
        return st;
    }
    switch (format) {
    case ZT_FORMAT_PFM: st = pfm_write(file.stream, image, path, err); break;
    case ZT_FORMAT_EXR: st = exr_write_image(file.stream, image, path, err); break;
    case ZT_FORMAT_PNG:
        st = png_write_rgb8(file.stream, rgb, image->width, image->height, tm.gamma,
                            path, err);
        break;
    default:
        st = ppm_write_rgb8(file.stream, rgb, image->width, image->height, path, err);
        break;
    }
    free(rgb);
    if (st != ZT_OK) {
        atomic_file_abort(&file);
        return st;
    }
    return atomic_file_commit(&file, err);
}

long stream_bytes_left(FILE *stream)
{
    long here = ftell(stream);
    if (here < 0 || fseek(stream, 0, SEEK_END) != 0)
        return -1;
    long end = ftell(stream);
    if (fseek(stream, here, SEEK_SET) != 0)
        return -1;
    return end < here ? -1 : end - here;
}

zt_status zt_image_read(const char *path, zt_image **out, zt_error *err)
{
    if (!out)
        return zt_fail(err, ZT_ERR_ARGUMENT, "no place for the image");
    *out = NULL;
    if (!path)
        return zt_fail(err, ZT_ERR_ARGUMENT, "no input path given");
    FILE *stream = fopen(path, "rb");
    if (!stream)
        return zt_fail(err, ZT_ERR_READ, "%s: %s", path, strerror(errno));

    unsigned char magic[4] = {0};
    errno = 0;
    size_t got = fread(magic, 1, sizeof magic, stream);
    zt_status st;
    if (ferror(stream))
        st = zt_fail(err, ZT_ERR_READ, "%s: %s", path, strerror(errno ? errno : EIO));
    else if (fseek(stream, 0, SEEK_SET) != 0)
        st = zt_fail(err, ZT_ERR_READ, "%s: cannot seek: %s", path, strerror(errno));
    else if (got >= 2 && magic[0] == 'P' && (magic[1] == 'F' || magic[1] == 'f'))
        st = pfm_read(stream, path, out, err);
    else if (got == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 &&
             magic[3] == 0x01)
        st = exr_read_image(stream, path, out, err);
    else if (got == 4 && magic[0] == 0x89 && magic[1] == 'P' && magic[2] == 'N' &&
             magic[3] == 'G')
        st = png_read(stream, path, out, err);
    else if (got >= 2 && magic[0] == 'P' && (magic[1] == '3' || magic[1] == '6'))
        st = ppm_read(stream, path, out, err);
    else
        st = zt_fail(err, ZT_ERR_PARSE,
                     "%s: not a PFM, EXR, PNG or PPM (P3/P6) image", path);
    fclose(stream);
    if (st != ZT_OK && *out) {
        zt_image_release(*out);
        *out = NULL;
    }
    return st;
}
