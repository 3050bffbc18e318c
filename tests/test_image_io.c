/* Image files: round trips through every format, orientation, tonemapping
 * to exact bytes, automatic exposure, hostile inputs and atomic writes. */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <OpenEXR/openexr.h>
#include <png.h>

#include "zonetrace/image.h"

static void assert_close(double actual, double expected, double tolerance)
{
    if (!(fabs(actual - expected) <= tolerance)) {
        fprintf(stderr, "expected %.9g, got %.9g (tolerance %g)\n", expected, actual,
                tolerance);
        fail();
    }
}

/* Every third float a distinct value, with large HDR values, tiny and
 * subnormal ones, negatives and zeros. */
static zt_image *make_hdr_image(int width, int height)
{
    static const float specials[] = {1177.6f, 1e-30f, 1.4e-44f, 0.0f, -0.0f, -3.25f,
                                     65504.0f, 3.0e38f, 0.1f, 1.0f / 3.0f};
    zt_image *image = zt_image_create(width, height);
    assert_non_null(image);
    size_t n = (size_t)width * (size_t)height * 3;
    for (size_t i = 0; i < n; i++)
        image->pixels[i] = i % 3 == 0 ? specials[(i / 3) % 10] : (float)i * 0.37f + 0.001f;
    return image;
}

static int count_temporaries(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strstr(e->d_name, ".tmp."))
            count++;
    closedir(d);
    return count;
}

static const char *fresh_dir(const char *name)
{
    const char *path = test_tmp_path(name);
    assert_int_equal(mkdir(path, 0777), 0);
    return path;
}

static char *join(const char *dir, const char *name)
{
    static char buf[4][600];
    static int next;
    char tmp[600];
    snprintf(tmp, sizeof tmp, "%s/%s", dir, name); /* dir may be one of buf */
    char *b = buf[next++ % 4];
    memcpy(b, tmp, sizeof tmp);
    return b;
}

static const char *write_bytes(const char *name, const void *data, size_t size)
{
    const char *path = test_tmp_path(name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    fclose(f);
    return path;
}

static zt_status read_status(const char *path)
{
    zt_image *image = (zt_image *)&image; /* must be reset to NULL on failure */
    zt_error err = {0};
    zt_status st = zt_image_read(path, &image, &err);
    if (st == ZT_OK) {
        zt_image_release(image);
    } else {
        assert_null(image);
        assert_int_equal(err.status, st);
        assert_true(strlen(err.message) > 0);
    }
    return st;
}

static zt_tonemap linear_tonemap(void)
{
    zt_tonemap tm = {.auto_exposure = 0, .exposure = 0.0, .gamma = 1.0};
    return tm;
}

/* ---- round trips ---- */

static void round_trip_hdr(const char *name, int width, int height)
{
    zt_image *image = make_hdr_image(width, height);
    image->pixels[1] = NAN; /* NaN is data: it must survive */
    zt_error err = {0};
    const char *path = test_tmp_path(name);
    assert_int_equal(zt_image_write(image, path, NULL, &err), ZT_OK);
    zt_image *back = NULL;
    assert_int_equal(zt_image_read(path, &back, &err), ZT_OK);
    assert_non_null(back);
    test_assert_same_image(image, back, "read back");
    zt_image_release(image);
    zt_image_release(back);
}

static void test_pfm_round_trip(void **state)
{
    (void)state;
    round_trip_hdr("rt.pfm", 7, 5);
    round_trip_hdr("rt1.pfm", 1, 1);
}

static void test_exr_round_trip(void **state)
{
    (void)state;
    /* 37 rows: several 16-line ZIP chunks and a partial last one */
    round_trip_hdr("rt.exr", 29, 37);
    round_trip_hdr("rt1.exr", 1, 1);
}

/* An EXR as another program might write it: HALF channels, a data window
 * that does not start at 0, an extra alpha channel, and either R, G, B or
 * a lone Y.  rgb holds width x height pixels, top row first. */
static void write_half_exr(const char *path, int width, int height, const float *rgb,
                           int grey, exr_compression_t compression)
{
    exr_context_t ctxt;
    int part;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init), 0);
    assert_int_equal(exr_add_part(ctxt, "beauty", EXR_STORAGE_SCANLINE, &part), 0);
    exr_attr_box2i_t data_window = {.min = {.x = 10, .y = 20},
                                    .max = {.x = 10 + width - 1, .y = 20 + height - 1}};
    exr_attr_box2i_t display_window = {.min = {.x = 0, .y = 0}, .max = {.x = 63, .y = 63}};
    exr_attr_v2f_t center = {.x = 0, .y = 0};
    assert_int_equal(exr_initialize_required_attr(ctxt, part, &display_window, &data_window,
                                                  1.0f, &center, 1.0f,
                                                  EXR_LINEORDER_INCREASING_Y, compression),
                     0);
    static const char *const rgb_names[3] = {"R", "G", "B"};
    for (int c = 0; c < (grey ? 1 : 3); c++)
        assert_int_equal(exr_add_channel(ctxt, part, grey ? "Y" : rgb_names[c],
                                         EXR_PIXEL_HALF, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1),
                         0);
    assert_int_equal(exr_add_channel(ctxt, part, "A", EXR_PIXEL_HALF,
                                     EXR_PERCEPTUALLY_LINEAR, 1, 1), 0);
    assert_int_equal(exr_write_header(ctxt), 0);
    int32_t lines;
    assert_int_equal(exr_get_scanlines_per_chunk(ctxt, part, &lines), 0);
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    for (int y = 0; y < height; y += lines) {
        exr_chunk_info_t chunk;
        assert_int_equal(exr_write_scanline_chunk_info(ctxt, part, 20 + y, &chunk), 0);
        assert_int_equal(y == 0 ? exr_encoding_initialize(ctxt, part, &chunk, &encoder)
                                : exr_encoding_update(ctxt, part, &chunk, &encoder), 0);
        for (int c = 0; c < encoder.channel_count; c++) {
            exr_coding_channel_info_t *ch = &encoder.channels[c];
            /* alpha gets the red values: it must be ignored */
            int index = ch->channel_name[0] == 'G' ? 1 : ch->channel_name[0] == 'B' ? 2 : 0;
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 12;
            ch->user_line_stride = 12 * width;
            ch->encode_from_ptr = (const uint8_t *)(rgb + (size_t)y * width * 3 + index);
        }
        assert_int_equal(exr_encoding_choose_default_routines(ctxt, part, &encoder), 0);
        assert_int_equal(exr_encoding_run(ctxt, part, &encoder), 0);
    }
    exr_encoding_destroy(ctxt, &encoder);
    assert_int_equal(exr_finish(&ctxt), 0);
}

