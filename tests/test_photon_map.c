/* The caustic photons' density estimate (zone/maps/photon_map.c): a uniform
 * density comes back as itself, the k-d tree finds the same photons a
 * search of every photon finds, only photons of the surface, level and
 * side asked count, and the trees depend on the photons and their order
 * alone. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zone/maps/photon_map.h"

#define PI_D 3.14159265358979323846

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static double uniform(uint32_t *s) { return (lcg(s) & 0xffffff) / 16777216.0; }

static zone_photon photon(double x, double y, double z, double flux, int surface, int level,
                          int up)
{
    zone_photon p = {{(float)x, (float)y, (float)z}, {(float)flux, (float)(2 * flux),
                                                      (float)(3 * flux)},
                     surface, {0, (int8_t)(up ? 127 : -127), 0}, (uint8_t)level};
    return p;
}

/* Photons on a jittered grid over the square [-1, 1]^2 of the plane y = 0,
 * each of flux a / count: irradiance a / 4 inside, to within the grid's
 * fluctuation over a disc of 64 photons. */
static void test_uniform_density(void **state)
{
    (void)state;
    photon_map in, m;
    memset(&in, 0, sizeof in);
    memset(&m, 0, sizeof m);
    uint32_t seed = 7;
    int side = 400, count = side * side;
    double a = 8.0;
    for (int i = 0; i < side; i++)
        for (int j = 0; j < side; j++) {
            zone_photon p = photon(-1 + 2 * (i + uniform(&seed)) / side, 0,
                                   -1 + 2 * (j + uniform(&seed)) / side, a / count, 3, 1, 1);
            assert_true(photon_map_add(&in, &p));
        }
    assert_true(photon_map_build(&m, &in, 1, 3, 5));
    assert_int_equal(m.count, (size_t)count);
    assert_null(in.p);
    double worst = 0;
    for (int k = 0; k < 50; k++) {
        vec3 x = v3(-0.8 + 1.6 * uniform(&seed), 0, -0.8 + 1.6 * uniform(&seed));
        vec3 e = photon_map_irradiance(&m, 1, 3, x, v3(0, 1, 0), 0, 0.5);
        worst = fmax(worst, fabs(e.x / (a / 4) - 1));
        assert_true(fabs(e.y - 2 * e.x) <= 1e-6 * e.y && fabs(e.z - 3 * e.x) <= 1e-6 * e.z);
    }
    printf("uniform density: worst relative error %.4f over 50 points\n", worst);
    assert_true(worst < 0.05);
    /* Over a footprint wider than the k nearest reach: every photon in it,
     * the same density. */
    vec3 wide = photon_map_irradiance(&m, 1, 3, v3(0.1, 0, -0.2), v3(0, 1, 0), 0.3, 0.5);
    printf("over a footprint of radius 0.3: %.4f of the density\n", wide.x / (a / 4));
    assert_true(fabs(wide.x / (a / 4) - 1) < 0.01);
    /* Beyond the photons (nothing within the reach): no light; another
     * level, surface or side: none either. */
    vec3 far = photon_map_irradiance(&m, 1, 3, v3(5, 0, 5), v3(0, 1, 0), 0, 0.5);
    assert_true(far.x == 0);
    assert_true(photon_map_irradiance(&m, 2, 3, v3(0, 0, 0), v3(0, 1, 0), 0, 0.5).x == 0);
    assert_true(photon_map_irradiance(&m, 1, 4, v3(0, 0, 0), v3(0, 1, 0), 0, 0.5).x == 0);
    assert_true(photon_map_irradiance(&m, 1, 3, v3(0, 0, 0), v3(0, -1, 0), 0, 0.5).x == 0);
    photon_map_free(&m);
}

/* The estimate by brute force: the k nearest of every photon on the
 * surface, level and side, within r_max, or all within r_min when the k
 * nearest lie closer. */
static double brute(const zone_photon *all, int n, vec3 x, double r_min, double r_max)
{
    double *d2 = malloc((size_t)n * sizeof *d2);
    int *idx = malloc((size_t)n * sizeof *idx), c = 0;
    for (int i = 0; i < n; i++) {
        double dx = x.x - all[i].x[0], dy = x.y - all[i].x[1], dz = x.z - all[i].x[2];
        double d = dx * dx + dy * dy + dz * dz;
        if (all[i].level == 1 && all[i].surface == 0 && all[i].n[1] > 0 && d < r_max * r_max) {
            d2[c] = d;
            idx[c++] = i;
        }
    }
    /* Selection of the k smallest. */
    int k = c < PHOTON_MAP_K ? c : PHOTON_MAP_K;
    for (int i = 0; i < k; i++)
        for (int j = i + 1; j < c; j++)
            if (d2[j] < d2[i]) {
                double t = d2[i];
                d2[i] = d2[j];
                d2[j] = t;
                int u = idx[i];
                idx[i] = idx[j];
                idx[j] = u;
            }
    double r2 = c >= PHOTON_MAP_K ? d2[PHOTON_MAP_K - 1] : r_max * r_max, e = 0;
    if (c >= PHOTON_MAP_K && r2 < r_min * r_min && r_min < r_max) {
        /* Every photon within the footprint. */
        r2 = r_min * r_min;
        for (int i = 0; i < c; i++)
            if (d2[i] < r2)
                e += (1 - d2[i] / r2) * all[idx[i]].flux[0];
    } else {
        for (int i = 0; i < k; i++)
            e += (1 - d2[i] / r2) * all[idx[i]].flux[0];
    }
    free(d2);
    free(idx);
    return e * 2 / (PI_D * r2);
}

