/* A ray with each component in all four lanes, set up once per query and
 * shared by the plane blocks and the BVH's box and triangle tests (which
 * otherwise broadcast the same scalars again at every block, node and
 * packet). */
#ifndef ZT_GEOM_RAY4_H
#define ZT_GEOM_RAY4_H

#include "util/simd4.h"
#include "util/vec3f.h"

typedef struct ray4 {
    f4 ox, oy, oz;
    f4 dx, dy, dz;
} ray4;

static inline ray4 ray4_make(vec3f o, vec3f d)
{
    ray4 r = {f4_splat(o.x), f4_splat(o.y), f4_splat(o.z),
              f4_splat(d.x), f4_splat(d.y), f4_splat(d.z)};
    return r;
}

#endif
