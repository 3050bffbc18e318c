/* Thin panes (a material with "thin"): light crosses them undeviated, less
 * what their two faces reflect, tinted; both renderers against the closed
 * form of a slab's Fresnel reflectance, and a pane in a white furnace. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846
#define DIFFUSE_HALF TEST_DIFFUSE(0.5)


/* Unpolarised Fresnel reflectance from vacuum into index n (written out
 * here, not taken from the renderer). */
static double fresnel(double cos_i, double n)
{
    double sin_t = sqrt(1 - cos_i * cos_i) / n, cos_t = sqrt(1 - sin_t * sin_t);
    double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    double rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

/* A slab's two faces with their inter-reflections: r + t^2 r / (1 - r^2). */
static double slab_reflectance(double cos_i, double n)
{
    double r = fresnel(cos_i, n);
    return r + (1 - r) * (1 - r) * r / (1 - r * r);
}

#define PANE_MATERIAL "\"material\": {\"character\": {\"diffuse\": 0.2, \"metallic\": 0, " \
    "\"reflecting\": 0, \"refractive\": 0.8}, \"color\": [0.9, 0.7, 0.5], " \
    "\"refractiveindex\": 1.5, \"thin\": true}"

/* A floor under the sun at elevation e, half of it under a tinted pane
 * (weight 0.8, part diffuse): level 1 on the floor is a E sin(e) / pi in
 * the open and that times 0.8 x tint x (1 - R(sin e)) under the pane. */
static void test_sun_through_pane(void **state)
{
    (void)state;
    const double e = 50 * PI / 180;
    /* The pane ends where the sun's rays to the floor's x = 0 cross it. */
    const double edge = 1 / tan(e);
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, 0], \"irradiance\": "
             "[1000, 1000, 1000]}}, {\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, "
             DIFFUSE_HALF "}},"
             "{\"triangle\": {\"points\": [[-40, 1, -40], [%.17g, 1, -40], [%.17g, 1, 40]], "
             PANE_MATERIAL "}},"
             "{\"triangle\": {\"points\": [[-40, 1, -40], [%.17g, 1, 40], [-40, 1, 40]], "
             PANE_MATERIAL "}}],"
             "\"camera\": {\"position\": [0, 0.5, 0.0001], \"lookat\": [0, 0, 0], \"fov\": 60, "
             "\"gridresolution\": [32, 32]}}",
             -cos(e), sin(e), -edge, -edge, -edge);
    zt_scene *s = test_scene_text(text, "sun_through_pane");
    const double open = 0.5 * 1000 * sin(e) / PI, tint[3] = {0.9, 0.7, 0.5};
    const double pass = 0.8 * (1 - slab_reflectance(sin(e), 1.5));
    for (int m = 0; m < 2; m++) {
        zt_image *im = test_render_level(s, m ? ZT_METHOD_ZONE : ZT_METHOD_PATH, 1, 1, 16);
        /* Light through the pane reaches the floor's x < 0 (the left
         * columns), the sun in the open its x > 0. */
        double worst = 0;
        for (int c = 0; c < 3; c++) {
            for (int y = 4; y < 28; y++) {
                double under = zt_image_pixel(im, 2, y)[c], clear = zt_image_pixel(im, 29, y)[c];
                worst = fmax(worst, fabs(under / (open * pass * tint[c]) - 1));
                worst = fmax(worst, fabs(clear / open - 1));
            }
        }
        print_message("%s: sun through a pane, largest error %.2e\n", m ? "zone" : "path", worst);
        assert_true(worst < 0.005);
        zt_image_release(im);
    }
    zt_scene_release(s);
}

/* A white pane (all refractive, thin) in a white sky, seen at 60 degrees:
 * what it reflects and what it passes add up to the sky, in every pixel,
 * at every depth. */
static void test_pane_furnace(void **state)
{
    (void)state;
    const char *text =
        "{\"scene\": [{\"sky\": {\"color\": [1, 1, 1]}},"
        "{\"triangle\": {\"points\": [[-50, 0, -50], [50, 0, -50], [50, 0, 50]], "
        "\"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 0, "
        "\"refractive\": 1}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5, \"thin\": true}}},"
        "{\"triangle\": {\"points\": [[-50, 0, -50], [50, 0, 50], [-50, 0, 50]], "
        "\"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 0, "
        "\"refractive\": 1}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5, \"thin\": true}}}],"
        "\"camera\": {\"position\": [0, 1, 1.7320508], \"lookat\": [0, 0, 0], \"fov\": 10, "
        "\"gridresolution\": [8, 8]}}";
    zt_scene *s = test_scene_text(text, "pane_furnace");
    for (int m = 0; m < 2; m++) {
        zt_image *im = test_render_level(s, m ? ZT_METHOD_ZONE : ZT_METHOD_PATH, -1, 4, 64);
        double worst = 0;
        for (int i = 0; i < 3 * im->width * im->height; i++)
            worst = fmax(worst, fabs(im->pixels[i] - 1));
        print_message("%s: pane furnace, largest error %.2e\n", m ? "zone" : "path", worst);
        assert_true(worst < 1e-4);
        zt_image_release(im);
    }
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sun_through_pane),
        cmocka_unit_test(test_pane_furnace),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
