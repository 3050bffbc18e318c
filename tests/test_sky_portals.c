/* Window panes as portals for the sky's light (zone/light/sky_portals.h).
 *
 * A closed room, 4 x 3 x 4, on the ground, with two windows: a skylight in the ceiling
 * glazed twice (two sheets 2 cm apart, the edges of the gap glazed too:
 * a box of glass, as model files write a pane) and a window in a wall
 * glazed once.  Checked: the panes make two portals, one a window; the
 * sky's light that the zone tracer gathers (zone_sky_irradiance) at
 * points of the floor and of the far wall equals the integral of the
 * sky's radiance times the panes' transmittance times the cosine over both
 * windows, computed here on a fine grid over each pane; under a sky of one
 * colour and under the Preetham sky's map, and a block of split points
 * sees between them what one point sees.  The skylight measures the sky
 * behind each of its sides; above the roof, where it leads into the closed
 * room, no point aims at it and the gather sees the sky.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "light/distant.h"
#include "material/bsdf.h"
#include "render/prim.h"
#include "render/render_internal.h"
#include "util/vec3_convert.h"
#include "zone/light/sky_gather.h"
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
    /* The ground, just below the floor: what is seen through the wall
     * window below the horizon is not sky. */
    len += (size_t)snprintf(text + len, cap - len,
                            "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": -0.01, %s}}]}",
                            TEST_DIFFUSE(0.3));
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
            if (cx <= 0 || d.y <= 0) /* (below the horizon: the ground) */
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

/* The sky's irradiance on a surface of normal n from the directions
 * above the horizon (y > 0): a fine grid over the sphere. */
static vec3 sky_above(const zt_renderer *r, vec3 n)
{
    const int nu = 512, nv = 1024;
    vec3 e = v3(0, 0, 0);
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double y = (i + 0.5) / nu, phi = 2 * PI * (j + 0.5) / nv, s = sqrt(1 - y * y);
            vec3 d = v3(s * cos(phi), y, s * sin(phi));
            double c = v3_dot(d, n);
            if (c <= 0)
                continue;
            vec3f l = sky_radiance(r, v3_to_f3(d));
            e = v3_add(e, v3_scale(v3(l.x, l.y, l.z), c * 2 * PI / ((double)nu * nv)));
        }
    return e;
}

/* The largest relative difference of a channel. */
static double rel_apart(vec3 a, vec3 b)
{
    return fmax(fabs(a.x - b.x) / b.x, fmax(fabs(a.y - b.y) / b.y, fabs(a.z - b.z) / b.z));
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
        const sky_portals *sp = &r->forest->portals;
        assert_int_equal(sp->count, 2);
        int of[2] = {-1, -1}, counted[2] = {0, 0};
        for (int q = 0; q < r->rs.prim_count; q++) {
            rs_part tmp;
            const rs_part *p = rs_prim(&r->rs, q, &tmp);
            if (!r->rs.objects[p->object].thin) {
                assert_int_equal(sp->of_prim[q], -1);
                continue;
            }
            int wall = p->p0.x > 3.9f && f3_add(p->p0, p->e1).x > 3.9f &&
                       f3_add(p->p0, p->e2).x > 3.9f;
            assert_true(sp->of_prim[q] >= 0);
            if (of[wall] < 0)
                of[wall] = sp->of_prim[q];
            assert_int_equal(sp->of_prim[q], of[wall]);
            counted[wall]++;
        }
        assert_int_equal(counted[0], 12);
        assert_int_equal(counted[1], 2);
        assert_int_not_equal(of[0], of[1]);
        /* The sky each side of the skylight: above it all of it but what
         * the glass keeps, below it the little that leaves through the
         * wall window. */
        const sky_portal *sky_light = &sp->p[of[0]];
        int up_side = sky_light->n.y > 0 ? 0 : 1;
        printf("skylight: sky behind it from above %.3f, from below %.3f\n",
               sky_light->open[1 - up_side], sky_light->open[up_side]);
        assert_true(sky_light->open[up_side] > 0.6f); /* one sheet crossed, at every angle */
        assert_true(sky_light->open[1 - up_side] < 0.1f);
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
            worst = fmax(worst, rel_apart(got, want));
            worst_without = fmax(worst_without, rel_apart(without, want));
            /* A block of 16 split points at x sees, between them, what one
             * point sees. */
            vec3 mean = v3(0, 0, 0);
            for (int j = 0; j < 16; j++) {
                zone_trace t = {.f = r->forest, .r = r};
                t.light_split = DIRECT_SPLIT(2, j);
                mean = v3_add(mean, v3_scale(zone_sky_irradiance(&t, x_in, n), 1.0 / 16));
            }
            assert_true(rel_apart(mean, got) < 1e-5);
        }
        /* The portals' directions are a stratified quadrature of 128 (the
         * default quality's share) over the windows a point faces, about
         * 64 a window, where the horizon cuts across the wall window
         * (measured: 2.7% at worst, across the room from it); without them,
         * the gather's 256 directions over the hemisphere find these
         * windows with a few each. */
        assert_true(worst < 0.04);
        assert_true(worst_without > 3 * worst);
        /* Above the roof, facing the sky but tilted toward the skylight:
         * it leads into a closed room, so the point does not aim at it
         * (the wall window's plane it sees from the room's side, and may),
         * and it sees the sky above the roof's plane. */
        vec3 x = v3(1.2, 3.3, 1.2), tilt = v3_normalize(v3(1, 1, 1));
        sky_portal_pick picks[SKY_PORTAL_PICKS_MAX];
        int picked = sky_portals_pick(sp, x, tilt, 128, picks);
        for (int i = 0; i < picked; i++)
            assert_int_not_equal(picks[i].portal, of[0]);
        vec3 roof = gathered(r, x, tilt), open = sky_above(r, tilt);
        printf("%s sky, above the roof: gathered %.5g, the sky above %.5g (%+.2f%%)\n",
               k ? "Preetham" : "colour", roof.y, open.y, 100 * (roof.y / open.y - 1));
        assert_true(rel_apart(roof, open) < 0.02);
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