/* Clustered photons on two surfaces, two levels and both sides: the tree's
 * estimate is the brute-force one at every point, near and far from the
 * clusters, with the reach or the footprint binding or not. */
static void test_matches_brute_force(void **state)
{
    (void)state;
    photon_map in, m;
    memset(&in, 0, sizeof in);
    memset(&m, 0, sizeof m);
    uint32_t seed = 11;
    int n = 6000;
    zone_photon *all = malloc((size_t)n * sizeof *all);
    for (int i = 0; i < n; i++) {
        double cx = (i % 3) * 0.7, cz = (i % 5) * 0.3, s = 0.05 + 0.2 * (i % 2);
        all[i] = photon(cx + s * (uniform(&seed) - 0.5), 0.01 * uniform(&seed),
                        cz + s * (uniform(&seed) - 0.5), 0.1 + uniform(&seed), i % 7 == 0,
                        1 + (i % 11 == 0), i % 13 != 0);
        assert_true(photon_map_add(&in, &all[i]));
    }
    assert_true(photon_map_build(&m, &in, 1, 3, 2));
    for (int k = 0; k < 200; k++) {
        vec3 x = v3(-0.3 + 2.0 * uniform(&seed), 0, -0.3 + 1.8 * uniform(&seed));
        double r_max = k % 2 ? 0.05 : 1.0, r_min = k % 3 ? 0 : 0.04;
        double want = brute(all, n, x, r_min, r_max);
        double got = photon_map_irradiance(&m, 1, 0, x, v3(0, 1, 0), r_min, r_max).x;
        assert_true(fabs(got - want) <= 1e-4 * fmax(want, 1e-3));
    }
    free(all);
    photon_map_free(&m);
}

/* Photons given in two parts are taken in order: the same trees as from
 * one part; photons of levels or surfaces out of range are left out; the
 * same photons in another order give other trees but the same estimates.
 * Trees read back are adopted; photons out of order or a bad axis are
 * refused. */
static void test_parts_and_order(void **state)
{
    (void)state;
    photon_map one, two[2], rev, a, b, c;
    memset(&one, 0, sizeof one);
    memset(two, 0, sizeof two);
    memset(&rev, 0, sizeof rev);
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    memset(&c, 0, sizeof c);
    uint32_t seed = 3;
    int n = 3000;
    zone_photon *all = malloc((size_t)n * sizeof *all);
    for (int i = 0; i < n; i++)
        all[i] = photon(uniform(&seed), 0.1 * uniform(&seed), uniform(&seed), uniform(&seed),
                        i % 5, 1 + i % 3, 1);
    for (int i = 0; i < n; i++) {
        assert_true(photon_map_add(&one, &all[i]));
        assert_true(photon_map_add(&two[i < n / 3 ? 0 : 1], &all[i]));
        assert_true(photon_map_add(&rev, &all[n - 1 - i]));
    }
    /* Levels 1 and 2 of surfaces 0..3: 8 trees; level 3 and surface 4
     * left out. */
    assert_true(photon_map_build(&a, &one, 1, 3, 4));
    assert_true(photon_map_build(&b, two, 2, 3, 4));
    assert_true(photon_map_build(&c, &rev, 1, 3, 4));
    assert_int_equal(a.group_count, 8);
    size_t want = 0;
    for (int i = 0; i < n; i++)
        want += all[i].level < 3 && all[i].surface < 4;
    assert_int_equal(a.count, want);
    assert_int_equal(b.count, want);
    assert_memory_equal(a.p, b.p, want * sizeof *a.p);
    assert_memory_equal(a.axis, b.axis, want);
    for (int k = 0; k < 100; k++) {
        vec3 x = v3(uniform(&seed), 0.05, uniform(&seed));
        double ea = photon_map_irradiance(&a, 1 + k % 2, k % 4, x, v3(0, 1, 0), 0, 0.3).x;
        double ec = photon_map_irradiance(&c, 1 + k % 2, k % 4, x, v3(0, 1, 0), 0, 0.3).x;
        assert_true(fabs(ea - ec) <= 1e-5 * ea);
    }
    assert_int_equal(photon_map_adopt(&c), 1);
    assert_int_equal(c.group_count, 8);
    c.axis[5] = 3;
    assert_int_equal(photon_map_adopt(&c), 0);
    c.axis[5] = 0;
    zone_photon t = c.p[0];
    c.p[0] = c.p[want - 1];
    c.p[want - 1] = t;
    assert_int_equal(photon_map_adopt(&c), 0);
    free(all);
    photon_map_free(&a);
    photon_map_free(&b);
    photon_map_free(&c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_uniform_density),
        cmocka_unit_test(test_matches_brute_force),
        cmocka_unit_test(test_parts_and_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
