#include "zone/zone_maps.h"

#include <stdlib.h>

#define ZT_PI_D 3.14159265358979323846

map_axis axis_uniform(int n, double len, int g)
{
    map_axis a = {n + 2 * g, 0, n + 2 * g, g, len / n, 1.0, len, NULL};
    return a;
}

/* Where edge j of a graded core lies, from its start. */
static double core_edge(const map_axis *a, int j)
{
    int g = a->grade, m = a->k1 - a->k0;
    if (j > m - g - 1) /* the far end mirrors the near one */
        return axis_core_span(a) - core_edge(a, m - j);
    if (j == 0)
        return 0.0;
    if (j <= g + 1)
        return a->w * ldexp(1.0, j - 1 - g);
    return a->w * (j - g);
}

double axis_outer_span(const map_axis *a, int m)
{
    return m > 0 ? a->w * a->r * (pow(a->r, m) - 1.0) / (a->r - 1.0) : 0.0;
}

static double edge_formula(const map_axis *a, int i)
{
    double c0 = axis_outer_span(a, a->k0), x;
    if (i < a->k0)
        x = c0 - axis_outer_span(a, a->k0 - i);
    else if (i <= a->k1)
        x = c0 + core_edge(a, i - a->k0);
    else
        x = c0 + axis_core_span(a) + axis_outer_span(a, i - a->k1);
    return x / a->len;
}

static int axis_cache(map_axis *a)
{
    free(a->edge);
    a->edge = malloc((size_t)(a->n + 1) * sizeof(double));
    if (!a->edge)
        return 0;
    for (int i = 0; i <= a->n; i++)
        a->edge[i] = edge_formula(a, i);
    return 1;
}

int map_layout_cache(map_layout *l)
{
    return axis_cache(&l->au) && axis_cache(&l->av);
}

/* Texel coordinate of fraction s along an axis: i + 0.5 at the middle of
 * texel i, linear inside each texel (and past the ends, in the end
 * texels' widths).  A binary search over the cached edges. */
static double axis_coord(const map_axis *a, double s)
{
    const double *e = a->edge;
    int n = a->n;
    if (s <= e[0])
        return (s - e[0]) / (e[1] - e[0]);
    if (s >= e[n])
        return n + (s - e[n]) / (e[n] - e[n - 1]);
    int lo = 0, hi = n; /* e[lo] <= s < e[hi] */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (e[mid] <= s)
            lo = mid;
        else
            hi = mid;
    }
    return lo + (s - e[lo]) / (e[lo + 1] - e[lo]);
}

vec3 map_point(const map_layout *l, double s, double t)
{
    return v3_add(l->origin, v3_add(v3_scale(l->du, s), v3_scale(l->dv, t)));
}

vec3 map_cell_centre(const map_layout *l, int i, int j, int su, int sv, int sub)
{
    double s0 = axis_edge(&l->au, i), s1 = axis_edge(&l->au, i + 1);
    double t0 = axis_edge(&l->av, j), t1 = axis_edge(&l->av, j + 1);
    return map_point(l, s0 + (s1 - s0) * (su + 0.5) / sub, t0 + (t1 - t0) * (sv + 0.5) / sub);
}

/* Solves p - origin = s du + t dv in the least-squares sense (du, dv span
 * the plane). */
static void plane_st(const map_layout *l, vec3 p, double *s, double *t)
{
    vec3 r = v3_sub(p, l->origin);
    double a = v3_dot(l->du, l->du), b = v3_dot(l->du, l->dv), c = v3_dot(l->dv, l->dv);
    double e = v3_dot(r, l->du), f = v3_dot(r, l->dv);
    double det = a * c - b * b;
    *s = det != 0 ? (e * c - b * f) / det : 0;
    *t = det != 0 ? (a * f - b * e) / det : 0;
}

void map_texel_point(const map_layout *l, int i, int j, vec3 *p, vec3 *n)
{
    if (l->shape == SHAPE_SPHERE) {
        double s = (i + 0.5) / l->nu, t = (j + 0.5) / l->nv;
        double theta = t * ZT_PI_D, phi = s * 2.0 * ZT_PI_D;
        *n = v3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
        *p = v3_add(l->centre, v3_scale(*n, l->radius));
        return;
    }
    double s = 0.5 * (axis_edge(&l->au, i) + axis_edge(&l->au, i + 1));
    double t = 0.5 * (axis_edge(&l->av, j) + axis_edge(&l->av, j + 1));
    *p = map_point(l, s, t);
    *n = v3_normalize(v3_cross(l->du, l->dv));
}

