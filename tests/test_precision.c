/* Hits at scales where float arithmetic runs short: smallpt builds its room
 * from spheres of radius 10^5, whose r^2 = 10^10 has a float ulp of 1024.
 * A floor that is such a sphere, under the sun, must shade as the plane it
 * approximates (a E sin(e) / pi), in both renderers: self-intersections
 * of camera, shadow or gather rays would speckle it. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>

#include "geom/accel.h"
#include "render/render_scene.h"
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

/* smallpt's ceiling: a sphere of radius 10^5 whose centre, 100081.6 up,
 * lies between two floats 0.0078 apart.  Its lowest point must be at
 * 81.6 as the file says (in float it was 0.0016 higher, and 0.58% more of
 * smallpt's light, which cuts through it, showed), with every
 * acceleration structure; and a ray through the wall's near side at
 * grazing angles finds the same surface. */
static void test_sphere_wall_centre_in_double(void **state)
{
    (void)state;
    zt_scene *s = test_scene_text(
        "{\"scene\": [{\"sphere\": {\"center\": [50, 100081.6, 81.6], \"radius\": 1e5, "
        TEST_DIFFUSE(0.75) "}}], \"camera\": {\"position\": [50, 40, 295.6], "
        "\"lookat\": [50, 40, 0], \"fov\": 40, \"gridresolution\": [4, 4]}}",
        "ceiling");
    for (int kind = ACCEL_EMBREE; kind <= ACCEL_BVH; kind++) {
        rscene rs;
        zt_error err = {0};
        assert_int_equal(rscene_build(&rs, s, NULL, 0, kind, &err), ZT_OK);
        for (int k = 0; k < 5; k++) {
            /* Straight up from points across the room: the sphere's height
             * there, in double, 81.6 less its sagitta. */
            double x = 10.0 + 20.0 * k, dx = x - 50.0;
            double want = 100081.6 - sqrt(1e10 - dx * dx);
            vec3f o = f3((float)x, 40.0f, 81.6f);
            hit h = accel_intersect(&rs, o, f3(0, 1, 0));
            assert_int_equal(h.part, 0);
            double y = 40.0 + h.t;
            if (fabs(y - want) > 2e-5)
                fail_msg("accelerator %d: ceiling at %.7f above x = %g, want %.7f", kind, y, x,
                         want);
        }
        rscene_free(&rs);
    }
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_wall_floor),
        cmocka_unit_test(test_sphere_wall_centre_in_double),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
