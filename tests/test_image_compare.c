/* Error figures between images, and box downsampling. */
#include "test_support.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "zonetrace/image.h"

static void assert_close(double actual, double expected, double tolerance)
{
    if (!(fabs(actual - expected) <= tolerance)) {
        fprintf(stderr, "expected %.9g, got %.9g (tolerance %g)\n", expected, actual,
                tolerance);
        fail();
    }
}

static zt_image *filled(int width, int height, float value)
{
    zt_image *image = zt_image_create(width, height);
    assert_non_null(image);
    for (size_t i = 0; i < (size_t)width * height * 3; i++)
        image->pixels[i] = value;
    return image;
}

static void test_constant_offset(void **state)
{
    (void)state;
    /* b = 2 everywhere, a = b + 0.2 */
    zt_image *a = filled(8, 6, 2.2f), *b = filled(8, 6, 2.0f);
    zt_compare_result r;
    zt_error err = {0};
    assert_int_equal(zt_image_compare(a, b, &r, &err), ZT_OK);
    /* 2.2f - 2.0f is 0.2 to float precision */
    assert_close(r.rmse, 0.2, 1e-6);
    assert_close(r.rel_rmse, 0.1, 1e-6);
    assert_close(r.psnr, 20.0, 1e-4); /* 20 log10(2 / 0.2) */
    for (int c = 0; c < 3; c++) {
        assert_close(r.mean_a[c], 2.2, 1e-6);
        assert_close(r.mean_b[c], 2.0, 0.0);
    }
    zt_image_release(a);
    zt_image_release(b);
}

static void test_identical(void **state)
{
    (void)state;
    zt_image *a = filled(3, 3, 0.5f);
    a->pixels[4] = 7.0f;
    zt_compare_result r;
    zt_error err = {0};
    assert_int_equal(zt_image_compare(a, a, &r, &err), ZT_OK);
    assert_true(r.rmse == 0.0);
    assert_true(r.rel_rmse == 0.0);
    assert_true(isinf(r.psnr) && r.psnr > 0);
    zt_image_release(a);
}

static void test_known_pixel(void **state)
{
    (void)state;
    /* one pixel: a = (1, 2, 3), b = (1, 1, 4): differences 0, 1, -1 */
    zt_image *a = zt_image_create(1, 1), *b = zt_image_create(1, 1);
    const float va[3] = {1, 2, 3}, vb[3] = {1, 1, 4};
    memcpy(a->pixels, va, sizeof va);
    memcpy(b->pixels, vb, sizeof vb);
    zt_compare_result r;
    zt_error err = {0};
    assert_int_equal(zt_image_compare(a, b, &r, &err), ZT_OK);
    double rmse = sqrt(2.0 / 3.0);
    assert_close(r.rmse, rmse, 1e-12);
    assert_close(r.rel_rmse, rmse / 2.0, 1e-12);        /* mean(b) = 6 / 3 */
    assert_close(r.psnr, 20.0 * log10(4.0 / rmse), 1e-9); /* max(b) = 4 */
    assert_close(r.mean_a[1], 2.0, 0.0);
    assert_close(r.mean_b[2], 4.0, 0.0);
    zt_image_release(a);
    zt_image_release(b);
}

static void test_black_reference(void **state)
{
    (void)state;
    zt_image *black = filled(2, 2, 0.0f), *grey = filled(2, 2, 0.5f);
    zt_compare_result r;
    zt_error err = {0};
    assert_int_equal(zt_image_compare(grey, black, &r, &err), ZT_OK);
    assert_close(r.rmse, 0.5, 0.0);
    assert_true(isinf(r.rel_rmse));
    assert_true(isinf(r.psnr) && r.psnr < 0);
    assert_int_equal(zt_image_compare(black, black, &r, &err), ZT_OK);
    assert_true(r.rel_rmse == 0.0 && r.rmse == 0.0);
    zt_image_release(black);
    zt_image_release(grey);
}

