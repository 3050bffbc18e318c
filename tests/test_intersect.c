/* Single-primitive intersection (geom/shapes.h) and ray_offset, with exact
 * or near-exact answers: the ground the acceleration tests stand on. */
#include "test_support.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "geom/ray_offset.h"
#include "geom/shapes.h"

static rs_part triangle(vec3f a, vec3f b, vec3f c, int culled)
{
    rs_part p = {0};
    p.shape = SHAPE_TRIANGLE;
    p.culled = (uint8_t)culled;
    p.p0 = a;
    p.e1 = f3_sub(b, a);
    p.e2 = f3_sub(c, a);
    p.n = f3_normalize(f3_cross(p.e1, p.e2));
    return p;
}

static rs_part sphere(vec3f c, float r, int culled)
{
    rs_part p = {0};
    p.shape = SHAPE_SPHERE;
    p.culled = (uint8_t)culled;
    p.p0 = c;
    p.radius = r;
    return p;
}

static rs_part plane(vec3f n, float offset, int culled)
{
    rs_part p = {0};
    p.shape = SHAPE_PLANE;
    p.culled = (uint8_t)culled;
    p.n = n;
    p.offset = offset;
    return p;
}

static float cast(const rs_part *p, vec3f o, vec3f d)
{
    return shape_hit(p, o, d, 0.0f, FLT_MAX);
}

static void expect_hit(float t, double expected, double rel)
{
    if (!(fabs(t - expected) <= rel * fabs(expected))) {
        fprintf(stderr, "expected a hit at %.9g, got %.9g\n", expected, t);
        fail();
    }
}

static void expect_miss(float t)
{
    if (!(t <= 0.0f)) { /* also fails for NaN */
        fprintf(stderr, "expected a miss, got %.9g\n", t);
        fail();
    }
}

/* Deterministic xorshift, uniform in [0, 1). */
static float rnd(uint32_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return (float)(*s >> 8) * (1.0f / 16777216.0f);
}

static vec3f rnd_dir(uint32_t *s)
{
    for (;;) {
        vec3f v = f3(2 * rnd(s) - 1, 2 * rnd(s) - 1, 2 * rnd(s) - 1);
        float l = f3_dot(v, v);
        if (l > 1e-4f && l <= 1.0f)
            return f3_scale(v, 1.0f / sqrtf(l));
    }
}

/* The unit triangle in z = 0, front side +z: hits from (x, y, 1) straight
 * down have u = x, v = y and t = 1 exactly. */
static rs_part unit_triangle(int culled)
{
    return triangle(f3(0, 0, 0), f3(1, 0, 0), f3(0, 1, 0), culled);
}

static void test_triangle_hit_and_miss(void **state)
{
    (void)state;
    rs_part t = unit_triangle(1);
    vec3f down = f3(0, 0, -1);
    expect_hit(cast(&t, f3(0.25f, 0.25f, 1), down), 1.0, 0);
    expect_hit(cast(&t, f3(0.1f, 0.2f, 7), down), 7.0, 0);
    expect_miss(cast(&t, f3(2, 2, 1), down));
    expect_miss(cast(&t, f3(0.6f, 0.6f, 1), down));
    expect_miss(cast(&t, f3(0.25f, 0.25f, 1), f3(0, 0, 1))); /* away */
    /* an oblique ray: from (0, 0, 2) towards (0.5, 0.25, 0) */
    vec3f to = f3(0.5f, 0.25f, 0), o = f3(0, 0, 2);
    double len = sqrt(0.25 + 0.0625 + 4);
    expect_hit(cast(&t, o, f3_normalize(f3_sub(to, o))), len, 1e-6);
}

