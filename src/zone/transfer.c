#include "zone/transfer.h"

#include <stdlib.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "zone/lambert.h"

#define PIECE_MAX 12

static size_t sat_stride(const map_layout *l)
{
    return (size_t)(l->nu + 1) * (size_t)(l->nv + 1) * 4;
}

static double *sat_table(const part_map *m, int level, int side)
{
    const map_layout *l = &m->layout;
    return m->sat + ((size_t)level * l->sides + side) * sat_stride(l);
}

int transfer_build_tables(part_map *m, int level)
{
    const map_layout *l = &m->layout;
    if (l->shape == SHAPE_SPHERE)
        return 1;
    if (!m->sat) {
        m->sat = calloc((size_t)m->levels * l->sides * sat_stride(l), sizeof(double));
        if (!m->sat)
            return 0;
    }
    int w = l->nu + 1;
    for (int side = 0; side < l->sides; side++) {
        double *s = sat_table(m, level, side);
        const float *wt = m->weight[0] + (size_t)side * l->nv * l->nu;
        for (int j = 0; j < l->nv; j++)
            for (int i = 0; i < l->nu; i++) {
                const float *v = map_texel(m, level, side, i, j);
                double ww = wt[(size_t)j * l->nu + i];
                double cell[4] = {ww * v[0], ww * v[1], ww * v[2], ww};
                double *o = s + ((size_t)(j + 1) * w + (i + 1)) * 4;
                const double *up = s + ((size_t)j * w + (i + 1)) * 4;
                const double *left = s + ((size_t)(j + 1) * w + i) * 4;
                const double *diag = s + ((size_t)j * w + i) * 4;
                for (int c = 0; c < 4; c++)
                    o[c] = cell[c] + up[c] + left[c] - diag[c];
            }
    }
    return 1;
}

/* Sum of weight*value over texels [i0,i1) x [j0,j1). */
static vec3 sat_sum(const part_map *m, int level, int side, int i0, int j0, int i1, int j1)
{
    const double *s = sat_table(m, level, side);
    int w = m->layout.nu + 1;
    const double *a = s + ((size_t)j1 * w + i1) * 4, *b = s + ((size_t)j0 * w + i1) * 4;
    const double *c = s + ((size_t)j1 * w + i0) * 4, *d = s + ((size_t)j0 * w + i0) * 4;
    return v3(a[0] - b[0] - c[0] + d[0], a[1] - b[1] - c[1] + d[1], a[2] - b[2] - c[2] + d[2]);
}

typedef struct source {
    const part_map *m;
    const part *p;
    int level, side, is_triangle, background;
    vec3 scale;        /* w_d * rho / pi: radiance per irradiance */
} source;

typedef struct receiver {
    zone_trace *t;
    vec3 x, n;
    vec3f origin;      /* x moved off its surface */
    double theta;
} receiver;

/* Keeps the part of polygon q where a.p + b >= 0. */
static int clip3(vec3 *q, int n, vec3 a, double b)
{
    vec3 out[PIECE_MAX];
    int k = 0;
    for (int i = 0, j = n - 1; i < n; j = i++) {
        double di = v3_dot(a, q[i]) + b, dj = v3_dot(a, q[j]) + b;
        if ((dj >= 0) != (di >= 0) && k < PIECE_MAX)
            out[k++] = v3_add(q[j], v3_scale(v3_sub(q[i], q[j]), dj / (dj - di)));
        if (di >= 0 && k < PIECE_MAX)
            out[k++] = q[i];
    }
    for (int i = 0; i < k; i++)
        q[i] = out[i];
    return k;
}

static vec3 param_point(const map_layout *l, double s, double t)
{
    return v3_add(l->origin, v3_add(v3_scale(l->du, s), v3_scale(l->dv, t)));
}

