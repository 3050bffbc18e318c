#include "zone/zone_maps.h"

#include <stdlib.h>

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

static int mip_size(int n, int k)
{
    n >>= k;
    return n > 0 ? n : 1;
}

/* Bilinear read of one level and side of mip k at normalised (s, t). */
static vec3 bilinear(const part_map *m, int k, int level, int side, double s, double t)
{
    const map_layout *l = &m->layout;
    int nu = mip_size(l->nu, k), nv = mip_size(l->nv, k);
    const float *base = m->mip[k] + (((size_t)level * l->sides + side) * (size_t)nv * nu) * 3;
    const float *wt = m->weight[k] + (size_t)side * nv * nu;
    double u = s * nu - 0.5, v = t * nv - 0.5;
    int wrap = l->shape == SHAPE_SPHERE;
    if (!wrap)
        u = fmin(fmax(u, 0.0), nu - 1.0);
    v = fmin(fmax(v, 0.0), nv - 1.0);
    int i0 = (int)floor(u), j0 = (int)floor(v);
    double fu = u - i0, fv = v - j0;
    int i1 = i0 + 1, j1 = j0 + 1 < nv ? j0 + 1 : j0;
    if (wrap) {
        i0 = ((i0 % nu) + nu) % nu;
        i1 = i1 % nu;
    } else if (i1 >= nu) {
        i1 = i0;
    }
    size_t idx[4] = {(size_t)j0 * nu + i0, (size_t)j0 * nu + i1, (size_t)j1 * nu + i0,
                     (size_t)j1 * nu + i1};
    double w[4] = {(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv};
    /* Texels off the reachable surface do not take part; the values are
     * weighted means, so they are scaled back by their weights. */
    double sw = 0;
    vec3 r = v3(0, 0, 0);
    vec3 plain = v3(0, 0, 0);
    for (int q = 0; q < 4; q++) {
        double ww = w[q] * wt[idx[q]];
        const float *px = base + idx[q] * 3;
        vec3 val = v3(px[0], px[1], px[2]);
        r = v3_add(r, v3_scale(val, ww));
        plain = v3_add(plain, v3_scale(val, w[q]));
        sw += ww;
    }
    /* Nothing reachable around: the plain bilinear value. */
    return sw > 1e-6 ? v3_scale(r, 1.0 / sw) : plain;
}

vec3 map_lookup_wide(const part_map *m, int level, int side, vec3 p, double width)
{
    const map_layout *l = &m->layout;
    if (level < 0 || level >= m->levels || !m->texels)
        return v3(0, 0, 0);
    if (side >= l->sides)
        side = l->sides - 1;
    double u, v;
    map_coords(l, p, &u, &v);
    double s = (u + 0.5) / l->nu, t = (v + 0.5) / l->nv;
    double texel = l->shape == SHAPE_SPHERE
                       ? 3.14159265358979 * l->radius / l->nv
                       : 0.5 * (v3_length(l->du) / l->nu + v3_length(l->dv) / l->nv);
    double lod = width > texel ? log2(width / texel) : 0.0;
    if (lod > m->mips - 1)
        lod = m->mips - 1;
    int k0 = (int)lod;
    vec3 a = bilinear(m, k0, level, side, s, t);
    if (k0 + 1 >= m->mips || lod == k0)
        return a;
    vec3 b = bilinear(m, k0 + 1, level, side, s, t);
    double f = lod - k0;
    return v3_add(v3_scale(a, 1 - f), v3_scale(b, f));
}

int map_build_mips(part_map *m, int level)
{
    const map_layout *l = &m->layout;
    m->mip[0] = m->texels;
    if (m->mips == 0) {
        /* Allocate every copy once, for all levels. */
        m->mips = 1;
        for (int k = 1; k < MAP_MIPS && (mip_size(l->nu, k - 1) > 1 || mip_size(l->nv, k - 1) > 1) &&
                        l->shape != SHAPE_SPHERE; k++) {
            size_t n = (size_t)m->levels * l->sides * mip_size(l->nu, k) * mip_size(l->nv, k) * 3;
            m->mip[k] = calloc(n, sizeof(float));
            m->weight[k] = calloc((size_t)l->sides * mip_size(l->nu, k) * mip_size(l->nv, k),
                                  sizeof(float));
            if (!m->mip[k] || !m->weight[k])
                return 0;
            m->mips = k + 1;
        }
    }
    for (int k = 1; k < m->mips; k++) {
        int nu = mip_size(l->nu, k), nv = mip_size(l->nv, k);
        int pu = mip_size(l->nu, k - 1), pv = mip_size(l->nv, k - 1);
        for (int side = 0; side < l->sides; side++) {
            const float *src = m->mip[k - 1] + (((size_t)level * l->sides + side) * (size_t)pv * pu) * 3;
            const float *sw = m->weight[k - 1] + (size_t)side * pv * pu;
            float *dst = m->mip[k] + (((size_t)level * l->sides + side) * (size_t)nv * nu) * 3;
            float *dw = m->weight[k] + (size_t)side * nv * nu;
            for (int j = 0; j < nv; j++)
                for (int i = 0; i < nu; i++) {
                    /* Weighted mean of the (up to) 2x2 finer texels. */
                    double sum[3] = {0, 0, 0}, wsum = 0;
                    int cnt = 0;
                    for (int dj = 0; dj < 2; dj++)
                        for (int di = 0; di < 2; di++) {
                            int si = 2 * i + di, sj = 2 * j + dj;
                            if (si >= pu || sj >= pv)
                                continue;
                            size_t q = (size_t)sj * pu + si;
                            double w = sw[q] > 0 ? sw[q] : 1e-9;
                            for (int c = 0; c < 3; c++)
                                sum[c] += w * src[q * 3 + c];
                            wsum += w;
                            cnt++;
                        }
                    for (int c = 0; c < 3; c++)
                        dst[((size_t)j * nu + i) * 3 + c] = (float)(sum[c] / wsum);
                    dw[(size_t)j * nu + i] = (float)(wsum / cnt);
                }
        }
    }
    return 1;
}

void map_free(part_map *m)
{
    free(m->texels);
    for (int k = 1; k < m->mips; k++)
        free(m->mip[k]);
    for (int k = 0; k < MAP_MIPS; k++)
        free(m->weight[k]);
    free(m->sat);
}
