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

/* A sphere's centre and radius as the scene gave them, in double: a float
 * rounds smallpt's wall centres (10^5 away) by up to 0.004, which moved
 * its ceiling up by 0.0016 and showed 0.58% more of the light sphere that
 * cuts through it. */
static inline double shape_sphere_double(const rs_part *p, double c[3])
{
    c[0] = (double)p->p0.x + p->c_lo.x;
    c[1] = (double)p->p0.y + p->c_lo.y;
    c[2] = (double)p->p0.z + p->c_lo.z;
    return (double)p->radius + p->r_lo;
}

/* Geometric form of the quadratic, which keeps precision when the ray
 * starts far away (Haines et al., Ray Tracing Gems ch. 7), in double: a
 * sphere used as a wall (radius 10^5 around a room 100 wide, as smallpt
 * builds its room) has r^2 = 10^10, where a float's unit in the last
 * place is 1024 and the roots would be off by whole units. */
static inline float shape_sphere_hit(const rs_part *p, vec3f o, vec3f d,
                                     float tmin, float tmax)
{
    double ctr[3], r = shape_sphere_double(p, ctr);
    double fx = (double)o.x - ctr[0], fy = (double)o.y - ctr[1], fz = (double)o.z - ctr[2];
    double b = -(fx * d.x + fy * d.y + fz * d.z);
    double lx = fx + d.x * b, ly = fy + d.y * b, lz = fz + d.z * b;
    double r2 = r * r;
    double disc = r2 - (lx * lx + ly * ly + lz * lz);
    if (disc < 0.0)
        return -1.0f;
    double c = fx * fx + fy * fy + fz * fz - r2;
    double q = b + copysign(sqrt(disc), b);
    double t0 = q != 0.0 ? c / q : 0.0, t1 = q;
    if (t0 > t1) {
        double tmp = t0; t0 = t1; t1 = tmp;
    }
    /* Compared as the floats returned, so that a query up to a hit's
     * distance does not find that hit before it. */
    float f0 = (float)t0, f1 = (float)t1;
    if (f0 > tmin && f0 < tmax)
        return f0;
    /* The far root is the inside of the sphere, hidden when culled. */
    if (!p->culled && f1 > tmin && f1 < tmax)
        return f1;
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

/* The point where a ray meets the part, put back onto its surface where
 * that matters.  o + t d carries the rounding of t and of the product,
 * which grows with the ray's length and the coordinates' size: on a floor
 * seen from afar it reaches the few units in the last place by which
 * ray_offset moves a point off a surface near a zero coordinate, and rays
 * from the point would meet the surface again.  A sphere's point is put
 * back onto it in double (as pbrt-v4 reprojects its sphere hits), a
 * plane's onto the plane (exact for the axis-aligned planes rooms are made
 * of).  Triangles keep o + t d, the case ray_offset's margins were made
 * for. */
static inline vec3f shape_hit_point(const rs_part *p, vec3f o, vec3f d, float t)
{
    vec3f x = f3_madd(o, d, t);
    if (p->shape == SHAPE_SPHERE) {
        double c[3], r = shape_sphere_double(p, c);
        double vx = (double)x.x - c[0], vy = (double)x.y - c[1], vz = (double)x.z - c[2];
        double len = sqrt(vx * vx + vy * vy + vz * vz);
        if (!(len > 0.0))
            return x;
        double k = r / len;
        return f3((float)(c[0] + vx * k), (float)(c[1] + vy * k), (float)(c[2] + vz * k));
    }
    if (p->shape == SHAPE_PLANE) {
        float e = f3_dot(p->n, x) - p->offset;
        return f3_sub(x, f3_scale(p->n, e));
    }
    return x;
}

/* Geometric normal at point x on the part (unit, the part's front side). */
static inline vec3f shape_normal(const rs_part *p, vec3f x)
{
    if (p->shape == SHAPE_SPHERE)
        return f3_scale(f3_sub(x, p->p0), 1.0f / p->radius);
    return p->n;
}

#endif
