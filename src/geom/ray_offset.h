/* Moving a ray origin off a surface so the new ray does not hit the surface
 * it starts on.  The offset is a few units in the last place of the
 * coordinates, along the geometric normal, plus a small absolute amount near
 * the origin (Waechter and Binder, "A Fast and Robust Method for Avoiding
 * Self-Intersection", Ray Tracing Gems, 2019). */
#ifndef ZT_GEOM_RAY_OFFSET_H
#define ZT_GEOM_RAY_OFFSET_H

#include <stdint.h>
#include <string.h>
#include "util/vec3f.h"

static inline float offset_component(float p, float n)
{
    const float origin = 1.0f / 32.0f, float_scale = 1.0f / 65536.0f;
    const float int_scale = 256.0f;
    if (fabsf(p) < origin)
        return p + float_scale * n;
    int32_t bits;
    memcpy(&bits, &p, sizeof bits);
    int32_t of = (int32_t)(int_scale * n);
    bits += (p < 0) ? -of : of;
    float r;
    memcpy(&r, &bits, sizeof r);
    return r;
}

/* p moved off the surface to the side that n (geometric normal, any
 * length) points to. */
static inline vec3f ray_offset(vec3f p, vec3f n)
{
    return f3(offset_component(p.x, n.x), offset_component(p.y, n.y),
              offset_component(p.z, n.z));
}

#endif
