/* Single-precision 3-vectors for the rendering hot loops. */
#ifndef ZT_UTIL_VEC3F_H
#define ZT_UTIL_VEC3F_H

#include <math.h>

typedef struct vec3f { float x, y, z; } vec3f;

static inline vec3f f3(float x, float y, float z) { vec3f r = {x, y, z}; return r; }
static inline vec3f f3_splat(float s) { return f3(s, s, s); }
static inline vec3f f3_add(vec3f a, vec3f b) { return f3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3f f3_sub(vec3f a, vec3f b) { return f3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3f f3_mul(vec3f a, vec3f b) { return f3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3f f3_scale(vec3f a, float s) { return f3(a.x * s, a.y * s, a.z * s); }
static inline vec3f f3_neg(vec3f a) { return f3(-a.x, -a.y, -a.z); }
static inline float f3_dot(vec3f a, vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3f f3_cross(vec3f a, vec3f b)
{
    return f3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float f3_length(vec3f a) { return sqrtf(f3_dot(a, a)); }
static inline vec3f f3_normalize(vec3f a)
{
    float l = f3_length(a);
    return l > 0.0f ? f3_scale(a, 1.0f / l) : a;
}
/* max(x, 0), min(max(x, 0), 1), min(max(x, -1), 1), max(a, b) and the
 * largest component as comparisons, which the compiler inlines: fmaxf is a
 * library call without -ffast-math, and a call in the hot loop spills
 * every float register.  A NaN x gives the lower end of the clamps, as
 * with fmaxf, and a NaN b in f_max a. */
static inline float f_max0(float x) { return x > 0.0f ? x : 0.0f; }
static inline float f_clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }
static inline float f_clamp1(float x) { return x > -1.0f ? (x < 1.0f ? x : 1.0f) : -1.0f; }
static inline float f_max(float a, float b) { return b > a ? b : a; }
static inline float f3_max(vec3f a)
{
    float m = a.x > a.y ? a.x : a.y;
    return m > a.z ? m : a.z;
}
static inline float f3_luminance(vec3f a) { return 0.2126f * a.x + 0.7152f * a.y + 0.0722f * a.z; }
static inline int f3_is_black(vec3f a) { return a.x <= 0.0f && a.y <= 0.0f && a.z <= 0.0f; }
static inline vec3f f3_madd(vec3f a, vec3f b, float s) { return f3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }

/* An orthonormal basis around unit n (Duff et al. 2017, branchless). */
static inline void f3_basis(vec3f n, vec3f *t, vec3f *b)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float c = n.x * n.y * a;
    *t = f3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = f3(c, sign + n.y * n.y * a, -n.y);
}

#endif
