/* zonetrace: images.
 *
 * An image is a linear, high dynamic range RGB framebuffer of 32-bit floats,
 * row-major, top row first.  Writers pick the format from the file name's
 * extension: .pfm and .exr keep the linear values; .png and .ppm are 8-bit
 * and go through exposure and gamma (zt_tonemap).  Every writer writes to a
 * temporary file beside the target and renames it into place, so a failed or
 * interrupted write never leaves a partial image under the target name.
 */
#ifndef ZONETRACE_IMAGE_H
#define ZONETRACE_IMAGE_H

#include <stddef.h>
#include "zonetrace/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct zt_image {
    int width;
    int height;
    float *pixels; /* width*height*3 floats, RGB, row 0 at the top */
} zt_image;

/* A new black image.  Returns NULL on bad sizes or when out of memory.
 * Release it with zt_image_release. */
zt_image *zt_image_create(int width, int height);

/* Frees the image and its pixels.  NULL is allowed. */
void zt_image_release(zt_image *image);

/* Pointer to the RGB triple of pixel (x, y), y = 0 at the top. */
static inline float *zt_image_pixel(const zt_image *image, int x, int y)
{
    return image->pixels + ((size_t)y * (size_t)image->width + (size_t)x) * 3;
}

typedef enum zt_image_format {
    ZT_FORMAT_UNKNOWN = 0,
    ZT_FORMAT_PFM,
    ZT_FORMAT_EXR,
    ZT_FORMAT_PNG,
    ZT_FORMAT_PPM
} zt_image_format;

/* The format a file name asks for, by its extension (case-insensitive). */
zt_image_format zt_image_format_from_path(const char *path);

/* How linear values become 8-bit ones (PNG, PPM only). */
typedef struct zt_tonemap {
    int auto_exposure; /* non-zero: choose the exposure from the image */
    double exposure;   /* stops (EV); the values are multiplied by 2^exposure */
    double gamma;      /* output = x^(1/gamma); 0 means the sRGB curve */
} zt_tonemap;

/* Defaults: automatic exposure, sRGB curve. */
zt_tonemap zt_tonemap_default(void);

/* The exposure (in EV) that automatic exposure picks for this image: it maps
 * the 99th percentile of luminance to 0.9 of full scale.  A black image
 * gets 0. */
double zt_image_auto_exposure(const zt_image *image);

/* Writes the image to path in the format of its extension.  tonemap may be
 * NULL for the defaults; HDR formats ignore it.  "-" writes PPM to stdout.
 * Fails with ZT_ERR_ARGUMENT for an unknown extension, ZT_ERR_WRITE when
 * the file cannot be written. */
zt_status zt_image_write(const zt_image *image, const char *path,
                         const zt_tonemap *tonemap, zt_error *err);

/* Reads a PFM, EXR, PNG or PPM (P3/P6) file into a new linear image
 * (8-bit inputs are taken as sRGB and linearised).  *out is the caller's. */
zt_status zt_image_read(const char *path, zt_image **out, zt_error *err);

/* Differences between an image and a reference of the same size. */
typedef struct zt_compare_result {
    double rel_rmse;   /* rmse / mean(reference) */
    double rmse;       /* sqrt(mean((a-b)^2)) over pixels and channels */
    double psnr;       /* 20 log10(max(reference) / rmse), in dB; inf if equal */
    double mean_a[3];  /* per-channel means */
    double mean_b[3];
} zt_compare_result;

/* Compares image a against reference b.  Fails with ZT_ERR_ARGUMENT when
 * the sizes differ. */
zt_status zt_image_compare(const zt_image *a, const zt_image *b,
                           zt_compare_result *out, zt_error *err);

/* a's own error against a noisy reference b: the relative RMSE with b's
 * noise taken out, sqrt(max(0, sum (a-b)^2 - scale x sum variance)) /
 * (sqrt(3 pixels) mean(b)), variance holding each pixel's variance of b's
 * mean per channel (bench_reference --noise writes it).  An image equal to
 * b's expectation scores 0 up to the noise of the variance estimate.  scale
 * is 1 for the images as they are; for images averaged over k x k blocks
 * (zt_image_downsample, the variance image too) it is 1 / k^2.  Fails with
 * ZT_ERR_ARGUMENT when the sizes differ. */
zt_status zt_image_own_error(const zt_image *a, const zt_image *b, const zt_image *variance,
                             double scale, double *out, zt_error *err);

/* A new image whose pixels are the means of factor x factor blocks of src
 * (the size must divide evenly).  NULL on bad arguments or out of memory. */
zt_image *zt_image_downsample(const zt_image *src, int factor);

#ifdef __cplusplus
}
#endif
#endif
