/* The small numerical helpers the samplers use in place of libm calls. */
#include "test_support.h"

#include <math.h>

#include "util/sincos_turn.h"
#include "util/vec3f.h"

/* sin and cos of 2 pi u against double precision on a fine grid of [0, 1)
 * and at the quarter turns, where the reduction changes quadrant. */
static void test_sincos_turn(void **state)
{
    (void)state;
    const double two_pi = 6.283185307179586;
    double worst = 0.0;
    for (int i = 0; i < (1 << 20); i++) {
        float u = (float)i / (float)(1 << 20);
        float s, c;
        sincos_turn(u, &s, &c);
        double a = two_pi * (double)u;
        worst = fmax(worst, fmax(fabs(s - sin(a)), fabs(c - cos(a))));
    }
    const float edges[] = {0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f,
                           0.99999994f};
    for (unsigned k = 0; k < sizeof edges / sizeof edges[0]; k++)
        for (int step = -2; step <= 2; step++) {
            float u = nextafterf(edges[k], step < 0 ? 0.0f : 1.0f);
            if (step == 0)
                u = edges[k];
            float s, c;
            sincos_turn(u, &s, &c);
            double a = two_pi * (double)u;
            worst = fmax(worst, fmax(fabs(s - sin(a)), fabs(c - cos(a))));
        }
    print_message("sincos_turn: largest error %.3g\n", worst);
    assert_true(worst < 1e-7);
}

/* The inlined clamps give 0 for NaN, as fmaxf(x, 0) does. */
static void test_clamps(void **state)
{
    (void)state;
    assert_true(f_max0(-1.0f) == 0.0f && f_max0(2.0f) == 2.0f && f_max0(NAN) == 0.0f);
    assert_true(f_clamp01(-1.0f) == 0.0f && f_clamp01(0.5f) == 0.5f);
    assert_true(f_clamp01(3.0f) == 1.0f && f_clamp01(NAN) == 0.0f);
    assert_true(f3_max(f3(1.0f, 3.0f, 2.0f)) == 3.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sincos_turn),
        cmocka_unit_test(test_clamps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
