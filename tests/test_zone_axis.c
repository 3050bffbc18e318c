/* The texel edges of a map axis with cut end texels (zone/zone_maps.h):
 * they must rise, start at 0 and end at the axis' length, and the cut
 * texels must halve towards both ends. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>

#include "zone/zone_maps.h"

static void check_axis(int n, int grade)
{
    map_layout l = {0};
    l.au = axis_uniform(n, 3.0, grade);
    l.av = axis_uniform(2, 1.0, 0);
    assert_true(map_layout_cache(&l));
    const map_axis *a = &l.au;
    assert_int_equal(a->n, n + 2 * grade);
    assert_true(fabs(axis_edge(a, 0)) < 1e-15);
    assert_true(fabs(axis_edge(a, a->n) - 1.0) < 1e-15);
    for (int i = 0; i < a->n; i++)
        assert_true(axis_edge(a, i + 1) > axis_edge(a, i));
    double w = 1.0 / n; /* an uncut texel, as a fraction of the axis */
    for (int k = 0; k <= grade; k++) {
        /* Texel k from either end: w / 2^grade for the first two, then
         * doubling up to w / 2. */
        double want = k == 0 ? w / (1 << grade) : w / (1 << (grade + 1 - k));
        double near = axis_edge(a, k + 1) - axis_edge(a, k);
        double far = axis_edge(a, a->n - k) - axis_edge(a, a->n - k - 1);
        assert_true(fabs(near - want) < 1e-12);
        assert_true(fabs(far - want) < 1e-12);
    }
    for (int i = grade + 1; i < a->n - grade - 1; i++)
        assert_true(fabs(axis_edge(a, i + 1) - axis_edge(a, i) - w) < 1e-12);
    free(l.au.edge);
    free(l.av.edge);
}

static void test_graded_edges(void **state)
{
    (void)state;
    check_axis(5, 0);
    check_axis(5, 1);
    check_axis(7, 2);
    check_axis(2, 2); /* two texels, both cut */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_graded_edges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