/* For a texel cut by the surface's edge, eval_st holds the centroid of the
 * part that exists. */
void map_texel_eval_point(const part_map *m, int u, int j, int side, vec3 *x, vec3 *n)
{
    const map_layout *l = &m->layout;
    map_texel_point(l, u, j, x, n);
    if (l->shape != SHAPE_SPHERE) {
        const float *st = m->eval_st + 2 * (((size_t)side * l->nv + j) * l->nu + u);
        *x = map_point(l, st[0], st[1]);
    }
    if (side)
        *n = v3_scale(*n, -1);
}

void map_texel_alt_point(const part_map *m, int u, int j, int side, vec3 *x, vec3 *n)
{
    const map_layout *l = &m->layout;
    map_texel_point(l, u, j, x, n);
    const float *st = m->alt_st + 2 * ((size_t)j * l->nu + u);
    *x = map_point(l, st[0], st[1]);
    if (side)
        *n = v3_scale(*n, -1);
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
    double s, t;
    plane_st(l, p, &s, &t);
    *u = axis_coord(&l->au, s) - 0.5;
    *v = axis_coord(&l->av, t) - 0.5;
}

int poly3_clip(vec3 *q, int n, int max, vec3 a, double b)
{
    int all_in = 1;
    for (int i = 0; i < n && all_in; i++)
        all_in = v3_dot(a, q[i]) + b >= 0;
    if (all_in) /* the common case: nothing to cut */
        return n;
    vec3 out[2 * MAP_CLIPS + 8];
    int k = 0, cap = max < (int)(sizeof out / sizeof out[0]) ? max : (int)(sizeof out / sizeof out[0]);
    for (int i = 0, j = n - 1; i < n; j = i++) {
        double di = v3_dot(a, q[i]) + b, dj = v3_dot(a, q[j]) + b;
        if ((dj >= 0) != (di >= 0) && k < cap)
            out[k++] = v3_add(q[j], v3_scale(v3_sub(q[i], q[j]), dj / (dj - di)));
        if (di >= 0 && k < cap)
            out[k++] = q[i];
    }
    for (int i = 0; i < k; i++)
        q[i] = out[i];
    return k;
}

int map_texel_polygon(const map_layout *l, int i, int j, vec3 *q, int max)
{
    return map_rect_polygon(l, axis_edge(&l->au, i), axis_edge(&l->au, i + 1),
                            axis_edge(&l->av, j), axis_edge(&l->av, j + 1), q, max);
}

int map_rect_polygon(const map_layout *l, double s0, double s1, double t0, double t1, vec3 *q,
                     int max)
{
    q[0] = map_point(l, s0, t0);
    q[1] = map_point(l, s1, t0);
    q[2] = map_point(l, s1, t1);
    q[3] = map_point(l, s0, t1);
    int n = 4;
    for (int k = 0; k < l->clips && n >= 3; k++)
        n = poly3_clip(q, n, max, l->clip_n[k], l->clip_d[k]);
    return n;
}

static double poly3_area(const vec3 *q, int n, vec3 *centroid)
{
    vec3 sum = v3(0, 0, 0), c = v3(0, 0, 0);
    double area = 0;
    vec3 nrm = v3(0, 0, 0);
    for (int k = 1; k + 1 < n; k++)
        nrm = v3_add(nrm, v3_cross(v3_sub(q[k], q[0]), v3_sub(q[k + 1], q[0])));
    double len = v3_length(nrm);
    if (len <= 0) {
        *centroid = q[0];
        return 0;
    }
    vec3 un = v3_scale(nrm, 1.0 / len);
    for (int k = 1; k + 1 < n; k++) {
        double a = 0.5 * v3_dot(v3_cross(v3_sub(q[k], q[0]), v3_sub(q[k + 1], q[0])), un);
        vec3 tc = v3_scale(v3_add(q[0], v3_add(q[k], q[k + 1])), 1.0 / 3.0);
        sum = v3_add(sum, v3_scale(tc, a));
        area += a;
    }
    c = area > 0 ? v3_scale(sum, 1.0 / area) : q[0];
    *centroid = c;
    return area;
}

