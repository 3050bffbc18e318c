#include "zone/phase_one/glint.h"

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "light/light_sample.h"
#include "material/bsdf.h"
#include "render/prim.h"
#include "zone/light/lambert.h"
#include "util/vec3_convert.h"

#define DISK_SIDES_MAX 32  /* a sphere light's outline, as seen from its image */
#define BISECT_STEPS 32    /* the specular point to about 1e-10 of the arc */


int glint_sphere(const rscene *rs, int i)
{
    if (i < 0 || i >= rs->part_count)
        return 0;
    const rs_part *p = &rs->parts[i];
    if (p->is_light || p->shape != SHAPE_SPHERE)
        return 0;
    const rs_object *m = &rs->objects[p->object];
    /* A rough sphere spreads a light's image over its lobe: its photons
     * carry that light (caustic.c). */
    return !m->rough && (m->weight[LOBE_REFLECTING] > 0.0f || m->weight[LOBE_METALLIC] > 0.0f ||
                         m->weight[LOBE_REFRACTIVE] > 0.0f);
}

/* In the plane of c, x and y, the angle phi of s runs from x's direction
 * to y's, and at s the unit vectors to x and y have no component along the
 * tangent: bisection on phi. */
int glint_specular_point(vec3 c, double r, vec3 x, vec3 y, vec3 *s)
{
    vec3 px = v3_sub(x, c), py = v3_sub(y, c);
    double lx = v3_length(px);
    vec3 e1 = v3_scale(px, 1.0 / lx);
    vec3 t = v3_sub(py, v3_scale(e1, v3_dot(py, e1)));
    double tl = v3_length(t);
    if (tl < 1e-12 * v3_length(py)) {
        /* y on x's line through the centre: the reflection is back along it. */
        if (v3_dot(py, e1) <= 0)
            return 0;
        *s = v3_add(c, v3_scale(e1, r));
        return 1;
    }
    vec3 e2 = v3_scale(t, 1.0 / tl);
    double yx = v3_dot(py, e1), yy = tl;
    double lo = 0.0, hi = atan2(yy, yx);
    for (int k = 0; k < BISECT_STEPS; k++) {
        double phi = 0.5 * (lo + hi), cs = cos(phi), sn = sin(phi);
        double sx = r * cs, sy = r * sn;
        double ax = lx - sx, ay = -sy, bx = yx - sx, by = yy - sy;
        double la = sqrt(ax * ax + ay * ay), lb = sqrt(bx * bx + by * by);
        /* Tangential component (-sin, cos) of the sum of unit vectors. */
        double g = (-sn * ax + cs * ay) / la + (-sn * bx + cs * by) / lb;
        if (g > 0)
            lo = phi;
        else
            hi = phi;
    }
    double phi = 0.5 * (lo + hi);
    vec3 n = v3_add(v3_scale(e1, cos(phi)), v3_scale(e2, sin(phi)));
    *s = v3_add(c, v3_scale(n, r));
    return v3_dot(n, v3_sub(x, *s)) > 0 && v3_dot(n, v3_sub(y, *s)) > 0;
}

/* Irradiance at x (normal n) of unit radiance arriving from the directions
 * of the points q[0..2]: the triangle of directions, clipped to x's
 * horizon. */
static double image_irradiance(vec3 x, vec3 n, const vec3 q[3])
{
    vec3 a[3], out[4];
    double h[3];
    for (int i = 0; i < 3; i++) {
        a[i] = v3_add(x, v3_normalize(v3_sub(q[i], x)));
        h[i] = v3_dot(n, v3_sub(a[i], x));
    }
    int m = 0;
    for (int i = 0, j = 2; i < 3; j = i++) {
        if ((h[j] > 0) != (h[i] > 0)) {
            double u = h[j] / (h[j] - h[i]);
            out[m++] = v3_add(a[j], v3_scale(v3_sub(a[i], a[j]), u));
        }
        if (h[i] > 0)
            out[m++] = a[i];
    }
    return m >= 3 ? lambert_polygon(x, n, out, m) : 0.0;
}

/* Whether the path x -> s -> y is open: x on a receiver with normal n, s
 * on sphere part `mirror`, y on light part `light`. */