static void test_exr_half_foreign(void **state)
{
    (void)state;
    enum { W = 5, H = 19 };
    float rgb[W * H * 3];
    /* values HALF holds exactly */
    for (int i = 0; i < W * H * 3; i++)
        rgb[i] = i % 3 == 2 ? 1024.0f * (float)(1 + i % 2) : (float)(i % 7) * 0.25f;
    static const exr_compression_t compressions[2] = {EXR_COMPRESSION_NONE,
                                                      EXR_COMPRESSION_ZIP};
    for (int grey = 0; grey < 2; grey++) {
        for (int k = 0; k < 2; k++) {
            const char *path = test_tmp_path("half.exr");
            write_half_exr(path, W, H, rgb, grey, compressions[k]);
            zt_image *image = NULL;
            zt_error err = {0};
            assert_int_equal(zt_image_read(path, &image, &err), ZT_OK);
            assert_int_equal(image->width, W);
            assert_int_equal(image->height, H);
            for (int i = 0; i < W * H * 3; i++)
                assert_true(image->pixels[i] == (grey ? rgb[i / 3 * 3] : rgb[i]));
            zt_image_release(image);
        }
    }
}

static void test_pfm_bytes_bottom_row_first(void **state)
{
    (void)state;
    zt_image *image = zt_image_create(2, 2);
    for (int x = 0; x < 2; x++)
        for (int c = 0; c < 3; c++) {
            zt_image_pixel(image, x, 0)[c] = 1.0f; /* top */
            zt_image_pixel(image, x, 1)[c] = 2.0f; /* bottom */
        }
    zt_error err = {0};
    const char *path = test_tmp_path("orient.pfm");
    assert_int_equal(zt_image_write(image, path, NULL, &err), ZT_OK);
    size_t length;
    char *bytes = test_read_file(path, &length);
    static const char header[] = "PF\n2 2\n-1.0\n";
    size_t h = sizeof header - 1;
    assert_int_equal(length, h + 2 * 2 * 3 * 4);
    assert_memory_equal(bytes, header, h);
    /* little-endian 2.0f (bottom row) comes first, 1.0f (top) last */
    static const unsigned char two[4] = {0x00, 0x00, 0x00, 0x40};
    static const unsigned char one[4] = {0x00, 0x00, 0x80, 0x3f};
    assert_memory_equal(bytes + h, two, 4);
    assert_memory_equal(bytes + length - 4, one, 4);
    free(bytes);
    zt_image_release(image);
}

