/* Small double-precision vectors for tests that compute the expected
 * light themselves.  Header-only. */
#ifndef ZT_TEST_D3_H
#define ZT_TEST_D3_H

#include <math.h>

typedef struct { double x, y, z; } d3;

static inline d3 mk(double x, double y, double z) { d3 r = {x, y, z}; return r; }
static inline double dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline d3 add(d3 a, d3 b) { return mk(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline d3 scale(d3 a, double s) { return mk(a.x * s, a.y * s, a.z * s); }
static inline d3 unit(d3 a) { return scale(a, 1 / sqrt(dot(a, a))); }
static inline d3 cross(d3 a, d3 b)
{
    return mk(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

#endif
