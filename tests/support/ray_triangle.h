/* Whether a ray or a segment meets a triangle (either side), for tests
 * that integrate light numerically: the Moller-Trumbore test in double
 * precision.  Header-only. */
#ifndef ZT_TEST_RAY_TRIANGLE_H
#define ZT_TEST_RAY_TRIANGLE_H

#include <math.h>

#include "util/vec3.h"

/* The distance t along o + t d at which the line meets the triangle, or
 * -1 where it passes by (or runs parallel). */
static inline double line_triangle_t(vec3 o, vec3 d, const vec3 tri[3])
{
    vec3 e1 = v3_sub(tri[1], tri[0]), e2 = v3_sub(tri[2], tri[0]);
    vec3 p = v3_cross(d, e2);
    double det = v3_dot(e1, p);
    if (fabs(det) < 1e-14)
        return -1;
    vec3 s = v3_sub(o, tri[0]);
    double u = v3_dot(s, p) / det;
    vec3 q = v3_cross(s, e1);
    double v = v3_dot(d, q) / det;
    return u >= 0 && v >= 0 && u + v <= 1 ? v3_dot(e2, q) / det : -1;
}

static inline int ray_hits_triangle(vec3 o, vec3 d, const vec3 tri[3])
{
    return line_triangle_t(o, d, tri) > 0;
}

/* Whether the segment from a to b meets a triangle between its ends (for
 * occluders that may lie beyond b). */
static inline int segment_hits_triangle(vec3 a, vec3 b, const vec3 tri[3])
{
    double t = line_triangle_t(a, v3_sub(b, a), tri);
    return t > 1e-9 && t < 1 - 1e-9;
}

#endif