static void test_top_row_stays_top(void **state)
{
    (void)state;
    static const char *names[] = {"top.pfm", "top.exr", "top.png", "top.ppm"};
    zt_tonemap tm = linear_tonemap();
    zt_image *image = zt_image_create(3, 4);
    for (int x = 0; x < 3; x++)
        for (int c = 0; c < 3; c++)
            zt_image_pixel(image, x, 0)[c] = 0.75f; /* only the top row is lit */
    for (int i = 0; i < 4; i++) {
        zt_error err = {0};
        const char *path = test_tmp_path(names[i]);
        assert_int_equal(zt_image_write(image, path, &tm, &err), ZT_OK);
        zt_image *back = NULL;
        assert_int_equal(zt_image_read(path, &back, &err), ZT_OK);
        assert_int_equal(back->width, 3);
        assert_int_equal(back->height, 4);
        assert_true(zt_image_pixel(back, 1, 0)[0] > 0.3f);
        assert_true(zt_image_pixel(back, 1, 3)[0] == 0.0f);
        zt_image_release(back);
    }
    zt_image_release(image);
}

/* ---- 8-bit output ---- */

#define N_KNOWN 8
static const float known_in[N_KNOWN] = {0.0f, 0.5f, 1.0f, 0.25f, 2.0f, -1.0f, 0.1f, 0.0019f};
/* floor(255 x + 0.5), clamped; 0.0019 -> 0.4845 rounds down */
static const unsigned char known_out[N_KNOWN] = {0, 128, 255, 64, 255, 0, 26, 0};

static zt_image *make_known_row(void)
{
    zt_image *image = zt_image_create(N_KNOWN, 1);
    for (int x = 0; x < N_KNOWN; x++)
        for (int c = 0; c < 3; c++)
            zt_image_pixel(image, x, 0)[c] = known_in[x];
    zt_image_pixel(image, 0, 0)[1] = NAN; /* NaN becomes 0 */
    return image;
}

static void test_ppm_exact_bytes(void **state)
{
    (void)state;
    zt_image *image = make_known_row();
    zt_tonemap tm = linear_tonemap();
    zt_error err = {0};
    const char *path = test_tmp_path("bytes.ppm");
    assert_int_equal(zt_image_write(image, path, &tm, &err), ZT_OK);
    size_t length;
    unsigned char *bytes = (unsigned char *)test_read_file(path, &length);
    static const char header[] = "P6\n8 1\n255\n";
    size_t h = sizeof header - 1;
    assert_int_equal(length, h + N_KNOWN * 3);
    assert_memory_equal(bytes, header, h);
    for (int x = 0; x < N_KNOWN; x++)
        for (int c = 0; c < 3; c++)
            assert_int_equal(bytes[h + (size_t)x * 3 + (size_t)c], known_out[x]);
    free(bytes);
    zt_image_release(image);
}

static void test_png_exact_bytes(void **state)
{
    (void)state;
    zt_image *image = make_known_row();
    zt_tonemap tm = linear_tonemap();
    zt_error err = {0};
    const char *path = test_tmp_path("bytes.png");
    assert_int_equal(zt_image_write(image, path, &tm, &err), ZT_OK);
    /* written with gAMA 1.0, so it reads back as code/255 exactly */
    zt_image *back = NULL;
    assert_int_equal(zt_image_read(path, &back, &err), ZT_OK);
    for (int x = 0; x < N_KNOWN; x++)
        for (int c = 0; c < 3; c++)
            assert_float_equal(zt_image_pixel(back, x, 0)[c], known_out[x] / 255.0f, 1e-7);
    zt_image_release(back);
    zt_image_release(image);
}

static unsigned char first_ppm_byte(float value, zt_tonemap tm)
{
    zt_image *image = zt_image_create(1, 1);
    for (int c = 0; c < 3; c++)
        image->pixels[c] = value;
    zt_error err = {0};
    const char *path = test_tmp_path("one.ppm");
    assert_int_equal(zt_image_write(image, path, &tm, &err), ZT_OK);
    size_t length;
    char *bytes = test_read_file(path, &length);
    unsigned char b = (unsigned char)bytes[length - 3];
    free(bytes);
    zt_image_release(image);
    return b;
}

static void test_tonemap_curves(void **state)
{
    (void)state;
    zt_tonemap tm = linear_tonemap();
    tm.exposure = 1.0; /* 0.25 * 2 = 0.5 */
    assert_int_equal(first_ppm_byte(0.25f, tm), 128);
    tm.exposure = -2.0; /* 2 / 4 = 0.5 */
    assert_int_equal(first_ppm_byte(2.0f, tm), 128);
    tm.exposure = 0.0;
    tm.gamma = 2.2; /* 0.5^(1/2.2) = 0.7297 -> 186.08 */
    assert_int_equal(first_ppm_byte(0.5f, tm), 186);
    tm.gamma = 0.0; /* sRGB: 0.5 -> 0.7354 -> 187.52 */
    assert_int_equal(first_ppm_byte(0.5f, tm), 188);
    assert_int_equal(first_ppm_byte(0.002f, tm), 7); /* linear toe: 12.92 x */

    zt_tonemap def = zt_tonemap_default();
    assert_int_equal(def.auto_exposure, 1);
    assert_true(def.exposure == 0.0 && def.gamma == 0.0);

    zt_image *image = zt_image_create(1, 1);
    zt_error err = {0};
    tm.gamma = -1.0;
    assert_int_equal(zt_image_write(image, test_tmp_path("badgamma.png"), &tm, &err),
                     ZT_ERR_ARGUMENT);
    tm.gamma = 1.0;
    tm.exposure = NAN;
    assert_int_equal(zt_image_write(image, test_tmp_path("badev.ppm"), &tm, &err),
                     ZT_ERR_ARGUMENT);
    zt_image_release(image);
}