static void test_triangle_edges_and_vertices(void **state)
{
    (void)state;
    rs_part t = unit_triangle(1);
    vec3f down = f3(0, 0, -1);
    const float on[][2] = {{0, 0},    {1, 0},     {0, 1},      {0.5f, 0},
                           {0, 0.5f}, {0.5f, 0.5f}, {0.25f, 0.75f}, {0.75f, 0.25f}};
    for (size_t i = 0; i < sizeof on / sizeof on[0]; i++)
        expect_hit(cast(&t, f3(on[i][0], on[i][1], 1), down), 1.0, 0);
    const float off[][2] = {{-1e-6f, 0.5f}, {0.5f, -1e-6f},  {0.5f + 1e-6f, 0.5f},
                            {-1e-6f, 0},    {1 + 1e-6f, 0}, {0, 1 + 1e-6f}};
    for (size_t i = 0; i < sizeof off / sizeof off[0]; i++)
        expect_miss(cast(&t, f3(off[i][0], off[i][1], 1), down));
}

static void test_triangle_grazing(void **state)
{
    (void)state;
    for (int culled = 0; culled < 2; culled++) {
        rs_part t = unit_triangle(culled);
        /* in the plane, through the triangle: det = 0, a miss, no NaN */
        expect_miss(cast(&t, f3(-1, 0.25f, 0), f3(1, 0, 0)));
        expect_miss(cast(&t, f3(-1, -1, 0), f3_normalize(f3(1, 1, 0))));
        /* parallel just above */
        expect_miss(cast(&t, f3(-1, 0.25f, 1e-3f), f3(1, 0, 0)));
        /* almost parallel, coming down onto it at x = 0.5 */
        vec3f d = f3_normalize(f3(1, 0, -1e-3f));
        expect_hit(cast(&t, f3(-0.5f, 0.25f, 1e-3f), d), sqrt(1 + 1e-6), 1e-5);
    }
}

static void test_triangle_culling(void **state)
{
    (void)state;
    rs_part culled = unit_triangle(1), open = unit_triangle(0);
    vec3f below = f3(0.25f, 0.25f, -1), above = f3(0.25f, 0.25f, 1);
    expect_miss(cast(&culled, below, f3(0, 0, 1)));
    expect_hit(cast(&culled, above, f3(0, 0, -1)), 1.0, 0);
    expect_hit(cast(&open, below, f3(0, 0, 1)), 1.0, 0);
    expect_hit(cast(&open, above, f3(0, 0, -1)), 1.0, 0);
}

static void test_interval_is_open(void **state)
{
    (void)state;
    rs_part shapes[] = {unit_triangle(0), plane(f3(0, 0, 1), 0, 0),
                        sphere(f3(0, 0, -1), 1, 0)};
    for (int i = 0; i < 3; i++) {
        const rs_part *p = &shapes[i];
        vec3f o = f3(0.25f, 0.25f, 1), d = f3(0, 0, -1);
        if (p->shape == SHAPE_SPHERE)
            o = f3(0, 0, 1);
        /* every shape is hit at t = 1 exactly: tmax is exclusive */
        expect_hit(shape_hit(p, o, d, 0.0f, nextafterf(1.0f, 2.0f)), 1.0, 0);
        expect_miss(shape_hit(p, o, d, 0.0f, 1.0f));
        /* tmin is exclusive: starting on the surface is no hit at t = 0 */
        vec3f on = f3_madd(o, d, 1.0f);
        if (p->shape != SHAPE_SPHERE)
            expect_miss(shape_hit(p, on, d, 0.0f, FLT_MAX));
    }
}

static void test_sphere_roots(void **state)
{
    (void)state;
    for (int culled = 0; culled < 2; culled++) {
        rs_part s = sphere(f3(0, 0, 0), 2, culled);
        /* from outside: the near root */
        expect_hit(cast(&s, f3(0, 0, 5), f3(0, 0, -1)), 3.0, 0);
        expect_hit(cast(&s, f3(0, -9, 0), f3(0, 1, 0)), 7.0, 0);
        /* behind the ray */
        expect_miss(cast(&s, f3(0, 0, 5), f3(0, 0, 1)));
        expect_miss(cast(&s, f3(3, 0, 5), f3(0, 0, -1)));
        /* from inside: the far root, hidden when culled */
        float inside_centre = cast(&s, f3(0, 0, 0), f3(1, 0, 0));
        float inside = cast(&s, f3(0, 0, 1), f3(0, 0, -1));
        if (culled) {
            expect_miss(inside_centre);
            expect_miss(inside);
        } else {
            expect_hit(inside_centre, 2.0, 0);
            expect_hit(inside, 3.0, 0);
        }
    }
}

