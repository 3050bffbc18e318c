/* PNG through libpng's simplified API (which handles every bit depth and
 * colour type, and reports errors without longjmp reaching us), JPEG
 * through libjpeg with an error manager that jumps back here. */
#include "scene/texture_decode.h"

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h>
#include <png.h>

static int fail(char *why, size_t n, const char *reason)
{
    snprintf(why, n, "%s", reason);
    return 0;
}

static int size_ok(unsigned w, unsigned h)
{
    return w > 0 && h > 0 && w <= TEXTURE_MAX_SIDE && h <= TEXTURE_MAX_SIDE &&
           (unsigned long long)w * h <= TEXTURE_MAX_TEXELS;
}

static int decode_png(const unsigned char *data, size_t size, mesh_texture *out, char *why,
                      size_t n)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, data, size)) {
        snprintf(why, n, "corrupt PNG (%s)", img.message);
        return 0;
    }
    if (!size_ok(img.width, img.height)) {
        png_image_free(&img);
        snprintf(why, n, "PNG of %ux%u texels is too large (at most %d a side, %d in all)",
                 img.width, img.height, TEXTURE_MAX_SIDE, TEXTURE_MAX_TEXELS);
        return 0;
    }
    img.format = PNG_FORMAT_RGBA;
    size_t bytes = PNG_IMAGE_SIZE(img);
    unsigned char *rgba = malloc(bytes);
    if (!rgba) {
        png_image_free(&img);
        return fail(why, n, "out of memory");
    }
    if (!png_image_finish_read(&img, NULL, rgba, 0, NULL)) {
        snprintf(why, n, "corrupt PNG (%s)", img.message);
        free(rgba);
        png_image_free(&img);
        return 0;
    }
    out->width = (int)img.width;
    out->height = (int)img.height;
    out->rgba = rgba;
    png_image_free(&img);
    return 1;
}

typedef struct jpeg_failure {
    struct jpeg_error_mgr mgr;
    jmp_buf back;
    char message[JMSG_LENGTH_MAX];
} jpeg_failure;

static void jpeg_fail(j_common_ptr cinfo)
{
    jpeg_failure *f = (jpeg_failure *)cinfo->err;
    f->mgr.format_message(cinfo, f->message);
    longjmp(f->back, 1);
}

static void jpeg_quiet(j_common_ptr cinfo, int level)
{
    (void)cinfo;
    (void)level; /* warnings are not printed: the library never prints */
}

static int decode_jpeg(const unsigned char *data, size_t size, mesh_texture *out, char *why,
                       size_t n)
{
    struct jpeg_decompress_struct cinfo;
    jpeg_failure err;
    /* Set before the jump target and read after it: volatile. */
    unsigned char *volatile rgba = NULL;
    unsigned char *volatile row = NULL;
    cinfo.err = jpeg_std_error(&err.mgr);
    err.mgr.error_exit = jpeg_fail;
    err.mgr.emit_message = jpeg_quiet;
    if (setjmp(err.back)) {
        snprintf(why, n, "corrupt JPEG (%s)", err.message);
        jpeg_destroy_decompress(&cinfo);
        free(rgba);
        free(row);
        return 0;
    }
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, data, (unsigned long)size);
    jpeg_read_header(&cinfo, TRUE);
    if (!size_ok(cinfo.image_width, cinfo.image_height)) {
        snprintf(why, n, "JPEG of %ux%u texels is too large (at most %d a side, %d in all)",
                 cinfo.image_width, cinfo.image_height, TEXTURE_MAX_SIDE, TEXTURE_MAX_TEXELS);
        jpeg_destroy_decompress(&cinfo);
        return 0;
    }
    cinfo.out_color_space = JCS_RGB;
    jpeg_start_decompress(&cinfo);
    unsigned w = cinfo.output_width, h = cinfo.output_height;
    if (cinfo.output_components != 3 || !size_ok(w, h)) {
        jpeg_destroy_decompress(&cinfo);
        return fail(why, n, "JPEG with an unexpected layout");
    }
    rgba = malloc((size_t)w * h * 4);
    row = malloc((size_t)w * 3);
    if (!rgba || !row) {
        jpeg_destroy_decompress(&cinfo);
        free(rgba);
        free(row);
        return fail(why, n, "out of memory");
    }
    while (cinfo.output_scanline < h) {
        unsigned y = cinfo.output_scanline;
        JSAMPROW rows[1] = {row};
        if (jpeg_read_scanlines(&cinfo, rows, 1) != 1)
            break;
        unsigned char *dst = rgba + (size_t)y * w * 4;
        for (unsigned x = 0; x < w; x++) {
            dst[4 * x] = row[3 * x];
            dst[4 * x + 1] = row[3 * x + 1];
            dst[4 * x + 2] = row[3 * x + 2];
            dst[4 * x + 3] = 255;
        }
    }
    if (cinfo.output_scanline < h) {
        jpeg_destroy_decompress(&cinfo);
        free(rgba);
        free(row);
        return fail(why, n, "truncated JPEG");
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    free(row);
    out->width = (int)w;
    out->height = (int)h;
    out->rgba = rgba;
    return 1;
}

int texture_decode(const unsigned char *data, size_t size, mesh_texture *out, char *why,
                   size_t why_size)
{
    static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    memset(out, 0, sizeof *out);
    out->wrap = 1;
    if (size >= 8 && memcmp(data, png_sig, 8) == 0)
        return decode_png(data, size, out, why, why_size);
    if (size >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff)
        return decode_jpeg(data, size, out, why, why_size);
    return fail(why, why_size, "not a PNG or JPEG image");
}