static void test_srgb_png_round_trip(void **state)
{
    (void)state;
    zt_image *image = zt_image_create(16, 1);
    for (int x = 0; x < 16; x++)
        for (int c = 0; c < 3; c++)
            zt_image_pixel(image, x, 0)[c] = (float)x / 15.0f;
    zt_tonemap tm = {.auto_exposure = 0, .exposure = 0.0, .gamma = 0.0};
    zt_error err = {0};
    const char *path = test_tmp_path("srgb.png");
    assert_int_equal(zt_image_write(image, path, &tm, &err), ZT_OK);
    zt_image *back = NULL;
    assert_int_equal(zt_image_read(path, &back, &err), ZT_OK);
    /* half an 8-bit step of the sRGB curve is at most ~0.0045 in linear */
    for (int i = 0; i < 48; i++)
        assert_float_equal(back->pixels[i], image->pixels[i], 0.005);
    zt_image_release(back);
    zt_image_release(image);
}

/* A 3 x 2 PNG as another program might write it; pixel i has code i % 4
 * (a palette index, or a grey level of 60 per step with alpha 128). */
static void write_foreign_png(const char *path, int color, int depth, int interlace)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_set_IHDR(png, info, 3, 2, depth, color, interlace, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    if (color == PNG_COLOR_TYPE_PALETTE) {
        png_color palette[4] = {{0, 0, 0}, {255, 0, 0}, {0, 255, 0}, {0, 0, 255}};
        png_byte alpha[2] = {0, 128}; /* tRNS: becomes alpha when expanded */
        png_set_PLTE(png, info, palette, 4);
        png_set_tRNS(png, info, alpha, 2, NULL);
    } else {
        png_set_gAMA(png, info, 1.0); /* linear, to check exact values */
    }
    png_write_info(png, info);
    unsigned char rows[2][16] = {{0}};
    for (int y = 0; y < 2; y++) {
        for (int x = 0; x < 3; x++) {
            int code = y * 3 + x;
            if (color == PNG_COLOR_TYPE_PALETTE) {
                rows[y][0] |= (unsigned char)((code % 4) << (6 - 2 * x)); /* 2-bit */
            } else { /* 16-bit grey + alpha, big-endian */
                rows[y][x * 4] = (unsigned char)(code % 4 * 60);
                rows[y][x * 4 + 2] = 0x80;
            }
        }
    }
    png_bytep row_pointers[2] = {rows[0], rows[1]};
    png_write_image(png, row_pointers);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    fclose(f);
}

static void test_png_foreign(void **state)
{
    (void)state;
    zt_image *image = NULL;
    zt_error err = {0};
    const char *path = test_tmp_path("palette.png");
    write_foreign_png(path, PNG_COLOR_TYPE_PALETTE, 2, PNG_INTERLACE_NONE);
    assert_int_equal(zt_image_read(path, &image, &err), ZT_OK);
    static const float expected[6][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0},
                                         {0, 0, 1}, {0, 0, 0}, {1, 0, 0}};
    assert_memory_equal(image->pixels, expected, sizeof expected);
    zt_image_release(image);

    path = test_tmp_path("grey-alpha.png");
    write_foreign_png(path, PNG_COLOR_TYPE_GRAY_ALPHA, 16, PNG_INTERLACE_ADAM7);
    assert_int_equal(zt_image_read(path, &image, &err), ZT_OK);
    for (int i = 0; i < 6; i++)
        for (int c = 0; c < 3; c++)
            assert_float_equal(image->pixels[i * 3 + c], (i % 4) * 60 * 256 / 65535.0f, 1e-7);
    zt_image_release(image);
}

static void test_stdout_ppm(void **state)
{
    (void)state;
    zt_image *image = make_known_row();
    zt_tonemap tm = linear_tonemap();
    const char *path = test_tmp_path("stdout.ppm");
    fflush(stdout);
    int saved = dup(1);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 1);
    zt_error err = {0};
    zt_status st = zt_image_write(image, "-", &tm, &err);
    fflush(stdout);
    dup2(saved, 1);
    close(saved);
    close(fd);
    assert_int_equal(st, ZT_OK);
    size_t length;
    char *bytes = test_read_file(path, &length);
    assert_int_equal(length, strlen("P6\n8 1\n255\n") + N_KNOWN * 3);
    assert_memory_equal(bytes, "P6\n8 1\n255\n", 11);
    assert_int_equal((unsigned char)bytes[11 + 3], 128);
    free(bytes);
    zt_image_release(image);
}

