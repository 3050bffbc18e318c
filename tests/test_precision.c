/* Hits at scales where float arithmetic runs short: smallpt builds its room
 * from spheres of radius 10^5, whose r^2 = 10^10 has a float ulp of 1024.
 * A floor that is such a sphere, under the sun, must shade as the plane it
 * approximates (a E sin(e) / pi), in both renderers: self-intersections
 * of camera, shadow or gather rays would speckle it. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846

static void test_sphere_wall_floor(void **state)
{
    (void)state;
    const double e = 40 * PI / 180;
    char text[1024];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, 0], \"irradiance\": "
             "[1000, 1000, 1000]}}, {\"sphere\": {\"center\": [50, -1e5, 81.6], \"radius\": 1e5, "
             TEST_DIFFUSE(0.75) "}}], \"camera\": {\"position\": [50, 52, 295.6], "
             "\"lookat\": [50, 0, 81.6], \"fov\": 20, \"gridresolution\": [24, 24]}}",
             cos(e), sin(e));
    zt_scene *s = test_scene_text(text, "sphere_floor");
    const double want = 0.75 * 1000 * sin(e) / PI;
    for (int m = 0; m < 2; m++) {
        zt_image *im = test_render_level(s, m ? ZT_METHOD_ZONE : ZT_METHOD_PATH, 1, 1, 16);
        double worst = 0;
        for (int i = 0; i < 3 * im->width * im->height; i++)
            worst = fmax(worst, fabs(im->pixels[i] / want - 1));
        print_message("%s: floor of radius 1e5 under the sun, largest error per pixel %.2e\n",
                      m ? "zone" : "path", worst);
        /* The floor's curvature under the view changes sin(e) by 1e-3 at
         * most. */
        assert_true(worst < 0.005);
        zt_image_release(im);
    }
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_wall_floor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