static void test_sphere_tangent(void **state)
{
    (void)state;
    rs_part s = sphere(f3(0, 0, 0), 1, 1);
    /* touching at (1, 0, 0): the discriminant is exactly zero, a hit */
    expect_hit(cast(&s, f3(1, 0, 5), f3(0, 0, -1)), 5.0, 0);
    expect_hit(cast(&s, f3(0, -1, -3), f3(0, 0, 1)), 3.0, 0);
    expect_miss(cast(&s, f3(1.0001f, 0, 5), f3(0, 0, -1)));
    expect_miss(cast(&s, f3(0, -1.0001f, -3), f3(0, 0, 1)));
}

static void test_large_and_tiny_coordinates(void **state)
{
    (void)state;
    /* the Cornell box floor, seen from its camera */
    rs_part floor = triangle(f3(0, 0, 0), f3(0, 0, 559.2f), f3(556, 0, 0), 1);
    vec3f eye = f3(278, 273, -800), target = f3(100, 0, 200);
    double dx = 100 - 278, dy = -273, dz = 1000;
    expect_hit(cast(&floor, eye, f3_normalize(f3_sub(target, eye))),
               sqrt(dx * dx + dy * dy + dz * dz), 2e-6);
    expect_hit(cast(&floor, f3(100.5f, 548.8f, 200.25f), f3(0, -1, 0)), 548.8f, 1e-6);
    expect_miss(cast(&floor, f3(100.5f, -548.8f, 200.25f), f3(0, 1, 0)));
    rs_part ball = sphere(f3(278, 100, 300), 100, 1);
    expect_hit(cast(&ball, f3(278, 100, -800), f3(0, 0, 1)), 1000.0, 0);
    rs_part far_ball = sphere(f3(1e5f, 0, 0), 1, 1);
    expect_hit(cast(&far_ball, f3(0, 0, 0), f3(1, 0, 0)), 1e5 - 1, 1e-6);

    /* tiny: the unit triangle scaled by 1e-4 */
    float s = 1e-4f;
    rs_part small = triangle(f3(0, 0, 0), f3(s, 0, 0), f3(0, s, 0), 1);
    expect_hit(cast(&small, f3(0.25f * s, 0.25f * s, s), f3(0, 0, -1)), s, 1e-6);
    expect_miss(cast(&small, f3(0.75f * s, 0.75f * s, s), f3(0, 0, -1)));
    rs_part speck = sphere(f3(0, 0, 0), 1e-3f, 0);
    expect_hit(cast(&speck, f3(0, 0, 1e-2f), f3(0, 0, -1)), 9e-3, 1e-5);
    expect_hit(cast(&speck, f3(0, 0, 0), f3(0, 1, 0)), 1e-3, 1e-6);
}

static void test_plane(void **state)
{
    (void)state;
    vec3f up = f3(0, 1, 0);
    for (int culled = 0; culled < 2; culled++) {
        rs_part p = plane(up, -10, culled); /* y = -10, front side +y */
        expect_hit(cast(&p, f3(3, 0, 4), f3(0, -1, 0)), 10.0, 0);
        expect_miss(cast(&p, f3(3, 0, 4), f3(0, 1, 0)));
        float behind = cast(&p, f3(3, -20, 4), f3(0, 1, 0));
        if (culled)
            expect_miss(behind);
        else
            expect_hit(behind, 10.0, 0);
        /* parallel, above and in the plane */
        expect_miss(cast(&p, f3(0, 0, 0), f3(1, 0, 0)));
        expect_miss(cast(&p, f3(0, -10, 0), f3(0, 0, 1)));
        /* oblique, 45 degrees */
        float t = cast(&p, f3(0, 0, 0), f3_normalize(f3(1, -1, 0)));
        expect_hit(t, 10 * sqrt(2.0), 1e-6);
    }
}