/* ---- automatic exposure ---- */

static void test_auto_exposure(void **state)
{
    (void)state;
    zt_image *image = zt_image_create(10, 11);
    /* 100 grey pixels 0.01 .. 1.00, and 10 non-finite ones to ignore */
    for (int i = 0; i < 100; i++)
        for (int c = 0; c < 3; c++)
            image->pixels[i * 3 + c] = (float)(i + 1) / 100.0f;
    for (int i = 100; i < 110; i++)
        image->pixels[i * 3 + (i % 3)] = i % 2 ? NAN : INFINITY;
    /* nearest rank: the 99th of 100 values, 0.99 */
    assert_close(zt_image_auto_exposure(image), log2(0.9 / 0.99), 1e-6);

    /* coloured: luminance weights 0.2126, 0.7152, 0.0722 */
    zt_image *green = zt_image_create(1, 1);
    green->pixels[1] = 2.0f;
    assert_close(zt_image_auto_exposure(green), log2(0.9 / (0.7152 * 2.0)), 1e-6);

    zt_image *black = zt_image_create(4, 4);
    assert_true(zt_image_auto_exposure(black) == 0.0);
    assert_true(zt_image_auto_exposure(NULL) == 0.0);

    /* the chosen exposure maps the 99th percentile to 0.9 of full scale */
    zt_tonemap tm = {.auto_exposure = 1, .exposure = 5.0, .gamma = 1.0};
    zt_error err = {0};
    const char *path = test_tmp_path("auto.ppm");
    assert_int_equal(zt_image_write(image, path, &tm, &err), ZT_OK);
    size_t length;
    unsigned char *bytes = (unsigned char *)test_read_file(path, &length);
    size_t pixel98 = length - 110 * 3 + 98 * 3;
    /* 0.9 * 255 = 229.5 sits on a rounding edge: either neighbour will do */
    assert_true(bytes[pixel98] == 229 || bytes[pixel98] == 230);
    free(bytes);
    zt_image_release(image);
    zt_image_release(green);
    zt_image_release(black);
}

/* Values in [0, 1) that no compressor can shrink much. */
static zt_image *make_noise_image(int width, int height)
{
    zt_image *image = zt_image_create(width, height);
    uint32_t state = 12345;
    for (size_t i = 0; i < (size_t)width * height * 3; i++) {
        state = state * 1664525u + 1013904223u;
        image->pixels[i] = (float)(state >> 8) / 16777216.0f;
    }
    return image;
}

/* ---- readers on hand-made files ---- */

static void put_le(unsigned char *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(u >> (8 * i));
}

static void put_be(unsigned char *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    for (int i = 0; i < 4; i++)
        p[3 - i] = (unsigned char)(u >> (8 * i));
}

static void test_pfm_variants(void **state)
{
    (void)state;
    unsigned char buf[64];
    zt_image *image = NULL;
    zt_error err = {0};

    /* big-endian (positive scale), scale magnitude ignored */
    size_t h = (size_t)sprintf((char *)buf, "PF\n1 1\n4.0\n");
    put_be(buf + h, 1.5f);
    put_be(buf + h + 4, -2.0f);
    put_be(buf + h + 8, 1177.6f);
    assert_int_equal(zt_image_read(write_bytes("be.pfm", buf, h + 12), &image, &err), ZT_OK);
    assert_true(image->pixels[0] == 1.5f && image->pixels[1] == -2.0f &&
                image->pixels[2] == 1177.6f);
    zt_image_release(image);

    /* greyscale, replicated; rows bottom first */
    h = (size_t)sprintf((char *)buf, "Pf\n1 2\n-1\n");
    put_le(buf + h, 0.25f);     /* bottom */
    put_le(buf + h + 4, NAN);   /* top: NaN is data */
    assert_int_equal(zt_image_read(write_bytes("grey.pfm", buf, h + 8), &image, &err), ZT_OK);
    for (int c = 0; c < 3; c++) {
        assert_true(isnan(zt_image_pixel(image, 0, 0)[c]));
        assert_true(zt_image_pixel(image, 0, 1)[c] == 0.25f);
    }
    zt_image_release(image);
}

