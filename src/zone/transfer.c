#include "zone/transfer.h"

#include <stdlib.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "zone/lambert.h"


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
                /* The area of the texel on the surface; its light, unless
                 * its centre is unreachable (inside a closed object: what
                 * lies there is hidden, so it counts as dark area). */
                double area = (axis_edge(&l->au, i + 1) - axis_edge(&l->au, i)) *
                              (axis_edge(&l->av, j + 1) - axis_edge(&l->av, j)) *
                              m->cover[(size_t)j * l->nu + i];
                double ww = area * wt[(size_t)j * l->nu + i];
                double cell[4] = {ww * v[0], ww * v[1], ww * v[2], area};
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

/* Sums of area*weight*value and of area over texels [i0,i1) x [j0,j1). */
static vec3 sat_sum(const part_map *m, int level, int side, int i0, int j0, int i1, int j1,
                    double *area)
{
    const double *s = sat_table(m, level, side);
    int w = m->layout.nu + 1;
    const double *a = s + ((size_t)j1 * w + i1) * 4, *b = s + ((size_t)j0 * w + i1) * 4;
    const double *c = s + ((size_t)j1 * w + i0) * 4, *d = s + ((size_t)j0 * w + i0) * 4;
    *area = a[3] - b[3] - c[3] + d[3];
    return v3(a[0] - b[0] - c[0] + d[0], a[1] - b[1] - c[1] + d[1], a[2] - b[2] - c[2] + d[2]);
}

typedef struct source {
    const part_map *m;
    const part *p;
    int level, side, background;
    vec3 scale;        /* w_d * rho / pi: radiance per irradiance */
} source;

typedef struct receiver {
    zone_trace *t;
    vec3 x, n;
    vec3f origin;      /* x moved off its surface */
    double theta;
    int background;    /* the source's flag, for visibility rays */
} receiver;

#define PIECE_MAX (2 * MAP_CLIPS + 8)

/* The form factor from the receiver to the part of rectangle [s0,s1] x
 * [t0,t1] of the source's layout that exists and lies above the receiver's
 * horizon, if the receiver sees that part's centroid (else 0). */
static double seen_form_factor(const receiver *r, const map_layout *l, double s0, double t0,
                               double s1, double t1)
{
    vec3 q[PIECE_MAX];
    q[0] = map_point(l, s0, t0);
    q[1] = map_point(l, s1, t0);
    q[2] = map_point(l, s1, t1);
    q[3] = map_point(l, s0, t1);
    int n = 4;
    /* Only the surface that exists (a triangle, a plane inside its room)... */
    for (int k = 0; k < l->clips && n >= 3; k++)
        n = poly3_clip(q, n, PIECE_MAX, l->clip_n[k], l->clip_d[k]);
    /* ...above the receiver's horizon. */
    if (n >= 3)
        n = poly3_clip(q, n, PIECE_MAX, r->n, -v3_dot(r->n, r->x));
    if (n < 3)
        return 0;
    double ff = lambert_polygon(r->x, r->n, q, n);
    if (ff <= 0)
        return 0;
    vec3 c = v3(0, 0, 0);
    for (int i = 0; i < n; i++)
        c = v3_add(c, q[i]);
    c = v3_scale(c, 1.0 / n);
    vec3f target = f3((float)c.x, (float)c.y, (float)c.z);
    vec3f d = f3_sub(target, r->origin);
    float len = f3_length(d);
    r->t->rays++;
    if (len <= 0 || accel_occluded(&r->t->r->rs, r->origin, f3_scale(d, 1.0f / len),
                                   len * 0.999f, r->background))
        return 0;
    return ff;
}

static vec3 piece(const receiver *r, const source *src, int i0, int j0, int i1, int j1)
{
    const map_layout *l = &src->m->layout;
    double s0 = axis_edge(&l->au, i0), s1 = axis_edge(&l->au, i1);
    double t0 = axis_edge(&l->av, j0), t1 = axis_edge(&l->av, j1);
    vec3 a = map_point(l, s0, t0), b = map_point(l, s1, t1);
    vec3 centre = v3_scale(v3_add(a, b), 0.5);
    double size = v3_length(v3_sub(b, a));
    double dist = v3_length(v3_sub(centre, r->x));
    if (size > r->theta * dist && (i1 - i0 > 1 || j1 - j0 > 1)) {
        /* Split the longer side in two. */
        vec3 e = v3(0, 0, 0);
        if (((s1 - s0) * l->au.len >= (t1 - t0) * l->av.len && i1 - i0 > 1) || j1 - j0 < 2) {
            int im = (i0 + i1) / 2;
            e = v3_add(piece(r, src, i0, j0, im, j1), piece(r, src, im, j0, i1, j1));
        } else {
            int jm = (j0 + j1) / 2;
            e = v3_add(piece(r, src, i0, j0, i1, jm), piece(r, src, i0, jm, i1, j1));
        }
        return e;
    }
    double area;
    vec3 sum = sat_sum(src->m, src->level, src->side, i0, j0, i1, j1, &area);
    if (area <= 0 || (sum.x <= 0 && sum.y <= 0 && sum.z <= 0))
        return v3(0, 0, 0);
    vec3 radiance = v3_mul(v3_scale(sum, 1.0 / area), src->scale);
    return v3_scale(radiance, seen_form_factor(r, l, s0, t0, s1, t1));
}

vec3 transfer_irradiance(zone_trace *t, int receiver_part, vec3 x, vec3 n, int level,
                         double theta)
{
    const zone_forest *f = t->f;
    const zt_scene *sc = t->r->scene;
    receiver r = {t, x, n, f3(0, 0, 0), theta, 0};
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
        source src = {m, p, level - 1, side, o->background,
                      v3_scale(o->mat.color, o->mat.weight[LOBE_DIFFUSE] / 3.14159265358979)};
        r.background = o->background;
        e = v3_add(e, piece(&r, &src, 0, 0, m->layout.nu, m->layout.nv));
    }
    return e;
}
