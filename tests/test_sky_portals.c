/* Window panes as portals for the sky's light (zone/light/sky_portals.h).
 *
 * A closed room, 4 x 3 x 4, with two windows: a skylight in the ceiling
 * glazed twice (two sheets 2 cm apart, the edges of the gap glazed too:
 * a box of glass, as model files write a pane) and a window in a wall
 * glazed once.  Checked: the panes make two portals, one a window; the
 * sky's light that the zone tracer gathers (zone_sky_irradiance) at
 * points of the floor and of the far wall equals the integral of the
 * sky's radiance times the panes' transmittance times the cosine over both
 * windows, computed here on a fine grid over each pane; under a sky of one
 * colour and under the Preetham sky's map.  Outside, on the roof, the
 * portals are left alone (they lead into a closed room) and the gather
 * sees the open sky.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "light/distant.h"
#include "material/bsdf.h"
#include "render/render_internal.h"
#include "util/vec3_convert.h"
#include "zone/light/sky_portals.h"
#include "zone/zone.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846

#define PANE "\"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": 0, " \
             "\"refractive\": 1}, \"color\": [0.9, 0.9, 0.9], \"refractiveindex\": 1.5, "     \
             "\"thin\": true}"

/* The skylight's opening and the wall window's. */
#define SKY_LO 1.5
#define SKY_HI 2.5
#define GAP 0.01 /* half the skylight's glazing gap, about y = 3 */

static size_t quad(char *text, size_t cap, size_t len, const double q[4][3], const char *mat)
{
    for (int t = 0; t < 2; t++) {
        const double *a = q[0], *b = q[t + 1], *c = q[t + 2];
        len += (size_t)snprintf(text + len, cap - len,
                                "{\"triangle\": {\"points\": [[%g, %g, %g], [%g, %g, %g], "
                                "[%g, %g, %g]], %s}},",
                                a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2], mat);
    }
    return len;
}

static zt_renderer *room(zt_scene **scene_out, const char *sky)
{
    static const double walls[][4][3] = {
        {{0, 0, 0}, {4, 0, 0}, {4, 0, 4}, {0, 0, 4}},             /* floor */
        {{0, 0, 0}, {0, 0, 4}, {0, 3, 4}, {0, 3, 0}},             /* x = 0 */
        {{0, 0, 0}, {0, 3, 0}, {4, 3, 0}, {4, 0, 0}},             /* z = 0 */
        {{0, 0, 4}, {4, 0, 4}, {4, 3, 4}, {0, 3, 4}},             /* z = 4 */
        /* x = 4 around the window y 1..2, z 1.5..2.5 */
        {{4, 0, 0}, {4, 0, 4}, {4, 1, 4}, {4, 1, 0}},
        {{4, 2, 0}, {4, 2, 4}, {4, 3, 4}, {4, 3, 0}},
        {{4, 1, 0}, {4, 1, 1.5}, {4, 2, 1.5}, {4, 2, 0}},
        {{4, 1, 2.5}, {4, 1, 4}, {4, 2, 4}, {4, 2, 2.5}},
        /* the ceiling around the skylight */
        {{0, 3, 0}, {0, 3, 4}, {SKY_LO, 3, 4}, {SKY_LO, 3, 0}},
        {{SKY_HI, 3, 0}, {SKY_HI, 3, 4}, {4, 3, 4}, {4, 3, 0}},
        {{SKY_LO, 3, 0}, {SKY_LO, 3, SKY_LO}, {SKY_HI, 3, SKY_LO}, {SKY_HI, 3, 0}},
        {{SKY_LO, 3, SKY_HI}, {SKY_LO, 3, 4}, {SKY_HI, 3, 4}, {SKY_HI, 3, SKY_HI}},
    };
    const double lo = SKY_LO, hi = SKY_HI, b = 3 - GAP, t = 3 + GAP;
    const double panes[][4][3] = {
        {{lo, b, lo}, {lo, b, hi}, {hi, b, hi}, {hi, b, lo}}, /* the skylight's sheets */
        {{lo, t, lo}, {lo, t, hi}, {hi, t, hi}, {hi, t, lo}},
        {{lo, b, lo}, {hi, b, lo}, {hi, t, lo}, {lo, t, lo}}, /* and its edges */
        {{lo, b, hi}, {hi, b, hi}, {hi, t, hi}, {lo, t, hi}},
        {{lo, b, lo}, {lo, b, hi}, {lo, t, hi}, {lo, t, lo}},
        {{hi, b, lo}, {hi, b, hi}, {hi, t, hi}, {hi, t, lo}},
        {{4, 1, 1.5}, {4, 1, 2.5}, {4, 2, 2.5}, {4, 2, 1.5}}, /* the wall window */
    };
    size_t cap = 32768, len = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    len += (size_t)snprintf(text, cap,
                            "{\"camera\": {\"position\": [1, 1.5, 1], \"lookat\": [4, 1, 3], "
                            "\"fov\": 75, \"gridresolution\": [8, 8]}, \"scene\": [%s,",
                            sky);
    for (size_t k = 0; k < sizeof walls / sizeof walls[0]; k++)
        len = quad(text, cap, len, walls[k], TEST_DIFFUSE(0.5));
    for (size_t k = 0; k < sizeof panes / sizeof panes[0]; k++)
        len = quad(text, cap, len, panes[k], PANE);
    text[len - 1] = ']';
    snprintf(text + len, cap - len, "}");
    zt_scene *scene = test_scene_text(text, "sky_portals.json");
    free(text);
    *scene_out = scene;
    return test_zone_renderer(scene, 1, 1, zt_render_options_default().quality);
}

