/* The image of a light in a mirror sphere (zone/glint.c) against a
 * numerical integral: directions from the receiver over the sphere's cone
 * on a fine grid, each reflected off the sphere and tested against the
 * light triangle. */
#include "test_support.h"
#include "ray_triangle.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/render_internal.h"
#include "zone/phase_one/glint.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

static const char *scene_text =
    "{\"scene\": ["
    "{\"lighttriangle\": {\"points\": [[-0.6, 3, -0.5], [0.7, 3, -0.4], [0, 3, 0.8]], "
    "\"emission\": [1, 1, 1]}},"
    "{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"material\": "
    "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 1, "
    "\"refractive\": 0}, \"color\": [0.8, 0.8, 0.8]}}}"
    "], \"camera\": {\"viewpoint\": [0, 0, 10], \"screen\": [[-1, 1, 9], "
    "[1, 1, 9], [-1, -1, 9], [1, -1, 9]], \"gridresolution\": [4, 4]}}";

static vec3 tri[3] = {{-0.6, 3, -0.5}, {0.7, 3, -0.4}, {0, 3, 0.8}};

static int hits_light(vec3 o, vec3 d)
{
    return ray_hits_triangle(o, d, tri);
}

/* Irradiance at x (normal n) of the light (unit radiance) seen in the unit
 * mirror sphere at the origin (reflectance 0.8): midpoint rule over
 * cos(theta) and phi of the sphere's cone. */
static double numeric(vec3 x, vec3 n, int steps)
{
    vec3 a = v3_normalize(v3_scale(x, -1.0));
    double cos_max = sqrt(1.0 - 1.0 / v3_dot(x, x));
    vec3 u = v3_normalize(v3_cross(fabs(a.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0), a));
    vec3 w = v3_cross(a, u);
    double sum = 0, dc = (1.0 - cos_max) / steps, dp = 2 * 3.14159265358979323846 / steps;
    for (int i = 0; i < steps; i++) {
        double ct = cos_max + (i + 0.5) * dc, st = sqrt(1 - ct * ct);
        for (int j = 0; j < steps; j++) {
            double ph = (j + 0.5) * dp;
            vec3 d = v3_add(v3_scale(a, ct), v3_add(v3_scale(u, st * cos(ph)), v3_scale(w, st * sin(ph))));
            double b = v3_dot(x, d), c = v3_dot(x, x) - 1, disc = b * b - c;
            if (disc <= 0)
                continue;
            vec3 p = v3_add(x, v3_scale(d, -b - sqrt(disc)));
            vec3 r = v3_sub(d, v3_scale(p, 2 * v3_dot(d, p)));
            double cn = v3_dot(n, d);
            if (cn > 0 && hits_light(p, r))
                sum += cn * dc * dp;
        }
    }
    return 0.8 * sum;
}

static void test_image_matches_integral(void **state)
{
    (void)state;
    zt_scene *s = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_string(scene_text, strlen(scene_text), "glint.json", &s, &err),
                     ZT_OK);
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 1;
    o.threads = 1;
    zt_renderer *r = NULL;
    assert_int_equal(zt_renderer_create(s, &o, &r, &err), ZT_OK);
    zone_trace t = {.r = r};
    assert_true(glint_sphere(&r->rs, 1));
    const int mirror[1] = {1};

    const vec3 xs[3] = {{2.5, 0.5, 0.3}, {-1.5, -0.5, 2.0}, {0.4, 1.9, -1.8}};
    for (int k = 0; k < 3; k++) {
        vec3 x = xs[k], n = v3_normalize(v3_scale(x, -1.0));
        double ref = numeric(x, n, 3000);
        double coarse = glint_irradiance(&t, mirror, 1, x, n, 2).x;
        double fine = glint_irradiance(&t, mirror, 1, x, n, 8).x;
        printf("receiver %d: integral %.6g, image cut 2: %.6g, cut 8: %.6g\n", k, ref, coarse, fine);
        assert_true(ref > 0);
        /* The image's straight edges are the only discretisation: within
         * 1% when fine, and closer when finer. */
        assert_true(fabs(fine - ref) < 0.01 * ref);
        assert_true(fabs(fine - ref) <= fabs(coarse - ref) + 1e-4 * ref);
    }
    /* A receiver facing away sees nothing of the sphere. */
    vec3 x = xs[0];
    assert_true(glint_irradiance(&t, mirror, 1, x, v3_normalize(x), 8).x == 0.0);

    zt_renderer_release(r);
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_image_matches_integral),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