/* The vector ray_offset gives the scalar reference's bits, either side of
 * the 1/32 switch, at both signs and zero. */
static void test_ray_offset_matches_scalar(void **state)
{
    (void)state;
    uint32_t seed = 777;
    const float mags[] = {0, 1e-8f, 0.03124f, 0.03125f, 0.0313f, 1, 556, 1e6f};
    for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++)
        for (int i = 0; i < 500; i++) {
            vec3f p = f3_scale(rnd_dir(&seed), mags[m]);
            if (i % 7 == 0)
                p = f3(mags[m], -mags[m], i % 2 ? -0.0f : 0.0f);
            vec3f n = f3_scale(rnd_dir(&seed), i % 3 ? 1.0f : -1.0f);
            vec3f a = ray_offset(p, n), b = ray_offset_scalar(p, n);
            assert_memory_equal(&a, &b, sizeof a);
        }
}

/* Points moved off along n (and against it) end up on that side, not far. */
static void test_ray_offset_sides(void **state)
{
    (void)state;
    uint32_t seed = 12345;
    const float mags[] = {0, 1e-8f, 1e-4f, 0.03f, 0.04f, 1, 100, 556, 1e4f, 1e6f};
    for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++) {
        for (int i = 0; i < 200; i++) {
            vec3f p = f3_scale(rnd_dir(&seed), mags[m]);
            vec3f n = i < 3 ? f3(i == 0, i == 1, i == 2) : rnd_dir(&seed);
            for (int side = -1; side <= 1; side += 2) {
                vec3f q = ray_offset(p, f3_scale(n, (float)side));
                double along = ((double)q.x - p.x) * n.x + ((double)q.y - p.y) * n.y +
                               ((double)q.z - p.z) * n.z;
                double moved = sqrt(((double)q.x - p.x) * ((double)q.x - p.x) +
                                    ((double)q.y - p.y) * ((double)q.y - p.y) +
                                    ((double)q.z - p.z) * ((double)q.z - p.z));
                if (!(along * side > 0) || moved > 1e-4 * fmax(mags[m], 1.0)) {
                    fprintf(stderr, "|p| %g side %d: along %g moved %g\n", mags[m],
                            side, along, moved);
                    fail();
                }
            }
        }
    }
}

/* A hit point on sphere s seen from direction d, and the outward normal. */
static vec3f sphere_point(const rs_part *s, vec3f d, vec3f *n)
{
    vec3f o = f3_madd(s->p0, d, -3.0f * s->radius);
    float t = cast(s, o, d);
    assert_true(t > 0.0f);
    vec3f x = f3_madd(o, d, t);
    *n = shape_normal(s, x);
    return x;
}

static vec3f reflect(vec3f d, vec3f n)
{
    return f3_madd(d, n, -2.0f * f3_dot(d, n));
}

/* The exit distance of a ray starting inside sphere s, in double. */
static double far_root(const rs_part *s, vec3f o, vec3f d)
{
    double f[3] = {(double)o.x - s->p0.x, (double)o.y - s->p0.y, (double)o.z - s->p0.z};
    double dd[3] = {d.x, d.y, d.z};
    double a = 0, b = 0, c = -(double)s->radius * s->radius;
    for (int i = 0; i < 3; i++) {
        a += dd[i] * dd[i];
        b += f[i] * dd[i];
        c += f[i] * f[i];
    }
    return (-b + sqrt(b * b - a * c)) / a;
}

