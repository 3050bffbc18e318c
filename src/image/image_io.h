/* Inside the image module: size limits, the per-format readers and writers
 * that format.c dispatches to, and the 8-bit conversions they share.
 *
 * Writers get an open stream (the atomic temporary, or stdout) and the name
 * to use in messages; they report failures but never close the stream.
 * Readers get a stream positioned at the start of the file; on success
 * *out is a new image, on failure it is left NULL.
 */
#ifndef ZT_IMAGE_IMAGE_IO_H
#define ZT_IMAGE_IMAGE_IO_H

#include <stdint.h>
#include <stdio.h>
#include "zonetrace/image.h"

/* Limits for every image, so that a hostile header cannot make the reader
 * allocate gigabytes (2^28 pixels is 3 GiB of floats). */
#define ZT_IMAGE_MAX_SIDE 32768
#define ZT_IMAGE_MAX_PIXELS (1L << 28)

/* Non-zero when width x height is within the limits above. */
int image_size_ok(long width, long height);

/* Non-zero when image is non-NULL, has pixels and a valid size. */
int image_valid(const zt_image *image);

zt_status pfm_write(FILE *stream, const zt_image *image, const char *name, zt_error *err);
zt_status pfm_read(FILE *stream, const char *name, zt_image **out, zt_error *err);

/* The EXR code does positioned I/O on fileno(stream). */
zt_status exr_write_image(FILE *stream, const zt_image *image, const char *name, zt_error *err);
zt_status exr_read_image(FILE *stream, const char *name, zt_image **out, zt_error *err);

/* rgb: width*height*3 bytes, top row first.  gamma as in zt_tonemap, used
 * to tag the PNG (sRGB chunk for 0, gAMA 1/gamma otherwise). */
zt_status png_write_rgb8(FILE *stream, const uint8_t *rgb, int width, int height,
                         double gamma, const char *name, zt_error *err);
zt_status png_read(FILE *stream, const char *name, zt_image **out, zt_error *err);

zt_status ppm_write_rgb8(FILE *stream, const uint8_t *rgb, int width, int height,
                         const char *name, zt_error *err);
zt_status ppm_read(FILE *stream, const char *name, zt_image **out, zt_error *err);

/* Tonemaps image to width*height*3 bytes (malloc'd; NULL when out of
 * memory).  tonemap NULL means zt_tonemap_default(). */
uint8_t *tonemap_to_rgb8(const zt_image *image, const zt_tonemap *tonemap);

/* Bytes from the stream's position to its end, or -1 when it cannot seek
 * (readers then find truncation by reading).  Lets a reader reject a
 * header that promises more data than the file holds before allocating. */
long stream_bytes_left(FILE *stream);

/* Inverse of the sRGB transfer curve, for v in [0, 1]. */
double srgb_to_linear(double v);

#endif
