/* Four-lane float and int vectors (GCC/Clang vector extensions), for the
 * BVH's box and triangle tests.  The compiler would not vectorise those
 * short loops by itself; these types make each lane operation one SSE
 * instruction.  Lane by lane the arithmetic is the scalar arithmetic, so
 * the results are the same bits.  Masks are -1 (true) or 0 per lane. */
#ifndef ZT_UTIL_SIMD4_H
#define ZT_UTIL_SIMD4_H

#include <stdint.h>

#ifdef __SSE__
#include <xmmintrin.h>
#endif

typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));

static inline f4 f4_splat(float s) { return (f4){s, s, s, s}; }
static inline i4 i4_splat(int32_t s) { return (i4){s, s, s, s}; }

/* m ? a : b, lane by lane. */
static inline f4 f4_select(i4 m, f4 a, f4 b)
{
    return (f4)((m & (i4)a) | (~m & (i4)b));
}

/* a < b ? a : b and a > b ? a : b, as the scalar code writes them (and as
 * minps and maxps compute them). */
static inline f4 f4_min(f4 a, f4 b)
{
#ifdef __SSE__
    return (f4)_mm_min_ps((__m128)a, (__m128)b);
#else
    return f4_select(a < b, a, b);
#endif
}

static inline f4 f4_max(f4 a, f4 b)
{
#ifdef __SSE__
    return (f4)_mm_max_ps((__m128)a, (__m128)b);
#else
    return f4_select(a > b, a, b);
#endif
}

/* The lanes' sum, pairwise. */
static inline float f4_hsum(f4 a) { return (a[0] + a[1]) + (a[2] + a[3]); }

/* The smallest lane, in every lane. */
static inline f4 f4_hmin(f4 a)
{
#ifdef __SSE__
    __m128 v = (__m128)a;
    v = _mm_min_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
    v = _mm_min_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 3, 2)));
    return (f4)v;
#else
    float m = a[0];
    for (int i = 1; i < 4; i++)
        m = a[i] < m ? a[i] : m;
    return f4_splat(m);
#endif
}

/* The largest lane, in every lane. */
static inline f4 f4_hmax(f4 a)
{
#ifdef __SSE__
    __m128 v = (__m128)a;
    v = _mm_max_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
    v = _mm_max_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 3, 2)));
    return (f4)v;
#else
    float m = a[0];
    for (int i = 1; i < 4; i++)
        m = a[i] > m ? a[i] : m;
    return f4_splat(m);
#endif
}

/* Bit i set when lane i of the mask is true. */
static inline int i4_bits(i4 m)
{
#ifdef __SSE__
    return _mm_movemask_ps((__m128)m);
#else
    return (m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8);
#endif
}

#endif
