/* Double-precision 3-vectors for the scene model and set-up code.  The hot
 * loops use vec3f.h instead. */
#ifndef ZT_UTIL_VEC3_H
#define ZT_UTIL_VEC3_H

#include <math.h>

typedef struct vec3 { double x, y, z; } vec3;

static inline vec3 v3(double x, double y, double z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3_splat(double a) { return v3(a, a, a); }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 v3_scale(vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline double v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_length(vec3 a) { return sqrt(v3_dot(a, a)); }
static inline vec3 v3_normalize(vec3 a)
{
    double l = v3_length(a);
    return l > 0 ? v3_scale(a, 1.0 / l) : a;
}
/* Unit tangents t, b completing unit n to a right-handed frame (t, b, n). */
static inline void v3_frame(vec3 n, vec3 *t, vec3 *b)
{
    vec3 a = fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0);
    *t = v3_normalize(v3_cross(a, n));
    *b = v3_cross(n, *t);
}
/* The tangents t, b of a frame turned by `angle` about its normal. */
static inline void v3_turn_frame(vec3 *t, vec3 *b, double angle)
{
    double c = cos(angle), s = sin(angle);
    vec3 tt = v3_add(v3_scale(*t, c), v3_scale(*b, s));
    *b = v3_sub(v3_scale(*b, c), v3_scale(*t, s));
    *t = tt;
}
/* min and max without fmin/fmax's NaN rules, which keep the compiler from
 * inlining them (hot loops over boxes). */
static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }
static inline vec3 v3_min3(vec3 a, vec3 b) { return (vec3){dmin(a.x, b.x), dmin(a.y, b.y), dmin(a.z, b.z)}; }
static inline vec3 v3_max3(vec3 a, vec3 b) { return (vec3){dmax(a.x, b.x), dmax(a.y, b.y), dmax(a.z, b.z)}; }
static inline double v3_max(vec3 a) { return dmax(a.x, dmax(a.y, a.z)); }
static inline int v3_isfinite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline int v3_is_black(vec3 a) { return a.x <= 0 && a.y <= 0 && a.z <= 0; }
static inline vec3 v3_from(const double a[3]) { return v3(a[0], a[1], a[2]); }
static inline void v3_store(vec3 a, double out[3]) { out[0] = a.x; out[1] = a.y; out[2] = a.z; }

/* Rotation about world axis 0 = X, 1 = Y, 2 = Z, right-hand rule. */
static inline vec3 v3_rotate_axis(vec3 a, int axis, double angle)
{
    double c = cos(angle), s = sin(angle);
    switch (axis) {
    case 0: return v3(a.x, a.y * c - a.z * s, a.y * s + a.z * c);
    case 1: return v3(a.x * c + a.z * s, a.y, -a.x * s + a.z * c);
    default: return v3(a.x * c - a.y * s, a.x * s + a.y * c, a.z);
    }
}

#endif
