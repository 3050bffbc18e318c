/* Image buffers: creation, release, size checks and box downsampling. */
#include "image/image_io.h"

#include <stdlib.h>

int image_size_ok(long width, long height)
{
    return width > 0 && height > 0 && width <= ZT_IMAGE_MAX_SIDE &&
           height <= ZT_IMAGE_MAX_SIDE && width * height <= ZT_IMAGE_MAX_PIXELS;
}

int image_valid(const zt_image *image)
{
    return image && image->pixels && image_size_ok(image->width, image->height);
}

zt_image *zt_image_create(int width, int height)
{
    if (!image_size_ok(width, height))
        return NULL;
    zt_image *image = malloc(sizeof *image);
    if (!image)
        return NULL;
    image->width = width;
    image->height = height;
    image->pixels = calloc((size_t)width * (size_t)height * 3, sizeof(float));
    if (!image->pixels) {
        free(image);
        return NULL;
    }
    return image;
}

void zt_image_release(zt_image *image)
{
    if (!image)
        return;
    free(image->pixels);
    free(image);
}

zt_image *zt_image_downsample(const zt_image *src, int factor)
{
    if (!image_valid(src) || factor < 1 || src->width % factor != 0 ||
        src->height % factor != 0)
        return NULL;
    zt_image *dst = zt_image_create(src->width / factor, src->height / factor);
    if (!dst)
        return NULL;
    double inv_count = 1.0 / ((double)factor * factor);
    for (int y = 0; y < dst->height; y++) {
        for (int x = 0; x < dst->width; x++) {
            double sum[3] = {0, 0, 0};
            for (int j = 0; j < factor; j++) {
                const float *row = zt_image_pixel(src, x * factor, y * factor + j);
                for (int i = 0; i < factor * 3; i += 3) {
                    sum[0] += row[i];
                    sum[1] += row[i + 1];
                    sum[2] += row[i + 2];
                }
            }
            float *out = zt_image_pixel(dst, x, y);
            for (int c = 0; c < 3; c++)
                out[c] = (float)(sum[c] * inv_count);
        }
    }
    return dst;
}
