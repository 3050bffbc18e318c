/* Moving a ray origin off a surface so the new ray does not hit the surface
 * it starts on.  The offset is a few units in the last place of the
 * coordinates, along the geometric normal, plus a small absolute amount near
 * the origin (Waechter and Binder, "A Fast and Robust Method for Avoiding
 * Self-Intersection", Ray Tracing Gems, 2019). */
#ifndef ZT_GEOM_RAY_OFFSET_H
#define ZT_GEOM_RAY_OFFSET_H

#include <stdint.h>
#include <string.h>
#include "util/simd4.h"
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
 * length) points to, one component at a time (the reference). */
static inline vec3f ray_offset_scalar(vec3f p, vec3f n)
{
    return f3(offset_component(p.x, n.x), offset_component(p.y, n.y),
              offset_component(p.z, n.z));
}

/* The same bits as ray_offset_scalar, the three components in vector lanes:
 * the scalar form cost two branches and about 45 instructions per vertex. */
typedef uint32_t u4 __attribute__((vector_size(16)));

static inline vec3f ray_offset(vec3f p, vec3f n)
{
    f4 pv = {p.x, p.y, p.z, 0.0f}, nv = {n.x, n.y, n.z, 0.0f};
    f4 near = pv + f4_splat(1.0f / 65536.0f) * nv;
    i4 of = __builtin_convertvector(f4_splat(256.0f) * nv, i4);
    u4 neg = (u4)(pv < f4_splat(0.0f));
    /* Both forms are computed: unsigned lanes, since the unused one may
     * wrap (-0.0 is INT_MIN as bits).  (of ^ ~0) + 1 is -of. */
    u4 far = (u4)pv + (((u4)of ^ neg) - neg);
    i4 small = ((i4)pv & i4_splat(0x7fffffff)) < i4_splat(0x3d000000); /* |p| < 1/32 */
    f4 r = f4_select(small, near, (f4)far);
    return f3(r[0], r[1], r[2]);
}

/* Where a shadow ray from o toward a point `target` on a light ends: short
 * of the target by 10^-5 of the distance, and at least by 32 units in the
 * last place of the largest coordinate of either end (more than the point,
 * the ray's length and the light's surface can disagree by).  Whatever
 * stands in the gap is not seen: a wider one (10^-4: 0.07 units in
 * smallpt's room) lets a light cut by a wall shine through the wall's last
 * stretch, and ending at the 32 units alone costs the Cornell box 12%. */
static inline float shadow_ray_end(vec3f o, vec3f target, float dist)
{
    /* The largest magnitude (at least 1) in vector lanes: exact, as max is. */
    const i4 abs_bits = i4_splat(0x7fffffff);
    f4 a = (f4)((i4)(f4){o.x, o.y, o.z, 1.0f} & abs_bits);
    f4 b = (f4)((i4)(f4){target.x, target.y, target.z, 1.0f} & abs_bits);
    float m = f4_hmax(f4_max(a, b))[0];
    float end = dist - f_max(32.0f * 1.1920929e-7f * m, 1e-5f * dist);
    return end > 0.5f * dist ? end : 0.5f * dist;
}

#endif
