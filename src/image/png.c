/* PNG through libpng.  We write 8-bit RGB, already tonemapped, tagged with
 * how it was encoded: an sRGB chunk for the sRGB curve, gAMA 1/gamma for a
 * power curve.  Reading takes any PNG, interlaced or not, of 1 to 16 bits
 * (grey, palette, RGB, with or without alpha; alpha is dropped) and
 * linearises it with the inverse of the curve it is tagged with: sRGB when
 * it has an sRGB chunk or no tag at all, x^(1/g) for gAMA g otherwise.  So a
 * PNG we wrote with gamma 1 reads back as k/255 exactly.
 * libpng reports errors by longjmp; they come back here as messages, and
 * its warnings are dropped (the library never prints). */
#include "image/image_io.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>

#include "util/error.h"

typedef struct png_failure {
    jmp_buf jump;
    char message[160];
} png_failure;

static void on_error(png_structp png, png_const_charp message)
{
    png_failure *failure = png_get_error_ptr(png);
    snprintf(failure->message, sizeof failure->message, "%s", message);
    longjmp(failure->jump, 1);
}

static void on_warning(png_structp png, png_const_charp message)
{
    (void)png;
    (void)message;
}

/* Our own I/O functions, so that failures say why (libpng's own only say
 * "Read Error" or "Write Error"). */
static void write_data(png_structp png, png_bytep data, size_t size)
{
    errno = 0;
    if (fwrite(data, 1, size, png_get_io_ptr(png)) != size)
        png_error(png, strerror(errno ? errno : EIO));
}

static void flush_data(png_structp png)
{
    (void)png; /* the caller flushes and syncs when it commits the file */
}

static void read_data(png_structp png, png_bytep data, size_t size)
{
    FILE *stream = png_get_io_ptr(png);
    errno = 0;
    if (fread(data, 1, size, stream) != size)
        png_error(png, ferror(stream) ? strerror(errno ? errno : EIO) : "truncated file");
}

zt_status png_write_rgb8(FILE *stream, const uint8_t *rgb, int width, int height,
                         double gamma, const char *name, zt_error *err)
{
    png_failure failure;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &failure,
                                              on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    }
    if (setjmp(failure.jump)) {
        png_destroy_write_struct(&png, &info);
        return zt_fail(err, ZT_ERR_WRITE, "%s: %s", name, failure.message);
    }
    png_set_write_fn(png, stream, write_data, flush_data);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    if (gamma == 0.0)
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    else
        png_set_gAMA(png, info, 1.0 / gamma);
    png_write_info(png, info);
    for (int y = 0; y < height; y++)
        png_write_row(png, rgb + (size_t)y * (size_t)width * 3);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return ZT_OK;
}

/* The linear value of every code of a bit depth, by the file's tag. */
static float *build_lut(png_structp png, png_infop info, int depth)
{
    size_t codes = (size_t)1 << depth;
    float *lut = malloc(codes * sizeof *lut);
    if (!lut)
        return NULL;
    int intent;
    double file_gamma = 0.0;
    int power = !png_get_sRGB(png, info, &intent) &&
                png_get_gAMA(png, info, &file_gamma) && file_gamma > 0.0;
    for (size_t k = 0; k < codes; k++) {
        double v = (double)k / (double)(codes - 1);
        lut[k] = (float)(power ? (file_gamma == 1.0 ? v : pow(v, 1.0 / file_gamma))
                               : srgb_to_linear(v));
    }
    return lut;
}

zt_status png_read(FILE *stream, const char *name, zt_image **out, zt_error *err)
{
    png_failure failure;
    *out = NULL;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &failure,
                                             on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_read_struct(&png, NULL, NULL);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    }
    /* volatile: they change after setjmp and are freed after a longjmp */
    zt_image *volatile image = NULL;
    png_bytep volatile data = NULL;
    png_bytepp volatile rows = NULL;
    float *volatile lut = NULL;
    volatile zt_status fail_status = ZT_ERR_PARSE;
    if (setjmp(failure.jump)) {
        png_destroy_read_struct(&png, &info, NULL);
        zt_image_release(image);
        free(data);
        free(rows);
        free(lut);
        if (ferror(stream))
            fail_status = ZT_ERR_READ;
        return zt_fail(err, fail_status, "%s: bad PNG: %s", name, failure.message);
    }
    png_set_read_fn(png, stream, read_data);
    png_set_user_limits(png, ZT_IMAGE_MAX_SIDE, ZT_IMAGE_MAX_SIDE);
    png_read_info(png, info);

    png_uint_32 width, height;
    int depth, color_type, interlace;
    png_get_IHDR(png, info, &width, &height, &depth, &color_type, &interlace, NULL, NULL);
    if (!image_size_ok((long)width, (long)height))
        png_error(png, "image too large");
    if (color_type == PNG_COLOR_TYPE_PALETTE)
        png_set_palette_to_rgb(png);
    if (color_type == PNG_COLOR_TYPE_GRAY && depth < 8)
        png_set_expand_gray_1_2_4_to_8(png);
    if (!(color_type & PNG_COLOR_MASK_COLOR))
        png_set_gray_to_rgb(png);
    /* unconditionally: expanding a palette also turns its tRNS into alpha */
    png_set_strip_alpha(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);

    depth = png_get_bit_depth(png, info) == 16 ? 16 : 8;
    size_t row_bytes = png_get_rowbytes(png, info);
    if (png_get_channels(png, info) != 3 || row_bytes != (size_t)width * 3 * (depth / 8))
        png_error(png, "unexpected pixel layout");
    image = zt_image_create((int)width, (int)height);
    data = malloc(row_bytes * height);
    rows = malloc(height * sizeof *rows);
    lut = build_lut(png, info, depth);
    if (!image || !data || !rows || !lut) {
        fail_status = ZT_ERR_MEMORY;
        png_error(png, "out of memory");
    }
    for (png_uint_32 y = 0; y < height; y++)
        rows[y] = data + y * row_bytes;
    png_read_image(png, rows);
    png_read_end(png, NULL);

    size_t count = (size_t)width * height * 3;
    for (size_t i = 0; i < count; i++) {
        unsigned code = depth == 16 ? (unsigned)data[2 * i] << 8 | data[2 * i + 1] : data[i];
        image->pixels[i] = lut[code];
    }
    png_destroy_read_struct(&png, &info, NULL);
    free(data);
    free(rows);
    free(lut);
    *out = image;
    return ZT_OK;
}