static void test_bad_arguments(void **state)
{
    (void)state;
    zt_image *a = filled(4, 2, 1.0f), *b = filled(2, 4, 1.0f);
    zt_compare_result r;
    zt_error err = {0};
    assert_int_equal(zt_image_compare(a, b, &r, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(err.status, ZT_ERR_ARGUMENT);
    assert_non_null(strstr(err.message, "4 x 2"));
    assert_int_equal(zt_image_compare(NULL, b, &r, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_image_compare(a, NULL, &r, NULL), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_image_compare(a, a, NULL, &err), ZT_ERR_ARGUMENT);
    zt_image_release(a);
    zt_image_release(b);
}

static void test_downsample(void **state)
{
    (void)state;
    /* 4 x 2, red channel = 0..7 row by row; blocks of 2 x 2 */
    zt_image *src = zt_image_create(4, 2);
    for (int i = 0; i < 8; i++) {
        src->pixels[i * 3] = (float)i;
        src->pixels[i * 3 + 1] = 1.0f;
        src->pixels[i * 3 + 2] = i < 4 ? 2.0f : 4.0f;
    }
    zt_image *half = zt_image_downsample(src, 2);
    assert_non_null(half);
    assert_int_equal(half->width, 2);
    assert_int_equal(half->height, 1);
    /* (0 + 1 + 4 + 5) / 4 and (2 + 3 + 6 + 7) / 4 */
    assert_true(zt_image_pixel(half, 0, 0)[0] == 2.5f);
    assert_true(zt_image_pixel(half, 1, 0)[0] == 4.5f);
    assert_true(zt_image_pixel(half, 1, 0)[1] == 1.0f);
    assert_true(zt_image_pixel(half, 1, 0)[2] == 3.0f);

    zt_image *same = zt_image_downsample(src, 1);
    assert_non_null(same);
    assert_memory_equal(same->pixels, src->pixels, 8 * 3 * sizeof(float));

    assert_null(zt_image_downsample(src, 3)); /* does not divide 4 or 2 */
    assert_null(zt_image_downsample(src, 4)); /* divides 4 but not 2 */
    assert_null(zt_image_downsample(src, 0));
    assert_null(zt_image_downsample(src, -2));
    assert_null(zt_image_downsample(NULL, 2));
    zt_image_release(half);
    zt_image_release(same);
    zt_image_release(src);
}

/* A reference with known noise: each value the truth 1 plus a uniform
 * deviate of variance 0.01 (a fixed generator), its variance image 0.01.
 * The truth's own error is about 0 (its raw error is the noise, 10%); an
 * image 5% too bright has an own error of about 5%; both again over 4 x 4
 * blocks.  Over 196,608 values the variance's estimate scatters by about
 * 0.3% of itself, so the own error of the truth stays under 1%. */
static void test_own_error(void **state)
{
    (void)state;
    const int w = 256, h = 256;
    const double sigma2 = 0.01, half = sqrt(3.0 * sigma2);
    zt_image *ref = filled(w, h, 1.0f), *var = filled(w, h, (float)sigma2);
    zt_image *truth = filled(w, h, 1.0f), *bright = filled(w, h, 1.05f);
    uint64_t s = 88172645463325252ull;
    for (size_t i = 0; i < (size_t)w * h * 3; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        double u = (double)(s >> 11) / 9007199254740992.0;
        ref->pixels[i] = (float)(1.0 + half * (2.0 * u - 1.0));
    }
    zt_compare_result r;
    zt_error err = {0};
    double own;
    assert_int_equal(zt_image_compare(truth, ref, &r, &err), ZT_OK);
    assert_close(r.rel_rmse, 0.1, 0.002);
    assert_int_equal(zt_image_own_error(truth, ref, var, 1.0, &own, &err), ZT_OK);
    assert_true(own < 0.01);
    assert_int_equal(zt_image_own_error(bright, ref, var, 1.0, &own, &err), ZT_OK);
    assert_close(own, 0.05, 0.005);

    zt_image *im[4] = {ref, var, truth, bright}, *small[4];
    for (int k = 0; k < 4; k++)
        assert_non_null(small[k] = zt_image_downsample(im[k], 4));
    assert_int_equal(zt_image_compare(small[2], small[0], &r, &err), ZT_OK);
    assert_close(r.rel_rmse, 0.025, 0.002);
    assert_int_equal(zt_image_own_error(small[2], small[0], small[1], 1.0 / 16, &own, &err),
                     ZT_OK);
    assert_true(own < 0.01);
    assert_int_equal(zt_image_own_error(small[3], small[0], small[1], 1.0 / 16, &own, &err),
                     ZT_OK);
    assert_close(own, 0.05, 0.005);
    /* A variance image of another size is refused. */
    assert_int_equal(zt_image_own_error(truth, ref, small[1], 1.0, &own, &err),
                     ZT_ERR_ARGUMENT);
    for (int k = 0; k < 4; k++) {
        zt_image_release(small[k]);
        zt_image_release(im[k]);
    }
}

static void test_create(void **state)
{
    (void)state;
    zt_image *image = zt_image_create(3, 2);
    assert_non_null(image);
    for (int i = 0; i < 18; i++)
        assert_true(image->pixels[i] == 0.0f);
    assert_true(zt_image_pixel(image, 2, 1) == image->pixels + 15);
    zt_image_release(image);
    assert_null(zt_image_create(0, 5));
    assert_null(zt_image_create(5, -1));
    assert_null(zt_image_create(32769, 1));
    assert_null(zt_image_create(32768, 32768)); /* more than 2^28 pixels */
    zt_image_release(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant_offset), cmocka_unit_test(test_identical),
        cmocka_unit_test(test_known_pixel),     cmocka_unit_test(test_black_reference),
        cmocka_unit_test(test_bad_arguments),   cmocka_unit_test(test_downsample),
        cmocka_unit_test(test_create),          cmocka_unit_test(test_own_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
