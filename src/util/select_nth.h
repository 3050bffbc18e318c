/* Selection by one key (Hoare's quickselect), for trees split at the median:
 * after NAME(a, n, k, axis), a[k] is the element that sorting a[0, n) by
 * KEY(&a[i], axis) would put there, none before it has a greater key and
 * none after it a smaller one.  A macro, so that each tree builder gets its
 * own function with its key inlined:
 *
 *     DEFINE_SELECT_NTH(select_nth, prim_ref, centre)
 */
#ifndef ZT_UTIL_SELECT_NTH_H
#define ZT_UTIL_SELECT_NTH_H

#define DEFINE_SELECT_NTH(NAME, TYPE, KEY)                                     \
    static void NAME(TYPE *a, int n, int k, int axis)                          \
    {                                                                          \
        int lo = 0, hi = n - 1;                                                \
        while (lo < hi) {                                                      \
            float pivot = KEY(&a[lo + (hi - lo) / 2], axis);                   \
            int i = lo, j = hi;                                                \
            while (i <= j) {                                                   \
                while (KEY(&a[i], axis) < pivot)                               \
                    i++;                                                       \
                while (KEY(&a[j], axis) > pivot)                               \
                    j--;                                                       \
                if (i <= j) {                                                  \
                    TYPE t_ = a[i];                                            \
                    a[i++] = a[j];                                             \
                    a[j--] = t_;                                               \
                }                                                              \
            }                                                                  \
            if (k <= j)                                                        \
                hi = j;                                                        \
            else if (k >= i)                                                   \
                lo = i;                                                        \
            else                                                               \
                return;                                                        \
        }                                                                      \
    }

#endif
