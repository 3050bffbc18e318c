/* The gather of light by way of mirrors (zone/phase_one/specular_gather.c)
 * against a numerical integral.  Two mirror spheres under a white sky,
 * nothing else: the light of level 1 at a point is the sky reflected once,
 * 0.8 x L over the directions that meet a sphere and whose reflection
 * escapes (one that meets the other sphere carries level 2).  Receivers
 * far from both spheres (directions aimed at the two cones alone), close
 * to the large one (its cone too wide: the hemisphere's directions and the
 * small sphere's cone weighed together), and facing away. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/render_internal.h"
#include "zone/phase_one/specular_gather.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846

static const char *scene_text =
    "{\"scene\": [{\"sky\": {\"color\": [1, 1, 1]}},"
    "{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"material\": "
    "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 1, "
    "\"refractive\": 0}, \"color\": [0.8, 0.8, 0.8]}}},"
    "{\"sphere\": {\"center\": [3, 0.5, -1], \"radius\": 0.4, \"material\": "
    "{\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 1, "
    "\"refractive\": 0}, \"color\": [0.8, 0.8, 0.8]}}}"
    "], \"camera\": {\"viewpoint\": [0, 0, 10], \"screen\": [[-1, 1, 9], "
    "[1, 1, 9], [-1, -1, 9], [1, -1, 9]], \"gridresolution\": [4, 4]}}";

static const vec3 centre[2] = {{0, 0, 0}, {3, 0.5, -1}};
static const double radius[2] = {1, 0.4};

/* The distance along o + s d (d unit) to sphere k, or 0 for a miss. */
static double sphere_hit(int k, vec3 o, vec3 d)
{
    vec3 oc = v3_sub(o, centre[k]);
    double b = v3_dot(oc, d), c = v3_dot(oc, oc) - radius[k] * radius[k];
    double disc = b * b - c;
    if (disc <= 0)
        return 0;
    double s = -b - sqrt(disc);
    return s > 1e-9 ? s : 0;
}

/* Level-1 irradiance at x (normal n): midpoint rule over cos(theta) and
 * phi of each sphere's cone. */
static double numeric(vec3 x, vec3 n, int steps)
{
    double sum = 0;
    for (int k = 0; k < 2; k++) {
        vec3 to = v3_sub(centre[k], x);
        double dist = v3_length(to);
        vec3 a = v3_scale(to, 1.0 / dist);
        double cos_max = sqrt(1.0 - radius[k] * radius[k] / (dist * dist));
        vec3 u = v3_normalize(v3_cross(fabs(a.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0), a));
        vec3 w = v3_cross(a, u);
        double dc = (1.0 - cos_max) / steps, dp = 2 * PI / steps;
        for (int i = 0; i < steps; i++) {
            double ct = cos_max + (i + 0.5) * dc, st = sqrt(1 - ct * ct);
            for (int j = 0; j < steps; j++) {
                double ph = (j + 0.5) * dp;
                vec3 d = v3_add(v3_scale(a, ct),
                                v3_add(v3_scale(u, st * cos(ph)), v3_scale(w, st * sin(ph))));
                double cn = v3_dot(n, d), s = sphere_hit(k, x, d);
                /* The other sphere in front hides this one there. */
                double s_other = sphere_hit(1 - k, x, d);
                if (cn <= 0 || s <= 0 || (s_other > 0 && s_other < s))
                    continue;
                vec3 p = v3_add(x, v3_scale(d, s));
                vec3 m = v3_scale(v3_sub(p, centre[k]), 1.0 / radius[k]);
                vec3 r = v3_sub(d, v3_scale(m, 2 * v3_dot(d, m)));
                if (sphere_hit(1 - k, p, r) > 0)
                    continue;
                sum += cn * dc * dp;
            }
        }
    }
    return 0.8 * sum;
}

static void test_gather_matches_integral(void **state)
{
    (void)state;
    zt_scene *s = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_string(scene_text, strlen(scene_text), "mirrors.json", &s, &err),
                     ZT_OK);
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 2;
    o.threads = 1;
    zt_renderer *r = NULL;
    assert_int_equal(zt_renderer_create(s, &o, &r, &err), ZT_OK);
    zone_trace t = {.f = r->forest, .r = r};
    assert_int_equal(r->forest->spec_target_count, 2);

    /* Far from both; between them; 0.1 above the large one, facing it. */
    const vec3 xs[3] = {{-2.5, 2.0, 3.0}, {1.6, -1.2, 1.4}, {0, 1.1, 0}};
    const vec3 ns[3] = {{0.6, -0.3, -0.74}, {0.2, 0.6, -0.77}, {0, -1, 0}};
    for (int k = 0; k < 3; k++) {
        vec3 x = xs[k], n = v3_normalize(ns[k]);
        double ref = numeric(x, n, 2000);
        vec3 e = zone_specular_gather(&t, x, n, 1);
        print_message("receiver %d: integral %.6f, gathered %.6f (%+.2f%%)\n", k, ref, e.y,
                      100 * (e.y / ref - 1));
        assert_true(ref > 0);
        /* Deterministic quadrature over a few dozen directions a cone:
         * within 3%. */
        assert_true(fabs(e.y - ref) < 0.03 * ref);
    }
    /* Facing away from both spheres: nothing. */
    vec3 e = zone_specular_gather(&t, xs[0], v3_normalize(v3(-0.6, 0.3, 0.74)), 1);
    assert_true(e.x == 0.0 && e.y == 0.0 && e.z == 0.0);

    zt_renderer_release(r);
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gather_matches_integral),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
