/* From linear HDR values to 8-bit ones: exposure, transfer curve, clamp,
 * round to nearest.  Also the automatic exposure and the inverse sRGB curve
 * the 8-bit readers use. */
#include "image/image_io.h"

#include <math.h>
#include <stdlib.h>

#define AUTO_PERCENTILE 0.99
#define AUTO_TARGET 0.9

zt_tonemap zt_tonemap_default(void)
{
    zt_tonemap t = {.auto_exposure = 1, .exposure = 0.0, .gamma = 0.0};
    return t;
}

static int compare_floats(const void *pa, const void *pb)
{
    float a = *(const float *)pa, b = *(const float *)pb;
    return (a > b) - (a < b);
}

/* A full sort rather than a histogram: exact, deterministic, and the copy
 * costs a third of the image's own memory. */
double zt_image_auto_exposure(const zt_image *image)
{
    if (!image_valid(image))
        return 0.0;
    size_t count = (size_t)image->width * (size_t)image->height;
    float *lum = malloc(count * sizeof *lum);
    if (!lum)
        return 0.0;
    size_t n = 0;
    for (size_t i = 0; i < count; i++) {
        const float *p = image->pixels + i * 3;
        double y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        if (isfinite(y))
            lum[n++] = (float)y;
    }
    double ev = 0.0;
    if (n > 0) {
        qsort(lum, n, sizeof *lum, compare_floats);
        /* nearest-rank percentile: the smallest value with at least 99% of
         * the samples at or below it */
        size_t rank = (size_t)ceil(AUTO_PERCENTILE * (double)n);
        double p99 = lum[rank > 0 ? rank - 1 : 0];
        if (p99 > 0.0)
            ev = log2(AUTO_TARGET / p99);
    }
    free(lum);
    return ev;
}

static double linear_to_srgb(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

double srgb_to_linear(double v)
{
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

static uint8_t to_byte(double v, double scale, double gamma)
{
    v *= scale;
    if (!(v > 0.0)) /* also NaN */
        return 0;
    if (v >= 1.0)
        return 255;
    v = gamma == 0.0 ? linear_to_srgb(v) : gamma == 1.0 ? v : pow(v, 1.0 / gamma);
    v = floor(v * 255.0 + 0.5);
    return (uint8_t)(v > 255.0 ? 255.0 : v);
}

uint8_t *tonemap_to_rgb8(const zt_image *image, const zt_tonemap *tonemap)
{
    zt_tonemap tm = tonemap ? *tonemap : zt_tonemap_default();
    size_t count = (size_t)image->width * (size_t)image->height * 3;
    uint8_t *out = malloc(count);
    if (!out)
        return NULL;
    double ev = tm.auto_exposure ? zt_image_auto_exposure(image) : tm.exposure;
    double scale = exp2(ev);
    for (size_t i = 0; i < count; i++)
        out[i] = to_byte(image->pixels[i], scale, tm.gamma);
    return out;
}