static int path_open(const rscene *rs, vec3 x, vec3 n, vec3 s, vec3 c, int mirror, vec3 y,
                     int light, uint64_t *rays)
{
    (*rays)++;
    vec3f xo = ray_offset(v3_to_f3(x), v3_to_f3(n));
    vec3 d1 = v3_sub(s, f3_to_v3(xo));
    double l1 = v3_length(d1);
    if (accel_occluded(rs, xo, v3_to_f3(v3_scale(d1, 1.0 / l1)), (float)(l1 * 0.9999),
                       rs->parts[mirror].background))
        return 0;
    (*rays)++;
    vec3f so = ray_offset(v3_to_f3(s), v3_to_f3(v3_normalize(v3_sub(s, c))));
    vec3 d2 = v3_sub(y, f3_to_v3(so));
    double l2 = v3_length(d2);
    rs_part lt;
    return !accel_occluded(rs, so, v3_to_f3(v3_scale(d2, 1.0 / l2)), (float)(l2 * 0.9999),
                           rs_prim(rs, light, &lt)->background);
}

/* Radiance reflected towards x by the sphere part `mirror` from light part
 * `light` at point y: emission, tint and reflectance at y's specular
 * point, or zero when x -> s -> y is blocked. */
static vec3 reflected(const rscene *rs, vec3 x, vec3 n, int mirror, int light, vec3 y,
                      uint64_t *rays)
{
    const rs_part *sp = &rs->parts[mirror];
    const rs_object *m = &rs->objects[sp->object];
    vec3 c = f3_to_v3(sp->p0), s;
    if (!glint_specular_point(c, sp->radius, x, y, &s) || !path_open(rs, x, n, s, c, mirror, y, light, rays))
        return v3(0, 0, 0);
    vec3 ns = v3_normalize(v3_sub(s, c));
    float cos_i = (float)v3_dot(ns, v3_normalize(v3_sub(x, s)));
    double k = m->weight[LOBE_REFLECTING];
    if (m->weight[LOBE_METALLIC] > 0.0f)
        k += m->weight[LOBE_METALLIC] * bsdf_schlick(cos_i, m->ior);
    /* Glass reflects its Fresnel share off its outside (the receiver is
     * outside it, in vacuum; what crosses the glass is gathered). */
    if (m->weight[LOBE_REFRACTIVE] > 0.0f)
        k += m->weight[LOBE_REFRACTIVE] * (m->thin ? bsdf_pane_reflectance(cos_i, m->ior)
                                                   : bsdf_fresnel_dielectric(cos_i, 1.0f, m->ior));
    rs_part lt;
    vec3f le = light_emitted(rs, light, rs_prim(rs, light, &lt), v3_to_f3(y),
                             v3_to_f3(v3_normalize(v3_sub(y, s))));
    return v3_scale(v3(le.x * m->color.x, le.y * m->color.y, le.z * m->color.z), k);
}

#define CUTS_MAX 8

/* The image of light triangle v[0..2] cut into n x n small triangles (its
 * outline follows the sphere's curvature better), with visibility,
 * emission and reflectance taken at the triangle's centre; the grid's
 * corners are carried to the sphere once each. */
static vec3 light_triangle(const rscene *rs, vec3 x, vec3 nx, int mirror, int light,
                           const vec3 v[3], int n, uint64_t *rays)
{
    const rs_part *sp = &rs->parts[mirror];
    vec3 c = f3_to_v3(sp->p0);
    if (n > CUTS_MAX)
        n = CUTS_MAX;
    vec3 s[CUTS_MAX + 1][CUTS_MAX + 1];
    unsigned char ok[CUTS_MAX + 1][CUTS_MAX + 1];
    vec3 e1 = v3_scale(v3_sub(v[1], v[0]), 1.0 / n), e2 = v3_scale(v3_sub(v[2], v[0]), 1.0 / n);
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            vec3 y = v3_add(v[0], v3_add(v3_scale(e1, i), v3_scale(e2, j)));
            /* A light may pierce the sphere: its points inside have no
             * image on the outside. */
            ok[i][j] = v3_length(v3_sub(y, c)) > sp->radius &&
                       glint_specular_point(c, sp->radius, x, y, &s[i][j]);
        }
    double g = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; i + j < n; j++) {
            if (ok[i][j] && ok[i + 1][j] && ok[i][j + 1]) {
                vec3 ss[3] = {s[i][j], s[i + 1][j], s[i][j + 1]};
                g += image_irradiance(x, nx, ss);
            }
            if (i + j + 1 < n && ok[i + 1][j] && ok[i + 1][j + 1] && ok[i][j + 1]) {
                vec3 ss[3] = {s[i + 1][j], s[i + 1][j + 1], s[i][j + 1]};
                g += image_irradiance(x, nx, ss);
            }
        }
    if (g <= 0)
        return v3(0, 0, 0);
    vec3 yc = v3_scale(v3_add(v3_add(v[0], v[1]), v[2]), 1.0 / 3.0);
    return v3_scale(reflected(rs, x, nx, mirror, light, yc, rays), g);
}