static void test_sphere_restart_after_offset(void **state)
{
    (void)state;
    uint32_t seed = 777;
    const float centre[][4] = {{0, 0, 0, 1},       {278, 100, 300, 100},
                               {556, 548.8f, 559.2f, 30}, {1e-3f, 0, 0, 1e-3f},
                               {0, -6, -3, 4},     {-4000, 2000, 100, 1}};
    for (size_t k = 0; k < sizeof centre / sizeof centre[0]; k++) {
        float r = centre[k][3];
        rs_part culled = sphere(f3(centre[k][0], centre[k][1], centre[k][2]), r, 1);
        rs_part open = culled;
        open.culled = 0;
        for (int i = 0; i < 500; i++) {
            vec3f d = rnd_dir(&seed), n;
            vec3f x = sphere_point(&open, d, &n);
            /* reflected, or any direction out of the surface: no re-hit */
            vec3f out = ray_offset(x, n);
            vec3f dirs[2] = {reflect(d, n), rnd_dir(&seed)};
            if (f3_dot(dirs[1], n) < 0.0f)
                dirs[1] = f3_neg(dirs[1]);
            for (int j = 0; j < 2; j++) {
                expect_miss(cast(&open, out, dirs[j]));
                expect_miss(cast(&culled, out, dirs[j]));
            }
            /* going in: the far side of an open sphere, nothing if culled */
            vec3f in = ray_offset(x, f3_neg(n));
            float cos_in = -f3_dot(d, n);
            if (cos_in < 0.05f)
                continue;
            double far = far_root(&open, in, d);
            float t = cast(&open, in, d);
            if (!(fabs(t - far) <= 1e-5 * far + 1e-6 * (f3_length(open.p0) + r))) {
                fprintf(stderr, "through the sphere: %.9g, expected %.9g\n", t, far);
                fail();
            }
            expect_miss(cast(&culled, in, d));
        }
    }
}

static void test_triangle_restart_after_offset(void **state)
{
    (void)state;
    uint32_t seed = 4242;
    const float scale[] = {1e-3f, 1, 100, 556, 1e4f};
    for (size_t k = 0; k < sizeof scale / sizeof scale[0]; k++) {
        float s = scale[k];
        for (int i = 0; i < 400; i++) {
            vec3f a = f3_scale(f3(rnd(&seed), rnd(&seed), rnd(&seed)), s);
            rs_part t = triangle(a, f3_add(a, f3_scale(rnd_dir(&seed), s)),
                                 f3_add(a, f3_scale(rnd_dir(&seed), s)), 0);
            if (f3_length(f3_cross(t.e1, t.e2)) < 0.05f * s * s)
                continue;
            float u = 0.05f + 0.4f * rnd(&seed), v = 0.05f + 0.4f * rnd(&seed);
            vec3f x = f3_add(a, f3_add(f3_scale(t.e1, u), f3_scale(t.e2, v)));
            vec3f d = rnd_dir(&seed);
            vec3f o = f3_madd(x, d, -s);
            float th = cast(&t, o, d);
            if (!(th > 0.0f))
                continue; /* too grazing to hit at all */
            x = f3_madd(o, d, th);
            vec3f n = f3_dot(t.n, d) < 0.0f ? t.n : f3_neg(t.n); /* facing the ray */
            expect_miss(cast(&t, ray_offset(x, n), reflect(d, n)));
            expect_miss(cast(&t, ray_offset(x, f3_neg(n)), d));
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle_hit_and_miss),
        cmocka_unit_test(test_triangle_edges_and_vertices),
        cmocka_unit_test(test_triangle_grazing),
        cmocka_unit_test(test_triangle_culling),
        cmocka_unit_test(test_interval_is_open),
        cmocka_unit_test(test_sphere_roots),
        cmocka_unit_test(test_sphere_tangent),
        cmocka_unit_test(test_large_and_tiny_coordinates),
        cmocka_unit_test(test_plane),
        cmocka_unit_test(test_ray_offset_sides),
        cmocka_unit_test(test_ray_offset_matches_scalar),
        cmocka_unit_test(test_sphere_restart_after_offset),
        cmocka_unit_test(test_triangle_restart_after_offset),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