static vec3 piece(const receiver *r, const source *src, int i0, int j0, int i1, int j1)
{
    const map_layout *l = &src->m->layout;
    double s0 = (double)i0 / l->nu, s1 = (double)i1 / l->nu;
    double t0 = (double)j0 / l->nv, t1 = (double)j1 / l->nv;
    vec3 q[PIECE_MAX]; /* not zeroed: this runs for every piece */
    q[0] = param_point(l, s0, t0);
    q[2] = param_point(l, s1, t1);
    vec3 centre = v3_scale(v3_add(q[0], q[2]), 0.5);
    double size = v3_length(v3_sub(q[2], q[0]));
    double dist = v3_length(v3_sub(centre, r->x));
    if (size > r->theta * dist && (i1 - i0 > 1 || j1 - j0 > 1)) {
        /* Split the longer side in two. */
        vec3 e = v3(0, 0, 0);
        if ((i1 - i0) * v3_length(l->du) / l->nu >= (j1 - j0) * v3_length(l->dv) / l->nv &&
            i1 - i0 > 1) {
            int im = (i0 + i1) / 2;
            e = v3_add(piece(r, src, i0, j0, im, j1), piece(r, src, im, j0, i1, j1));
        } else {
            int jm = (j0 + j1) / 2;
            e = v3_add(piece(r, src, i0, j0, i1, jm), piece(r, src, i0, jm, i1, j1));
        }
        return e;
    }
    q[1] = param_point(l, s1, t0);
    q[3] = param_point(l, s0, t1);
    int n = 4;
    /* A triangle's map covers the parallelogram around it: keep s + t <= 1. */
    if (src->is_triangle) {
        vec3 nrm = v3_cross(l->du, l->dv);
        /* s + t <= 1 as a plane through p1 and p2 perpendicular to the
         * surface: points p with (p - p1) . m <= 0. */
        vec3 p1 = v3_add(l->origin, l->du), p2 = v3_add(l->origin, l->dv);
        vec3 mdir = v3_cross(v3_sub(p2, p1), nrm);
        if (v3_dot(mdir, v3_sub(l->origin, p1)) > 0)
            mdir = v3_scale(mdir, -1);
        n = clip3(q, n, v3_scale(mdir, -1), v3_dot(mdir, p1));
        if (n < 3)
            return v3(0, 0, 0);
    }
    /* Above the receiver's horizon only. */
    n = clip3(q, n, r->n, -v3_dot(r->n, r->x));
    if (n < 3)
        return v3(0, 0, 0);
    vec3 sum = sat_sum(src->m, src->level, src->side, i0, j0, i1, j1);
    double cells = (double)(i1 - i0) * (j1 - j0);
    vec3 radiance = v3_mul(v3_scale(sum, 1.0 / cells), src->scale);
    if (radiance.x <= 0 && radiance.y <= 0 && radiance.z <= 0)
        return v3(0, 0, 0);
    double ff = lambert_polygon(r->x, r->n, q, n);
    if (ff <= 0)
        return v3(0, 0, 0);
    /* Visibility of the clipped piece's centroid. */
    vec3 c = v3(0, 0, 0);
    for (int i = 0; i < n; i++)
        c = v3_add(c, q[i]);
    c = v3_scale(c, 1.0 / n);
    vec3f target = f3((float)c.x, (float)c.y, (float)c.z);
    vec3f d = f3_sub(target, r->origin);
    float len = f3_length(d);
    r->t->rays++;
    if (len <= 0 || accel_occluded(&r->t->r->rs, r->origin, f3_scale(d, 1.0f / len),
                                   len * 0.999f, src->background))
        return v3(0, 0, 0);
    return v3_scale(radiance, ff);
}

vec3 transfer_irradiance(zone_trace *t, int receiver_part, vec3 x, vec3 n, int level,
                         double theta)
{
    const zone_forest *f = t->f;
    const zt_scene *sc = t->r->scene;
    receiver r = {t, x, n, f3(0, 0, 0), theta};
    r.origin = ray_offset(f3((float)x.x, (float)x.y, (float)x.z),
                          f3((float)n.x, (float)n.y, (float)n.z));
    vec3 e = v3(0, 0, 0);
    for (int i = 0; i < f->map_count; i++) {
        const part_map *m = &f->maps[i];
        const part *p = &sc->parts[i];
        if (i == receiver_part || !m->sat || p->shape == SHAPE_SPHERE || level - 1 >= m->levels)
            continue;
        const object *o = &sc->objects[p->object];
        vec3 ns = v3_normalize(v3_cross(m->layout.du, m->layout.dv));
        double side_dist = v3_dot(ns, v3_sub(x, m->layout.origin));
        int side = side_dist > 0 ? 0 : 1;
        if (side >= m->layout.sides || side_dist == 0)
            continue;
        source src = {m, p, level - 1, side, p->shape == SHAPE_TRIANGLE, o->background,
                      v3_scale(o->mat.color, o->mat.weight[LOBE_DIFFUSE] / 3.14159265358979)};
        e = v3_add(e, piece(&r, &src, 0, 0, m->layout.nu, m->layout.nv));
    }
    return e;
}