static void test_ppm_readers(void **state)
{
    (void)state;
    zt_image *image = NULL;
    zt_error err = {0};
    /* P3 with comments; maxval 255; values are sRGB-decoded */
    const char *p3 = test_write_file("a.ppm", "P3\n# a comment\n2 1 # more\n255\n"
                                              "0 255 128\n255 0 0\n");
    assert_int_equal(zt_image_read(p3, &image, &err), ZT_OK);
    assert_int_equal(image->width, 2);
    assert_true(image->pixels[0] == 0.0f && image->pixels[1] == 1.0f);
    assert_float_equal(image->pixels[2], 0.21586f, 1e-4); /* sRGB 128 */
    assert_true(image->pixels[3] == 1.0f);
    zt_image_release(image);

    /* P6 with maxval 65535: two bytes per sample, big-endian */
    unsigned char p6[32];
    size_t h = (size_t)sprintf((char *)p6, "P6\n1 1\n65535\n");
    static const unsigned char samples[6] = {0xff, 0xff, 0x00, 0x00, 0x00, 0x01};
    memcpy(p6 + h, samples, 6);
    assert_int_equal(zt_image_read(write_bytes("b.ppm", p6, h + 6), &image, &err), ZT_OK);
    assert_true(image->pixels[0] == 1.0f && image->pixels[1] == 0.0f);
    assert_float_equal(image->pixels[2], (float)(1.0 / 65535 / 12.92), 1e-9);
    zt_image_release(image);
}

static void test_reference_pfm(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    char path[512];
    if (shared)
        snprintf(path, sizeof path, "%s/reference/cornell-cycles-2048spp.pfm", shared);
    if (!shared || access(path, R_OK) != 0) {
        fprintf(stderr, "note: reference PFM absent; test skipped\n");
        skip();
    }
    zt_image *image = NULL;
    zt_error err = {0};
    assert_int_equal(zt_image_read(path, &image, &err), ZT_OK);
    assert_int_equal(image->width, 512);
    assert_int_equal(image->height, 512);
    zt_compare_result r;
    assert_int_equal(zt_image_compare(image, image, &r, &err), ZT_OK);
    assert_close(r.mean_a[0], 15.991, 0.0005);
    assert_close(r.mean_a[1], 12.015, 0.0005);
    assert_close(r.mean_a[2], 5.481, 0.0005);
    zt_image_release(image);
}

/* Blender wrote a PNG of the reference at -5 EV through the sRGB curve;
 * ours from the PFM must agree to within one 8-bit step (which also checks
 * that the PFM is read the right way up). */
static void test_reference_png_agrees(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    char pfm[512], png[512];
    if (shared) {
        snprintf(pfm, sizeof pfm, "%s/reference/cornell-cycles-2048spp.pfm", shared);
        snprintf(png, sizeof png, "%s/reference/cornell-cycles-2048spp.png", shared);
    }
    if (!shared || access(pfm, R_OK) != 0 || access(png, R_OK) != 0) {
        fprintf(stderr, "note: reference images absent; test skipped\n");
        skip();
    }
    zt_image *hdr = NULL, *theirs = NULL, *ours = NULL;
    zt_error err = {0};
    assert_int_equal(zt_image_read(pfm, &hdr, &err), ZT_OK);
    assert_int_equal(zt_image_read(png, &theirs, &err), ZT_OK);
    zt_tonemap tm = {.auto_exposure = 0, .exposure = -5.0, .gamma = 0.0};
    const char *path = test_tmp_path("cornell.png");
    assert_int_equal(zt_image_write(hdr, path, &tm, &err), ZT_OK);
    assert_int_equal(zt_image_read(path, &ours, &err), ZT_OK);
    size_t n = (size_t)512 * 512 * 3;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)ours->pixels[i] - theirs->pixels[i]);
        assert_true(d < 0.01); /* one step near white is 0.0089 */
        sum += d;
    }
    assert_true(sum / (double)n < 1e-5);
    zt_image_release(hdr);
    zt_image_release(theirs);
    zt_image_release(ours);
}

/* ---- hostile inputs ---- */

static void test_bad_pfm(void **state)
{
    (void)state;
    assert_int_equal(read_status(test_write_file("garbage.pfm", "hello, world")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("empty.pfm", "")), ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("huge.pfm", "PF\n100000 100000\n-1.0\n")),
                     ZT_ERR_PARSE);
    /* each side within the limit, but more than 2^28 pixels */
    assert_int_equal(read_status(test_write_file("wide.pfm", "PF\n32768 8193\n-1.0\n")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("overflow.pfm",
                                                 "PF\n99999999999999999999 1\n-1.0\n")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("neg.pfm", "PF\n-4 4\n-1.0\n")), ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("zero.pfm", "PF\n0 4\n-1.0\n")), ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("scale0.pfm", "PF\n1 1\n0\n123456789012")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("scalenan.pfm", "PF\n1 1\nnan\n123456789012")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("magic.pfm", "PG\n1 1\n-1\n123456789012")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("nosep.pfm", "PF1 1\n-1\n123456789012")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("short.pfm", "PF\n4 4\n-1.0\n0123456789")),
                     ZT_ERR_PARSE);
    /* header only, exactly one byte short, exactly right */
    assert_int_equal(read_status(test_write_file("noheader.pfm", "PF\n1 1\n-1.0")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("oneshort.pfm", "PF\n1 1\n-1.0\n12345678901")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("exact.pfm", "PF\n1 1\n-1.0\n123456789012")),
                     ZT_OK);
    assert_int_equal(read_status(test_tmp_path("does-not-exist.pfm")), ZT_ERR_READ);

    zt_error err = {0};
    assert_int_equal(zt_image_read(test_tmp_path("x.pfm"), NULL, &err), ZT_ERR_ARGUMENT);
}

