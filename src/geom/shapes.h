/* Ray intersection with single primitives in single precision.  Each
 * returns the distance t in (tmin, tmax) of the first valid hit, or a value
 * <= 0 for a miss.  "culled" primitives are invisible from behind. */
#ifndef ZT_GEOM_SHAPES_H
#define ZT_GEOM_SHAPES_H

#include "geom/hit.h"
#include "render/render_scene.h"

static inline float shape_plane_hit(const rs_part *p, vec3f o, vec3f d,
                                    float tmin, float tmax)
{
    float dn = f3_dot(d, p->n);
    if (dn == 0.0f || (p->culled && dn > 0.0f))
        return -1.0f;
    /* t = num / dn; compare before dividing, most planes are rejected. */
    float num = p->offset - f3_dot(o, p->n);
    if (dn < 0.0f ? (num >= tmin * dn || num <= tmax * dn)
                  : (num <= tmin * dn || num >= tmax * dn))
        return -1.0f;
    float t = num / dn;
    return (t > tmin && t < tmax) ? t : -1.0f;
}

/* Moeller-Trumbore for the inside test (u, v); t comes from the plane.
 * MT's t, e2.qv / det, loses digits when e1 and e2 are nearly parallel
 * (det cancels): a sliver listed from its sharp end had hits 2e-5 below
 * its plane, beyond ray_offset, and shadowed itself.  With n (unit, from
 * double precision) the hit is within a few ulps of |o - p0| of the plane
 * whatever the triangle's shape. */
static inline float shape_triangle_hit(const rs_part *p, vec3f o, vec3f d,
                                       float tmin, float tmax)
{
    vec3f pv = f3_cross(d, p->e2);
    float det = f3_dot(p->e1, pv);
    /* det = -d.N: a front-side hit has det > 0 */
    if (p->culled ? det <= 0.0f : det == 0.0f)
        return -1.0f;
    float inv = 1.0f / det;
    vec3f tv = f3_sub(o, p->p0);
    float u = f3_dot(tv, pv) * inv;
    if (u < 0.0f || u > 1.0f)
        return -1.0f;
    vec3f qv = f3_cross(tv, p->e1);
    float v = f3_dot(d, qv) * inv;
    if (v < 0.0f || u + v > 1.0f)
        return -1.0f;
    float dn = f3_dot(p->n, d);
    /* Parallel: a miss, not t = inf or NaN.  Culled: dn must agree with
     * det that the ray meets the front, or a grazing ray whose two
     * roundings disagree could hit from behind. */
    if (p->culled ? dn >= 0.0f : dn == 0.0f)
        return -1.0f;
    float t = -f3_dot(p->n, tv) / dn;
    return (t > tmin && t < tmax) ? t : -1.0f;
}

/* Geometric form of the quadratic, which keeps precision when the ray
 * starts far away (Haines et al., Ray Tracing Gems ch. 7). */
static inline float shape_sphere_hit(const rs_part *p, vec3f o, vec3f d,
                                     float tmin, float tmax)
{
    vec3f f = f3_sub(o, p->p0);
    float b = -f3_dot(f, d);
    vec3f l = f3_madd(f, d, b);
    float r2 = p->radius * p->radius;
    float disc = r2 - f3_dot(l, l);
    if (disc < 0.0f)
        return -1.0f;
    float c = f3_dot(f, f) - r2;
    float q = b + copysignf(sqrtf(disc), b);
    float t0 = q != 0.0f ? c / q : 0.0f, t1 = q;
    if (t0 > t1) {
        float tmp = t0; t0 = t1; t1 = tmp;
    }
    if (t0 > tmin && t0 < tmax)
        return t0;
    /* The far root is the inside of the sphere, hidden when culled. */
    if (!p->culled && t1 > tmin && t1 < tmax)
        return t1;
    return -1.0f;
}

static inline float shape_hit(const rs_part *p, vec3f o, vec3f d, float tmin,
                              float tmax)
{
    switch (p->shape) {
    case SHAPE_TRIANGLE: return shape_triangle_hit(p, o, d, tmin, tmax);
    case SHAPE_SPHERE: return shape_sphere_hit(p, o, d, tmin, tmax);
    case SHAPE_PLANE: return shape_plane_hit(p, o, d, tmin, tmax);
    default: return -1.0f;
    }
}

/* Geometric normal at point x on the part (unit, the part's front side). */
static inline vec3f shape_normal(const rs_part *p, vec3f x)
{
    if (p->shape == SHAPE_SPHERE)
        return f3_scale(f3_sub(x, p->p0), 1.0f / p->radius);
    return p->n;
}

#endif