int map_build_cover(part_map *m)
{
    const map_layout *l = &m->layout;
    size_t cells = (size_t)l->nu * l->nv;
    free(m->cover);
    free(m->eval_st);
    m->cover = malloc(cells * sizeof(float));
    m->eval_st = malloc(cells * 2 * (size_t)l->sides * sizeof(float));
    if (!m->cover || !m->eval_st)
        return 0;
    for (int j = 0; j < l->nv; j++)
        for (int i = 0; i < l->nu; i++) {
            size_t k = (size_t)j * l->nu + i;
            double s0 = axis_edge(&l->au, i), s1 = axis_edge(&l->au, i + 1);
            double t0 = axis_edge(&l->av, j), t1 = axis_edge(&l->av, j + 1);
            double s = 0.5 * (s0 + s1), t = 0.5 * (t0 + t1);
            float cover = 1.0f;
            if (l->shape != SHAPE_SPHERE && l->clips > 0) {
                vec3 q[2 * MAP_CLIPS + 8], c;
                int n = map_texel_polygon(l, i, j, q, 2 * MAP_CLIPS + 8);
                double whole = v3_length(v3_cross(l->du, l->dv)) * (s1 - s0) * (t1 - t0);
                double part = n >= 3 ? poly3_area(q, n, &c) : 0.0;
                cover = whole > 0 ? (float)fmin(1.0, part / whole) : 0.0f;
                if (cover > 0 && cover < 1) {
                    /* Value at the centroid of the part inside. */
                    plane_st(l, c, &s, &t);
                }
            }
            m->cover[k] = cover;
            for (int side = 0; side < l->sides; side++) {
                m->eval_st[2 * (side * cells + k)] = (float)s;
                m->eval_st[2 * (side * cells + k) + 1] = (float)t;
            }
        }
    return 1;
}

static double crossing_side(const map_crossing *c, vec3 p)
{
    return v3_dot(c->n, p) - c->d;
}

int map_separated(const part_map *m, vec3 x, vec3 y, int skip)
{
    for (int k = 0; k < m->crossings; k++) {
        const map_crossing *c = &m->cross[k];
        double sx = crossing_side(c, x), sy = crossing_side(c, y);
        if (k == skip || (sx > 0) == (sy > 0))
            continue;
        vec3 z = v3_add(x, v3_scale(v3_sub(y, x), sx / (sx - sy)));
        vec3 ab = v3_sub(c->b, c->a);
        double t = v3_dot(v3_sub(z, c->a), ab) / v3_dot(ab, ab);
        if (t >= 0.0 && t <= 1.0)
            return 1;
    }
    return 0;
}

/* Whether crossing c's segment passes through convex polygon q (n
 * corners, on the surface of normal nrm, centroid cen). */
static int segment_meets(const map_crossing *c, const vec3 *q, int n, vec3 nrm, vec3 cen)
{
    double t0 = 0.0, t1 = 1.0;
    vec3 ab = v3_sub(c->b, c->a);
    for (int k = 0; k < n && t0 < t1; k++) {
        vec3 en = v3_cross(nrm, v3_sub(q[(k + 1) % n], q[k]));
        if (v3_dot(en, v3_sub(cen, q[k])) < 0)
            en = v3_scale(en, -1);
        /* en . (a + t ab - q[k]) >= 0 */
        double al = v3_dot(en, v3_sub(c->a, q[k])), be = v3_dot(en, ab);
        if (fabs(be) < 1e-300) {
            if (al < 0)
                return 0;
        } else if (be > 0) {
            t0 = fmax(t0, -al / be);
        } else {
            t1 = fmin(t1, -al / be);
        }
    }
    return t1 - t0 > 1e-9;
}