static void test_bad_ppm(void **state)
{
    (void)state;
    assert_int_equal(read_status(test_write_file("m0.ppm", "P6\n1 1\n0\nabc")), ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("mbig.ppm", "P6\n1 1\n65536\nabc")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("short6.ppm", "P6\n2 2\n255\nabc")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("short3.ppm", "P3\n2 1\n255\n1 2 3 4 5")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("over3.ppm", "P3\n1 1\n15\n1 2 16\n")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("junk3.ppm", "P3\n1 1\n255\n1 x 3\n")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("huge.ppm", "P6\n40000 40000\n255\n")),
                     ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("p5.ppm", "P5\n1 1\n255\na")), ZT_ERR_PARSE);
    assert_int_equal(read_status(test_write_file("ok6.ppm", "P6\n1 1\n255\nabc")), ZT_OK);
}

/* Writes a valid file in the format, then reads truncated and corrupted
 * copies: never a crash; a failure always comes with a message. */
static void truncations(const char *name)
{
    zt_image *image = make_hdr_image(40, 20);
    zt_tonemap tm = linear_tonemap();
    zt_error err = {0};
    const char *path = test_tmp_path(name);
    assert_int_equal(zt_image_write(image, path, &tm, &err), ZT_OK);
    size_t length;
    char *bytes = test_read_file(path, &length);
    char cut_name[64];
    snprintf(cut_name, sizeof cut_name, "cut-%s", name);
    size_t cuts[] = {0, 3, 4, 8, 20, length / 3, length / 2, length - 20, length - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++)
        assert_int_not_equal(read_status(write_bytes(cut_name, bytes, cuts[i])), ZT_OK);
    /* random bytes overwritten (half the time in the header): any status
     * will do, as long as nothing crashes (ASan watches) */
    char *mutant = malloc(length);
    uint32_t seed = 7;
    for (int round = 0; round < 150; round++) {
        memcpy(mutant, bytes, length);
        size_t span = round % 2 && length > 300 ? 300 : length;
        for (int k = 0; k < 1 + round % 8; k++) {
            seed = seed * 1664525u + 1013904223u;
            mutant[(seed >> 8) % span] = (char)(seed >> 24);
        }
        (void)read_status(write_bytes(cut_name, mutant, length));
    }
    free(mutant);
    free(bytes);
    zt_image_release(image);
}

static void test_truncated_files(void **state)
{
    (void)state;
    truncations("t.pfm");
    truncations("t.exr");
    truncations("t.png");
    truncations("t.ppm");
    static const unsigned char exr_magic_only[] = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 'x'};
    assert_int_equal(read_status(write_bytes("magic.exr", exr_magic_only,
                                             sizeof exr_magic_only)),
                     ZT_ERR_PARSE);
}

/* ---- writing ---- */

static void test_format_from_path(void **state)
{
    (void)state;
    assert_int_equal(zt_image_format_from_path("a.pfm"), ZT_FORMAT_PFM);
    assert_int_equal(zt_image_format_from_path("dir/A.EXR"), ZT_FORMAT_EXR);
    assert_int_equal(zt_image_format_from_path("x.y.Png"), ZT_FORMAT_PNG);
    assert_int_equal(zt_image_format_from_path("out.ppm"), ZT_FORMAT_PPM);
    assert_int_equal(zt_image_format_from_path("-"), ZT_FORMAT_PPM);
    assert_int_equal(zt_image_format_from_path("dir.png/file"), ZT_FORMAT_UNKNOWN);
    assert_int_equal(zt_image_format_from_path("image.jpg"), ZT_FORMAT_UNKNOWN);
    assert_int_equal(zt_image_format_from_path("pfm"), ZT_FORMAT_UNKNOWN);
    assert_int_equal(zt_image_format_from_path("a.pfmx"), ZT_FORMAT_UNKNOWN);
    assert_int_equal(zt_image_format_from_path(NULL), ZT_FORMAT_UNKNOWN);
}