static vec3f sky_radiance(const zt_renderer *r, vec3f w)
{
    return r->rs.distant.map ? distant_map_radiance(&r->rs.distant, w) : r->rs.sky;
}

static const rs_object *pane_object(const zt_renderer *r)
{
    for (int i = 0; i < r->rs.object_count; i++)
        if (r->rs.objects[i].thin)
            return &r->rs.objects[i];
    fail();
    return NULL;
}

/* The integral over a window of the sky's radiance x the transmittance of
 * `sheets` panes x the cosine at x: the window as the rectangle
 * corner + s eu + t ev on a grid of n x n, in area. */
static vec3 window_integral(const zt_renderer *r, vec3 x, vec3 n, vec3 corner, vec3 eu, vec3 ev,
                            int sheets)
{
    const int grid = 400;
    const rs_object *pane = pane_object(r);
    vec3 normal = v3_normalize(v3_cross(eu, ev));
    double da = v3_length(v3_cross(eu, ev)) / ((double)grid * grid);
    vec3 e = v3(0, 0, 0);
    for (int i = 0; i < grid; i++)
        for (int j = 0; j < grid; j++) {
            vec3 q = v3_add(corner, v3_add(v3_scale(eu, (i + 0.5) / grid),
                                           v3_scale(ev, (j + 0.5) / grid)));
            vec3 d = v3_sub(q, x);
            double r2 = v3_dot(d, d);
            d = v3_scale(d, 1 / sqrt(r2));
            double cx = v3_dot(d, n), cq = fabs(v3_dot(d, normal));
            if (cx <= 0)
                continue;
            vec3f t = bsdf_pane_transmittance(pane, (float)cq);
            vec3f l = sky_radiance(r, v3_to_f3(d));
            double f = cx * cq / r2 * da;
            double tt[3] = {t.x, t.y, t.z};
            for (int s = 1; s < sheets; s++) {
                tt[0] *= t.x;
                tt[1] *= t.y;
                tt[2] *= t.z;
            }
            e = v3_add(e, v3(l.x * tt[0] * f, l.y * tt[1] * f, l.z * tt[2] * f));
        }
    return e;
}

/* Both windows from x inside the room. */
static vec3 exact_inside(const zt_renderer *r, vec3 x, vec3 n)
{
    vec3 sky = window_integral(r, x, n, v3(SKY_LO, 3 - GAP, SKY_LO), v3(SKY_HI - SKY_LO, 0, 0),
                               v3(0, 0, SKY_HI - SKY_LO), 2);
    vec3 wall = window_integral(r, x, n, v3(4, 1, 1.5), v3(0, 1, 0), v3(0, 0, 1), 1);
    return v3_add(sky, wall);
}

/* The sky's irradiance on an open surface facing up: a fine grid in
 * (cos^2 of the zenith angle, azimuth), even in projected solid angle. */
