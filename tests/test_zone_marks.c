/* What a pixel's own rays can miss, found from the eye
 * (zone/phase_two_marks.c): a light smaller than a pixel, between its
 * corner and sample rays, and a light's sub-pixel image in a mirror
 * sphere.  Both against values computed here from the geometry alone;
 * and a pixel whose fine grid holds many surfaces. */
#include "test_support.h"
#include "ray_triangle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

/* 8 x 8 pixels over the screen [-1, 1]^2 at z = 9, eye at z = 10: a pixel
 * is 0.25 x 0.25 on the screen, and a point at z = 0 projects at 1/10 of
 * its x and y. */
#define CAMERA(n)                                                                           \
    "\"camera\": {\"viewpoint\": [0, 0, 10], \"screen\": [[-1, 1, 9], [1, 1, 9], "       \
    "[-1, -1, 9], [1, -1, 9]], \"gridresolution\": [" #n ", " #n "]}"

static zt_image *zone_level(const char *text, int level)
{
    zt_scene *s = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_string(text, strlen(text), "marks.json", &s, &err), ZT_OK);
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.level = level;
    o.depth = level;
    o.threads = 2;
    zt_image *img = NULL;
    assert_int_equal(zt_render(s, &o, &img, NULL, &err), ZT_OK);
    zt_scene_release(s);
    return img;
}

/* Sum over the image of pixel value x pixel area on the screen: the
 * integral of radiance over the screen. */
static double screen_integral(const zt_image *img)
{
    double sum = 0;
    for (int i = 0; i < img->width * img->height; i++)
        sum += img->pixels[3 * i];
    return sum * (2.0 / img->width) * (2.0 / img->height);
}

/* A light triangle whose projection, 1/10 of its size, lies inside pixel
 * (3, 3) and meets none of its corners and not its centre: the pixel's rays
 * all miss it.  Level 0 is its emission times its projected area. */
static void test_light_between_rays(void **state)
{
    (void)state;
    const char *text = "{\"scene\": [{\"lighttriangle\": {\"points\": [[-2.1, 0.4, 0], "
                       "[-1.9, 0.4, 0], [-2.0, 0.6, 0]], \"emission\": [50, 50, 50]}}], " CAMERA(8) "}";
    zt_image *img = zone_level(text, 0);
    double area = 0.5 * 0.02 * 0.02; /* the projection on the screen */
    double want = 50.0 * area, got = screen_integral(img);
    printf("tiny light: screen integral %.6g, expected %.6g\n", got, want);
    assert_true(fabs(got - want) < 1e-3 * want);
    assert_true(zt_image_pixel(img, 3, 3)[0] > 0.0f);
    zt_image_release(img);
}

static const vec3 tri[3] = {{2.8, -0.2, 2.8}, {3.3, 0.0, 3.0}, {3.0, 0.3, 3.3}};

/* The screen area whose rays reflect off the unit sphere at the origin
 * into the light: midpoint rule on an n x n grid over the square
 * [-0.11, 0.11]^2 of the screen, which holds the sphere's outline (radius
 * 1/sqrt(99) there). */
static double image_area(int n)
{
    const vec3 eye = {0, 0, 10};
    long count = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            vec3 d = v3_normalize(v3(0.11 * (-1 + 2 * (i + 0.5) / n), 0.11 * (1 - 2 * (j + 0.5) / n), -1));
            double b = v3_dot(eye, d), disc = b * b - (100 - 1);
            if (disc <= 0)
                continue;
            vec3 p = v3_add(eye, v3_scale(d, -b - sqrt(disc)));
            vec3 r = v3_sub(d, v3_scale(p, 2 * v3_dot(d, p)));
            count += ray_hits_triangle(p, r, tri);
        }
    return count * (0.22 * 0.22 / ((double)n * n));
}

/* A small light beside a mirror sphere: its image is a fraction of a
 * pixel.  Level 1 is the mirror's reflectance times the emission over the
 * image's area. */
static void test_image_in_sphere(void **state)
{
    (void)state;
    const char *text =
        "{\"scene\": [{\"lighttriangle\": {\"points\": [[2.8, -0.2, 2.8], [3.3, 0.0, 3.0], "
        "[3.0, 0.3, 3.3]], \"emission\": [50, 50, 50]}},"
        "{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"material\": "
        "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 1, "
        "\"refractive\": 0}, \"color\": [0.8, 0.8, 0.8]}}}], " CAMERA(64) "}";
    zt_image *img = zone_level(text, 1);
    double area = image_area(3000);
    double want = 0.8 * 50.0 * area, got = screen_integral(img);
    printf("image in sphere: %.3g of a pixel; screen integral %.6g, expected %.6g\n",
           area / (0.03125 * 0.03125), got, want);
    assert_true(area > 0 && area < 0.25 * 0.03125 * 0.03125);
    /* The fine grid's 64 x 64 cells against the image's outline. */
    assert_true(fabs(got - want) < 0.05 * want);
    zt_image_release(img);
}

/* One pixel holding a mirror sphere, a light and a backdrop of 576 small
 * triangles: its fine grid shades more samples than a pixel usually has
 * (each small triangle is a group of its own), and the image must still
 * be made, finite. */
static void test_dense_fine_pixel(void **state)
{
    (void)state;
    size_t cap = 1 << 17, len = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    len += (size_t)snprintf(text + len, cap - len,
                            "{\"scene\": [{\"lighttriangle\": {\"points\": [[-9, -9, -4], "
                            "[-4, -9, -4], [-6.5, -4, -4]], \"emission\": [5, 5, 5]}},"
                            "{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 2, \"material\": "
                            "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 1, "
                            "\"refractive\": 0}, \"color\": [0.8, 0.8, 0.8]}}}");
    for (int j = 0; j < 24; j++)
        for (int i = 0; i < 24; i++) {
            double x = -12 + i, y = -12 + j;
            len += (size_t)snprintf(text + len, cap - len,
                                    ",{\"triangle\": {\"points\": [[%g, %g, -6], [%g, %g, -6], "
                                    "[%g, %g, -6]], \"material\": {\"character\": {\"diffuse\": 1, "
                                    "\"metallic\": 0, \"reflecting\": 0, \"refractive\": 0}, "
                                    "\"color\": [0.5, 0.5, 0.5]}}}",
                                    x, y, x + 0.9, y, x, y + 0.9);
        }
    snprintf(text + len, cap - len, "], " CAMERA(1) "}");
    zt_image *img = zone_level(text, 1);
    float *v = zt_image_pixel(img, 0, 0);
    printf("dense pixel: %g %g %g\n", v[0], v[1], v[2]);
    assert_true(isfinite(v[0]) && v[0] > 0.0f);
    zt_image_release(img);
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_light_between_rays),
        cmocka_unit_test(test_image_in_sphere),
        cmocka_unit_test(test_dense_fine_pixel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