int map_cell_split(const part_map *m, int i, int j, int su, int sv, int sub, vec3 *far)
{
    const map_layout *l = &m->layout;
    if (!m->crossings || m->cut[(size_t)j * l->nu + i] < 0)
        return 0;
    const map_crossing *x = &m->cross[m->cut[(size_t)j * l->nu + i]];
    double s0 = axis_edge(&l->au, i), s1 = axis_edge(&l->au, i + 1);
    double t0 = axis_edge(&l->av, j), t1 = axis_edge(&l->av, j + 1);
    double ds = (s1 - s0) / sub, dt = (t1 - t0) / sub;
    enum { QMAX = 2 * MAP_CLIPS + 8 };
    vec3 q[QMAX], cen;
    int n = map_rect_polygon(l, s0 + su * ds, s0 + (su + 1) * ds, t0 + sv * dt,
                             t0 + (sv + 1) * dt, q, QMAX);
    if (n < 3)
        return 0;
    double whole = poly3_area(q, n, &cen);
    if (!segment_meets(x, q, n, v3_normalize(v3_cross(l->du, l->dv)), cen))
        return 0;
    /* The part on the other side of the crossing's plane from the centre. */
    vec3 centre = map_cell_centre(l, i, j, su, sv, sub);
    double sign = crossing_side(x, centre) > 0 ? -1.0 : 1.0;
    int nf = poly3_clip(q, n, QMAX, v3_scale(x->n, sign), -sign * x->d);
    return nf >= 3 && poly3_area(q, nf, far) > 1e-4 * whole;
}

int map_build_cuts(part_map *m)
{
    const map_layout *l = &m->layout;
    size_t cells = (size_t)l->nu * l->nv;
    m->cut = malloc(cells);
    m->alt_sign = malloc(cells);
    m->alt_cover = calloc(cells, sizeof(float));
    m->alt_st = calloc(cells * 2, sizeof(float));
    m->alt = calloc((size_t)m->levels * l->sides * cells * 3, sizeof(float));
    m->alt_weight = calloc((size_t)l->sides * cells, sizeof(float));
    if (!m->cut || !m->alt_sign || !m->alt_cover || !m->alt_st || !m->alt || !m->alt_weight)
        return 0;
    vec3 nrm = v3_normalize(v3_cross(l->du, l->dv));
    enum { QMAX = 2 * MAP_CLIPS + 8 };
    for (int j = 0; j < l->nv; j++)
        for (int i = 0; i < l->nu; i++) {
            size_t k = (size_t)j * l->nu + i;
            m->cut[k] = -1;
            m->alt_sign[k] = 0;
            if (m->cover[k] <= 0)
                continue;
            vec3 q[QMAX], cen;
            int n = map_texel_polygon(l, i, j, q, QMAX);
            if (n < 3)
                continue;
            double whole = poly3_area(q, n, &cen), best = 1e-4 * whole;
            for (int c = 0; c < m->crossings; c++) {
                const map_crossing *x = &m->cross[c];
                if (!segment_meets(x, q, n, nrm, cen))
                    continue;
                vec3 hp[QMAX], hn[QMAX], cp, cn;
                for (int a = 0; a < n; a++)
                    hp[a] = hn[a] = q[a];
                int np = poly3_clip(hp, n, QMAX, x->n, -x->d);
                int nn = poly3_clip(hn, n, QMAX, v3_scale(x->n, -1), x->d);
                double ap = np >= 3 ? poly3_area(hp, np, &cp) : 0.0;
                double an = nn >= 3 ? poly3_area(hn, nn, &cn) : 0.0;
                double small = fmin(ap, an);
                if (small <= best)
                    continue;
                /* The larger half keeps the texel's value; the smaller
                 * one gets its own. */
                best = small;
                int alt_pos = ap < an;
                vec3 big = alt_pos ? cn : cp, other = alt_pos ? cp : cn;
                m->cut[k] = (signed char)c;
                m->alt_sign[k] = alt_pos ? 1 : -1;
                m->alt_cover[k] = (float)(small / (ap + an));
                double s, t;
                plane_st(l, other, &s, &t);
                m->alt_st[2 * k] = (float)s;
                m->alt_st[2 * k + 1] = (float)t;
                plane_st(l, big, &s, &t);
                for (int side = 0; side < l->sides; side++) {
                    m->eval_st[2 * (side * cells + k)] = (float)s;
                    m->eval_st[2 * (side * cells + k) + 1] = (float)t;
                }
            }
        }
    return 1;
}

static int mip_size(int n, int k)
{
    n >>= k;
    return n > 0 ? n : 1;
}

/* Bilinear read of one level and side of mip k at normalised (s, t). */
/* The two texels along one axis around texel coordinate u and the share
 * of the second.  Past the first or last centre (up to the map's edge, half
 * a texel on) the value is extrapolated linearly when `extend` is set: near
 * a seam irradiance keeps changing to the very edge, and holding it at the
 * last centre's value would be off by that change. */
