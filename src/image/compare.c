/* Error figures between a render and a reference, over all pixels and
 * channels of the linear images.  Double accumulators: a 2^28-pixel image
 * summed in float would lose most of its digits.  NaN pixels are not
 * skipped; they make the figures NaN, which is the honest answer. */
#include "image/image_io.h"

#include <math.h>

#include "util/error.h"

zt_status zt_image_compare(const zt_image *a, const zt_image *b,
                           zt_compare_result *out, zt_error *err)
{
    if (!out || !image_valid(a) || !image_valid(b))
        return zt_fail(err, ZT_ERR_ARGUMENT, "compare: missing or invalid image");
    if (a->width != b->width || a->height != b->height)
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "compare: sizes differ (%d x %d against reference %d x %d)",
                       a->width, a->height, b->width, b->height);
    size_t pixels = (size_t)a->width * (size_t)a->height;
    double sum_a[3] = {0, 0, 0}, sum_b[3] = {0, 0, 0}, sum_sq = 0.0;
    double max_b = -INFINITY;
    for (size_t i = 0; i < pixels; i++) {
        for (int c = 0; c < 3; c++) {
            double va = a->pixels[3 * i + (size_t)c], vb = b->pixels[3 * i + (size_t)c];
            double d = va - vb;
            sum_a[c] += va;
            sum_b[c] += vb;
            sum_sq += d * d;
            if (vb > max_b)
                max_b = vb;
        }
    }
    double mean_b = 0.0;
    for (int c = 0; c < 3; c++) {
        out->mean_a[c] = sum_a[c] / (double)pixels;
        out->mean_b[c] = sum_b[c] / (double)pixels;
        mean_b += out->mean_b[c] / 3.0;
    }
    out->rmse = sqrt(sum_sq / (double)(3 * pixels));
    /* a black reference: only an exact match has no relative error */
    out->rel_rmse = mean_b != 0.0 ? out->rmse / mean_b
                  : out->rmse == 0.0 ? 0.0 : INFINITY;
    if (out->rmse == 0.0)
        out->psnr = INFINITY;
    else if (max_b > 0.0)
        out->psnr = 20.0 * log10(max_b / out->rmse);
    else
        out->psnr = -INFINITY; /* no positive peak to speak of */
    return ZT_OK;
}

zt_status zt_image_own_error(const zt_image *a, const zt_image *b, const zt_image *variance,
                             double scale, double *out, zt_error *err)
{
    zt_compare_result r;
    zt_status st = zt_image_compare(a, b, &r, err);
    if (st != ZT_OK)
        return st;
    if (!image_valid(variance) || !out || !(scale > 0))
        return zt_fail(err, ZT_ERR_ARGUMENT, "own error: missing variance image or bad scale");
    if (variance->width != b->width || variance->height != b->height)
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "own error: the variance image is %d x %d, the reference %d x %d",
                       variance->width, variance->height, b->width, b->height);
    size_t values = 3 * (size_t)b->width * (size_t)b->height;
    double var = 0.0;
    for (size_t i = 0; i < values; i++)
        var += variance->pixels[i];
    double mean_b = (r.mean_b[0] + r.mean_b[1] + r.mean_b[2]) / 3.0;
    double own2 = r.rmse * r.rmse - scale * var / (double)values;
    *out = mean_b != 0.0 ? sqrt(own2 > 0.0 ? own2 : 0.0) / mean_b : r.rel_rmse;
    return ZT_OK;
}