static vec3 hemisphere(const zt_renderer *r)
{
    const int nu = 256, nv = 512;
    vec3 e = v3(0, 0, 0);
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double u = (i + 0.5) / nu, phi = 2 * PI * (j + 0.5) / nv;
            double s = sqrt(u), c = sqrt(1 - u);
            vec3f l = sky_radiance(r, f3((float)(s * cos(phi)), (float)c, (float)(s * sin(phi))));
            e = v3_add(e, v3_scale(v3(l.x, l.y, l.z), PI / ((double)nu * nv)));
        }
    return e;
}

static vec3 gathered(const zt_renderer *r, vec3 x, vec3 n)
{
    zone_trace t = {.f = r->forest, .r = r};
    return zone_sky_irradiance(&t, x, n);
}

static void test_portals_take_the_windows(void **state)
{
    (void)state;
    const char *skies[2] = {"{\"sky\": {\"color\": [0.3, 0.5, 0.9]}}",
                            "{\"sky\": {\"model\": \"preetham\", \"turbidity\": 3, "
                            "\"sun_direction\": [0.8, 0.5, 0.3]}}"};
    const vec3 points[][2] = {
        {{2, 0, 2}, {0, 1, 0}},       /* under the skylight */
        {{0.5, 0, 0.5}, {0, 1, 0}},   /* a corner of the floor */
        {{3.5, 0, 3.2}, {0, 1, 0}},   /* near the wall window, beside it */
        {{0, 1.5, 2}, {1, 0, 0}},     /* the wall across from it */
        {{2, 1.2, 0}, {0, 0, 1}},     /* a side wall */
    };
    const int count = sizeof points / sizeof points[0];
    for (int k = 0; k < 2; k++) {
        zt_scene *scene;
        zt_renderer *r = room(&scene, skies[k]);
        assert_true(r->forest->sky);
        /* The skylight's 12 triangles are one portal, the wall window's 2
         * another. */
        assert_int_equal(r->forest->portals.count, 2);
        double worst = 0, worst_without = 0;
        for (int i = 0; i < count; i++) {
            vec3 x = points[i][0], n = points[i][1];
            vec3 x_in = v3_add(x, v3_scale(n, 1e-4));
            vec3 want = exact_inside(r, x_in, n), got = gathered(r, x_in, n);
            /* The same gather with the portals hidden from it. */
            int portals = r->forest->portals.count;
            r->forest->portals.count = 0;
            vec3 without = gathered(r, x_in, n);
            r->forest->portals.count = portals;
            printf("%s sky, point %d: gathered %.5g, the windows' integral %.5g (%+.2f%%; "
                   "without portals %+.1f%%)\n",
                   k ? "Preetham" : "colour", i, got.y, want.y, 100 * (got.y / want.y - 1),
                   100 * (without.y / want.y - 1));
            worst = fmax(worst, fabs(got.y - want.y) / want.y);
            worst_without = fmax(worst_without, fabs(without.y - want.y) / want.y);
        }
        /* The portals' directions are a stratified quadrature of 128 (the
         * default quality's share) over the windows a point faces; without
         * them, the gather's 256 directions over the hemisphere find these
         * windows with a few each. */
        assert_true(worst < 0.03);
        assert_true(worst_without > 3 * worst);
        /* On the roof the portals lead into a closed room: no point aims
         * at them, and the gather sees the open sky (the integral over the
         * upper hemisphere). */
        vec3 x = v3(0.5, 3 + 1e-4, 0.5), up = v3(0, 1, 0);
        sky_portal_pick picks[SKY_PORTAL_PICKS_MAX];
        assert_int_equal(sky_portals_pick(&r->forest->portals, x, up, 128, picks), 0);
        vec3 roof = gathered(r, x, up), open = hemisphere(r);
        printf("%s sky, on the roof: gathered %.5g, the open sky %.5g (%+.2f%%)\n",
               k ? "Preetham" : "colour", roof.y, open.y, 100 * (roof.y / open.y - 1));
        assert_true(fabs(roof.y / open.y - 1) < 0.01);
        zt_renderer_release(r);
        zt_scene_release(scene);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_portals_take_the_windows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