/* A sphere light's image: its outline as seen from the specular point of
 * its centre, a fan of triangles around that centre. */
static vec3 light_sphere(const rscene *rs, vec3 x, vec3 nx, int mirror, int light, int n,
                         uint64_t *rays)
{

    const rs_part *lp = &rs->parts[light], *sp = &rs->parts[mirror];
    vec3 cl = f3_to_v3(lp->p0), c = f3_to_v3(sp->p0), s0;
    double rl = lp->radius;
    if (!glint_specular_point(c, sp->radius, x, cl, &s0))
        return v3(0, 0, 0);
    vec3 d = v3_sub(cl, s0);
    double dist = v3_length(d);
    if (dist <= rl)
        return v3(0, 0, 0);
    vec3 w = v3_scale(d, 1.0 / dist);
    vec3 oc = v3_sub(cl, v3_scale(w, rl * rl / dist)); /* outline's centre and radius */
    double orad = rl * sqrt(1.0 - rl * rl / (dist * dist));
    vec3 u = v3_normalize(v3_cross(fabs(w.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0), w));
    vec3 v = v3_cross(w, u);
    int sides = 4 * n < DISK_SIDES_MAX ? 4 * n : DISK_SIDES_MAX;
    double step = 2.0 * 3.14159265358979323846 / sides;
    double re = orad * sqrt(step / sin(step)); /* a polygon of the disk's area */
    vec3 ring[DISK_SIDES_MAX], sc;
    if (!glint_specular_point(c, sp->radius, x, oc, &sc))
        return v3(0, 0, 0);
    for (int i = 0; i < sides; i++) {
        vec3 y = v3_add(oc, v3_add(v3_scale(u, re * cos(i * step)), v3_scale(v, re * sin(i * step))));
        if (!glint_specular_point(c, sp->radius, x, y, &ring[i]))
            return v3(0, 0, 0);
    }
    double g = 0;
    for (int i = 0; i < sides; i++) {
        vec3 ss[3] = {sc, ring[i], ring[(i + 1) % sides]};
        g += image_irradiance(x, nx, ss);
    }
    if (g <= 0)
        return v3(0, 0, 0);
    /* Visibility and emission at the light's surface point facing the
     * image (the outline's centre lies inside the light). */
    return v3_scale(reflected(rs, x, nx, mirror, light, v3_sub(cl, v3_scale(w, rl)), rays), g);
}

vec3 glint_irradiance(zone_trace *t, const int *spheres, int sphere_count, vec3 x, vec3 n,
                      int subdivisions)
{
    const rscene *rs = &t->r->rs;
    vec3 e = v3(0, 0, 0);
    for (int k = 0; k < sphere_count; k++) {
        int mi = spheres[k];
        const rs_part *sp = &rs->parts[mi];
        vec3 c = f3_to_v3(sp->p0);
        /* Nothing of the sphere above x's horizon, or x inside it. */
        if (v3_dot(n, v3_sub(c, x)) <= -sp->radius || v3_length(v3_sub(c, x)) <= sp->radius)
            continue;
        for (int j = 0; j < rs->light_count; j++) {
            int li = rs->lights[j].part;
            rs_part lt;
            const rs_part *lp = rs_prim(rs, li, &lt);
            if (lp->shape == SHAPE_TRIANGLE) {
                vec3 p0 = f3_to_v3(lp->p0);
                vec3 v[3] = {p0, v3_add(p0, f3_to_v3(lp->e1)),
                             v3_add(p0, f3_to_v3(lp->e2))};
                e = v3_add(e, light_triangle(rs, x, n, mi, li, v, subdivisions, &t->rays));
            } else if (lp->shape == SHAPE_SPHERE) {
                e = v3_add(e, light_sphere(rs, x, n, mi, li, subdivisions, &t->rays));
            }
        }
    }
    return e;
}