static void axis_pick(double u, int n, int wrap, int extend, int *i0, int *i1, double *f)
{
    if (wrap) {
        int a = (int)floor(u);
        *f = u - a;
        *i0 = ((a % n) + n) % n;
        *i1 = (*i0 + 1) % n;
        return;
    }
    if (n < 2) {
        *i0 = *i1 = 0;
        *f = 0;
        return;
    }
    if (u < 0 || u > n - 1) {
        int low = u < 0;
        *i0 = low ? 0 : n - 2;
        *i1 = *i0 + 1;
        *f = !extend ? (low ? 0.0 : 1.0) : low ? fmax(u, -0.5) : 1.0 + fmin(u - (n - 1), 0.5);
        return;
    }
    int a = (int)floor(u);
    if (a > n - 2)
        a = n - 2;
    *i0 = a;
    *i1 = a + 1;
    *f = u - a;
}

/* Bilinear read at normalised (s, t) of the grid `base` (mip k of one
 * level and side; alt the other halves of its cut texels, or NULL).  On
 * the finest grid of a map with crossings, x (the point read) decides
 * which half of a cut texel is read, and texels a crossing separates from
 * x do not take part: the light jumps there and must not be smeared. */
static vec3 bilinear_of(const part_map *m, int k, const float *base, const float *alt_base,
                        int side, double s, double t, const vec3 *x)
{
    const map_layout *l = &m->layout;
    int nu = mip_size(l->nu, k), nv = mip_size(l->nv, k);
    const float *wt = m->weight[k] + (size_t)side * nv * nu;
    int cross = k == 0 && x && alt_base && m->crossings > 0;
    const float *alt = cross ? alt_base : NULL;
    const float *awt = cross ? m->alt_weight + (size_t)side * nv * nu : NULL;
    double u = s * nu - 0.5, v = t * nv - 0.5;
    int wrap = l->shape == SHAPE_SPHERE;
    for (int extend = 1; extend >= 0; extend--) {
        int i0, i1, j0, j1;
        double fu, fv;
        axis_pick(u, nu, wrap, extend, &i0, &i1, &fu);
        axis_pick(v, nv, 0, extend, &j0, &j1, &fv);
        size_t idx[4] = {(size_t)j0 * nu + i0, (size_t)j0 * nu + i1, (size_t)j1 * nu + i0,
                         (size_t)j1 * nu + i1};
        double w[4] = {(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv};
        const float *val[4];
        double tw[4];
        for (int q = 0; q < 4; q++) {
            val[q] = base + idx[q] * 3;
            tw[q] = wt[idx[q]];
            if (!cross)
                continue;
            int c = m->cut[idx[q]];
            if (c >= 0 && (crossing_side(&m->cross[c], *x) > 0 ? 1 : -1) == m->alt_sign[idx[q]]) {
                val[q] = alt + idx[q] * 3;
                tw[q] = awt[idx[q]];
            }
            vec3 centre, nn;
            map_texel_point(l, (int)(idx[q] % nu), (int)(idx[q] / nu), &centre, &nn);
            if (tw[q] > 0 && map_separated(m, *x, centre, c))
                tw[q] = 0;
        }
        int outside = fu < 0 || fu > 1 || fv < 0 || fv > 1;
        if (outside && (tw[0] <= 0 || tw[1] <= 0 || tw[2] <= 0 || tw[3] <= 0))
            continue; /* extrapolate only from four reachable texels */
        /* Texels off the reachable surface do not take part; the values
         * are weighted means, so they are scaled back by their weights. */
        double sw = 0;
        vec3 r = v3(0, 0, 0);
        vec3 plain = v3(0, 0, 0);
        for (int q = 0; q < 4; q++) {
            double ww = w[q] * tw[q];
            vec3 vq = v3(val[q][0], val[q][1], val[q][2]);
            r = v3_add(r, v3_scale(vq, ww));
            plain = v3_add(plain, v3_scale(vq, w[q]));
            sw += ww;
        }
        if (sw <= 1e-6 && cross) {
            /* Every neighbour lies across a crossing: the texel under x,
             * its half on x's side. */
            int ic = (int)floor(s * nu), jc = (int)floor(t * nv);
            ic = ic < 0 ? 0 : ic >= nu ? nu - 1 : ic;
            jc = jc < 0 ? 0 : jc >= nv ? nv - 1 : jc;
            size_t kc = (size_t)jc * nu + ic;
            int c = m->cut[kc];
            const float *pv = base + kc * 3;
            if (c >= 0 && (crossing_side(&m->cross[c], *x) > 0 ? 1 : -1) == m->alt_sign[kc] &&
                awt[kc] > 0)
                pv = alt + kc * 3;
            return v3(pv[0], pv[1], pv[2]);
        }
        /* Nothing reachable around: the plain bilinear value.  (Not
         * clamped at zero where extrapolated: light must add up linearly,
         * light by light.) */
        return sw > 1e-6 ? v3_scale(r, 1.0 / sw) : plain;
    }
    return v3(0, 0, 0);
}

static vec3 bilinear(const part_map *m, int k, int level, int side, double s, double t,
                     const vec3 *x)
{
    const map_layout *l = &m->layout;
    int nu = mip_size(l->nu, k), nv = mip_size(l->nv, k);
    size_t plane = ((size_t)level * l->sides + side) * (size_t)nv * nu;
    return bilinear_of(m, k, m->mip[k] + plane * 3, m->alt ? m->alt + plane * 3 : NULL, side, s,
                       t, x);
}

/* Bilinear between fine cell centres (held at the window's edge cells).
 * Where a crossing passes among the four cells, those it separates from x
 * (the point read) do not take part: the light jumps there, and the
 * cells on the far side hold what the read misses over there.  A cell the
 * crossing passes through stands for x's side by its part there. */
static vec3 fine_read(const part_map *m, const map_detail *d, double U, double V, vec3 x)
{
    int nu = d->ni * d->sub, nv = d->nj * d->sub;
    double fu = fmax(0.0, fmin(U * d->sub - 0.5, nu - 1.0));
    double fv = fmax(0.0, fmin(V * d->sub - 0.5, nv - 1.0));
    int a = (int)fu, b = (int)fv;
    int a1 = a + 1 < nu ? a + 1 : a, b1 = b + 1 < nv ? b + 1 : b;
    double fx = fu - a, fy = fv - b;
    int ca[4] = {a, a1, a, a1}, cb[4] = {b, b, b1, b1};
    double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const float *val[4];
    for (int q = 0; q < 4; q++)
        val[q] = d->e + ((size_t)cb[q] * nu + ca[q]) * 3;
    if (m->crossings > 0) {
        /* Only texels a crossing cuts can hold cells it separates. */
        const map_layout *l = &m->layout;
        int cut = 0;
        for (int q = 0; q < 4 && !cut; q++) {
            int i = d->i0 + ca[q] / d->sub, j = d->j0 + cb[q] / d->sub;
            cut = m->cut[(size_t)j * l->nu + i] >= 0;
        }
        int ix = d->i0 + (int)floor(U), jx = d->j0 + (int)floor(V);
        if (ix >= 0 && jx >= 0 && ix < l->nu && jx < l->nv)
            cut |= m->cut[(size_t)jx * l->nu + ix] >= 0;
        if (cut) {
            double sw = 0;
            for (int q = 0; q < 4; q++) {
                int i = d->i0 + ca[q] / d->sub, j = d->j0 + cb[q] / d->sub;
                vec3 c = map_cell_centre(l, i, j, ca[q] % d->sub, cb[q] % d->sub, d->sub);
                size_t cell = (size_t)cb[q] * nu + ca[q];
                if (d->split && d->split[cell]) {
                    const map_crossing *xc = &m->cross[m->cut[(size_t)j * l->nu + i]];
                    if ((crossing_side(xc, x) > 0) != (crossing_side(xc, c) > 0)) {
                        const float *f = d->far + 6 * cell;
                        c = v3(f[3], f[4], f[5]);
                        val[q] = f;
                    }
                }
                if (map_separated(m, x, c, -1))
                    w[q] = 0;
                sw += w[q];
            }
            if (sw <= 1e-9)
                return v3(0, 0, 0);
            for (int q = 0; q < 4; q++)
                w[q] /= sw;
        }
    }
    vec3 r = v3(0, 0, 0);
    for (int q = 0; q < 4; q++) {
        const float *e = val[q];
        r = v3_add(r, v3(w[q] * e[0], w[q] * e[1], w[q] * e[2]));
    }
    return r;
}

/* The caustics of a level and side at grid point (u, v) (texel units, as
 * map_coords gives them; s, t normalised). */
static vec3 detail_sum(const part_map *m, int level, int side, double u, double v, double s,
                       double t, vec3 x)
{
    vec3 e = v3(0, 0, 0);
    for (int k = 0; k < m->details; k++) {
        const map_detail *d = &m->detail[k];
        if (d->level != level || d->side != side)
            continue;
        double U = u + 0.5 - d->i0, V = v + 0.5 - d->j0;
        int inside = U >= 0 && V >= 0 && U < d->ni && V < d->nj &&
                     d->use[(size_t)(int)V * d->ni + (int)U];
        if (inside)
            e = v3_add(e, fine_read(m, d, U, V, x));
        else if (d->coarse)
            e = v3_add(e, bilinear_of(m, 0, d->coarse, NULL, side, s, t, NULL));
    }
    return e;
}

int map_refined_texel(const part_map *m, int level, int side, int i, int j)
{
    for (int k = 0; k < m->details; k++) {
        const map_detail *d = &m->detail[k];
        if (d->coarse || (level >= 0 && (d->level != level || d->side != side)))
            continue;
        int a = i - d->i0, b = j - d->j0;
        if (a >= 0 && b >= 0 && a < d->ni && b < d->nj && d->use[(size_t)b * d->ni + a])
            return 1;
    }
    return 0;
}

int map_refined_at(const part_map *m, vec3 p)
{
    if (!m->details || !m->detail_live || m->layout.shape == SHAPE_SPHERE)
        return 0;
    double u, v;
    map_coords(&m->layout, p, &u, &v);
    return map_refined_texel(m, -1, 0, (int)floor(u + 0.5), (int)floor(v + 0.5));
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
    /* The caustics kept apart, once they have left the texels (the wide
     * reads of Phase One's gathers come before that and find them there). */
    vec3 detail = m->details && m->detail_live
                      ? detail_sum(m, level, side, u, v, (u + 0.5) / l->nu, (v + 0.5) / l->nv, p)
                      : v3(0, 0, 0);
    double s = (u + 0.5) / l->nu, t = (v + 0.5) / l->nv;
    double texel = l->shape == SHAPE_SPHERE
                       ? 3.14159265358979 * l->radius / l->nv
                       : 0.5 * (l->au.w + l->av.w); /* the core's texels */
    double lod = width > texel ? log2(width / texel) : 0.0;
    if (lod > m->mips - 1)
        lod = m->mips - 1;
    int k0 = (int)lod;
    vec3 a = bilinear(m, k0, level, side, s, t, &p);
    if (k0 + 1 >= m->mips || lod == k0)
        return v3_add(a, detail);
    vec3 b = bilinear(m, k0 + 1, level, side, s, t, &p);
    double f = lod - k0;
    return v3_add(v3_add(v3_scale(a, 1 - f), v3_scale(b, f)), detail);
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

void map_free_phase_one(part_map *m)
{
    free(m->sat);
    free(m->cover);
    free(m->eval_st);
    free(m->alt_cover);
    free(m->alt_st);
    m->sat = NULL;
    m->cover = NULL;
    m->eval_st = NULL;
    m->alt_cover = NULL;
    m->alt_st = NULL;
}

void map_free(part_map *m)
{
    for (int k = 0; k < m->details; k++) {
        free(m->detail[k].use);
        free(m->detail[k].e);
        free(m->detail[k].coarse);
        free(m->detail[k].split);
        free(m->detail[k].far);
    }
    free(m->detail);
    free(m->layout.au.edge);
    free(m->layout.av.edge);
    free(m->texels);
    for (int k = 1; k < m->mips; k++)
        free(m->mip[k]);
    for (int k = 0; k < MAP_MIPS; k++)
        free(m->weight[k]);
    free(m->sat);
    free(m->cover);
    free(m->eval_st);
    free(m->cross);
    free(m->cut);
    free(m->alt_sign);
    free(m->alt);
    free(m->alt_weight);
    free(m->alt_cover);
    free(m->alt_st);
}