static void test_write_errors(void **state)
{
    (void)state;
    const char *dir = fresh_dir("werr");
    zt_image *image = zt_image_create(2, 2);
    zt_error err = {0};

    assert_int_equal(zt_image_write(image, join(dir, "a.jpg"), NULL, &err), ZT_ERR_ARGUMENT);
    assert_non_null(strstr(err.message, ".pfm .exr .png .ppm"));
    assert_non_null(strstr(err.message, "a.jpg"));

    assert_int_equal(zt_image_write(image, join(dir, "missing/a.pfm"), NULL, &err),
                     ZT_ERR_WRITE);
    assert_non_null(strstr(err.message, "missing/a.pfm"));
    assert_non_null(strstr(err.message, "No such file or directory"));

    /* a read-only directory (root writes anyway, so only as a user) */
    if (geteuid() != 0) {
        const char *locked = join(dir, "locked");
        assert_int_equal(mkdir(locked, 0555), 0);
        assert_int_equal(zt_image_write(image, join(locked, "a.png"), NULL, &err),
                         ZT_ERR_WRITE);
        assert_non_null(strstr(err.message, "Permission denied"));
        assert_int_equal(count_temporaries(locked), 0);
    }

    /* a directory in the way: the rename fails after the data is written */
    const char *blocked = join(dir, "blocked.exr");
    assert_int_equal(mkdir(blocked, 0777), 0);
    assert_int_equal(zt_image_write(image, blocked, NULL, &err), ZT_ERR_WRITE);
    assert_non_null(strstr(err.message, "blocked.exr"));
    assert_int_equal(count_temporaries(dir), 0);

    zt_image bad = {.width = 0, .height = 2, .pixels = image->pixels};
    assert_int_equal(zt_image_write(&bad, join(dir, "b.pfm"), NULL, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_image_write(NULL, join(dir, "b.pfm"), NULL, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_image_write(image, NULL, NULL, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(count_temporaries(dir), 0);
    zt_image_release(image);
}

/* A write that fails half-way (the file size limit makes write() fail with
 * EFBIG) must leave the old target as it was and no temporary behind. */
static void test_failed_write_keeps_target(void **state)
{
    (void)state;
    static const char *names[] = {"keep.pfm", "keep.exr", "keep.png", "keep.ppm"};
    const char *dir = fresh_dir("keep");
    zt_image *image = make_noise_image(300, 300);
    for (int i = 0; i < 4; i++) {
        const char *target = join(dir, names[i]);
        FILE *f = fopen(target, "wb");
        fputs("old contents", f);
        fclose(f);

        struct rlimit old;
        assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
        struct rlimit small = {.rlim_cur = 4096, .rlim_max = old.rlim_max};
        void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
        assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
        zt_error err = {0};
        zt_tonemap tm = linear_tonemap();
        zt_status st = zt_image_write(image, target, &tm, &err);
        setrlimit(RLIMIT_FSIZE, &old);
        signal(SIGXFSZ, old_handler);

        assert_int_equal(st, ZT_ERR_WRITE);
        assert_non_null(strstr(err.message, names[i]));
        char *contents = test_read_file(target, NULL);
        assert_string_equal(contents, "old contents");
        free(contents);
        assert_int_equal(count_temporaries(dir), 0);
    }
    /* and a successful write does replace it */
    zt_error err = {0};
    assert_int_equal(zt_image_write(image, join(dir, "keep.pfm"), NULL, &err), ZT_OK);
    zt_image *back = NULL;
    assert_int_equal(zt_image_read(join(dir, "keep.pfm"), &back, &err), ZT_OK);
    test_assert_same_image(image, back, "read back");
    assert_int_equal(count_temporaries(dir), 0);
    zt_image_release(back);
    zt_image_release(image);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pfm_round_trip),
        cmocka_unit_test(test_exr_round_trip),
        cmocka_unit_test(test_exr_half_foreign),
        cmocka_unit_test(test_pfm_bytes_bottom_row_first),
        cmocka_unit_test(test_top_row_stays_top),
        cmocka_unit_test(test_ppm_exact_bytes),
        cmocka_unit_test(test_png_exact_bytes),
        cmocka_unit_test(test_tonemap_curves),
        cmocka_unit_test(test_srgb_png_round_trip),
        cmocka_unit_test(test_png_foreign),
        cmocka_unit_test(test_stdout_ppm),
        cmocka_unit_test(test_auto_exposure),
        cmocka_unit_test(test_pfm_variants),
        cmocka_unit_test(test_ppm_readers),
        cmocka_unit_test(test_reference_pfm),
        cmocka_unit_test(test_reference_png_agrees),
        cmocka_unit_test(test_bad_pfm),
        cmocka_unit_test(test_bad_ppm),
        cmocka_unit_test(test_truncated_files),
        cmocka_unit_test(test_format_from_path),
        cmocka_unit_test(test_write_errors),
        cmocka_unit_test(test_failed_write_keeps_target),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
