#include "zone/zone_maps.h"

#define ZT_PI_D 3.14159265358979323846

void map_texel_point(const map_layout *l, int i, int j, vec3 *p, vec3 *n)
{
    double s = (i + 0.5) / l->nu, t = (j + 0.5) / l->nv;
    if (l->shape == SHAPE_SPHERE) {
        double theta = t * ZT_PI_D, phi = s * 2.0 * ZT_PI_D;
        *n = v3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
        *p = v3_add(l->centre, v3_scale(*n, l->radius));
        return;
    }
    *p = v3_add(l->origin, v3_add(v3_scale(l->du, s), v3_scale(l->dv, t)));
    *n = v3_normalize(v3_cross(l->du, l->dv));
}

void map_coords(const map_layout *l, vec3 p, double *u, double *v)
{
    if (l->shape == SHAPE_SPHERE) {
        vec3 d = v3_normalize(v3_sub(p, l->centre));
        double theta = acos(fmax(-1.0, fmin(1.0, d.z)));
        double phi = atan2(d.y, d.x);
        if (phi < 0)
            phi += 2.0 * ZT_PI_D;
        *u = phi / (2.0 * ZT_PI_D) * l->nu - 0.5;
        *v = theta / ZT_PI_D * l->nv - 0.5;
        return;
    }
    /* Solve p - origin = s du + t dv in the least-squares sense (du, dv
     * span the plane). */
    vec3 r = v3_sub(p, l->origin);
    double a = v3_dot(l->du, l->du), b = v3_dot(l->du, l->dv), c = v3_dot(l->dv, l->dv);
    double e = v3_dot(r, l->du), f = v3_dot(r, l->dv);
    double det = a * c - b * b;
    double s = det != 0 ? (e * c - b * f) / det : 0;
    double t = det != 0 ? (a * f - b * e) / det : 0;
    *u = s * l->nu - 0.5;
    *v = t * l->nv - 0.5;
}

vec3 map_lookup(const part_map *m, int level, int side, vec3 p)
{
    const map_layout *l = &m->layout;
    if (level < 0 || level >= m->levels)
        return v3(0, 0, 0);
    if (side >= l->sides)
        side = l->sides - 1;
    double u, v;
    map_coords(l, p, &u, &v);
    int wrap = l->shape == SHAPE_SPHERE;
    if (!wrap)
        u = fmin(fmax(u, 0.0), l->nu - 1.0);
    v = fmin(fmax(v, 0.0), l->nv - 1.0);
    int i0 = (int)floor(u), j0 = (int)floor(v);
    double fu = u - i0, fv = v - j0;
    int i1 = i0 + 1, j1 = j0 + 1 < l->nv ? j0 + 1 : j0;
    if (wrap) {
        i0 = ((i0 % l->nu) + l->nu) % l->nu;
        i1 = i1 % l->nu;
    } else if (i1 >= l->nu) {
        i1 = i0;
    }
    const float *a = map_texel(m, level, side, i0, j0), *b = map_texel(m, level, side, i1, j0);
    const float *c = map_texel(m, level, side, i0, j1), *d = map_texel(m, level, side, i1, j1);
    double w[4] = {(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv};
    return v3(w[0] * a[0] + w[1] * b[0] + w[2] * c[0] + w[3] * d[0],
              w[0] * a[1] + w[1] * b[1] + w[2] * c[1] + w[3] * d[1],
              w[0] * a[2] + w[1] * b[2] + w[2] * c[2] + w[3] * d[2]);
}
