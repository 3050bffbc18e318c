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
                size_t k = (size_t)j * l->nu + i;
                if (m->crossings && m->cut[k] >= 0) {
                    /* A cut texel: both halves, by their areas. */
                    size_t ka = (size_t)side * l->nv * l->nu + k;
                    const float *va = m->alt + ((size_t)level * l->sides * l->nv * l->nu + ka) * 3;
                    double ac = m->alt_cover[k];
                    double wa = area * ac * m->alt_weight[ka];
                    ww *= 1.0 - ac;
                    for (int c = 0; c < 3; c++)
                        cell[c] = ww * v[c] + wa * va[c];
                }
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

/* What could stand between a receiver and a piece: the box of every
 * finite part, and every plane.  A piece whose pyramid (receiver to piece)
 * meets none of them is seen whole, with no ray cast. */
#define BLOCKER_BOXES_MAX 256
#define PIECE_MAX (2 * MAP_CLIPS + 8)
/* How often a refined texel near the receiver may be halved: to an eighth,
 * past the fine cells (a quarter at quality 5). */
#define NEAR_DEPTH 3

struct transfer_blockers {
    int boxes;          /* -1: too many parts to test, cast rays */
    vec3 *lo, *hi;
    int *box_part;
    int planes;
    vec3 *pn;
    double *pd;
    int *plane_part;
    double eps;
};

transfer_blockers *transfer_blockers_build(const zt_scene *sc)
{
    transfer_blockers *b = calloc(1, sizeof *b);
    if (!b)
        return NULL;
    int n = sc->part_count;
    b->lo = malloc((size_t)(n + 1) * sizeof(vec3));
    b->hi = malloc((size_t)(n + 1) * sizeof(vec3));
    b->box_part = malloc((size_t)(n + 1) * sizeof(int));
    b->pn = malloc((size_t)(n + 1) * sizeof(vec3));
    b->pd = malloc((size_t)(n + 1) * sizeof(double));
    b->plane_part = malloc((size_t)(n + 1) * sizeof(int));
    if (!b->lo || !b->hi || !b->box_part || !b->pn || !b->pd || !b->plane_part) {
        transfer_blockers_free(b);
        return NULL;
    }
    vec3 slo, shi;
    forest_scene_bounds(sc, &slo, &shi);
    b->eps = 1e-7 * (1.0 + v3_length(v3_sub(shi, slo)));
    for (int i = 0; i < n; i++) {
        const part *p = &sc->parts[i];
        if (p->shape == SHAPE_PLANE) {
            b->pn[b->planes] = p->normal;
            b->pd[b->planes] = p->offset;
            b->plane_part[b->planes++] = i;
        } else if (p->shape == SHAPE_TRIANGLE) {
            b->lo[b->boxes] = v3_min3(v3_min3(p->p[0], p->p[1]), p->p[2]);
            b->hi[b->boxes] = v3_max3(v3_max3(p->p[0], p->p[1]), p->p[2]);
            b->box_part[b->boxes++] = i;
        } else if (p->shape == SHAPE_SPHERE) {
            vec3 r = v3(p->radius, p->radius, p->radius);
            b->lo[b->boxes] = v3_sub(p->p[0], r);
            b->hi[b->boxes] = v3_add(p->p[0], r);
            b->box_part[b->boxes++] = i;
        }
    }
    if (b->boxes > BLOCKER_BOXES_MAX)
        b->boxes = -1;
    return b;
}

void transfer_blockers_free(transfer_blockers *b)
{
    if (!b)
        return;
    free(b->lo);
    free(b->hi);
    free(b->box_part);
    free(b->pn);
    free(b->pd);
    free(b->plane_part);
    free(b);
}

/* Whether box [lo, hi] lies wholly on the negative side of plane
 * a . p + d = 0 (beyond eps). */
static int box_outside(vec3 lo, vec3 hi, vec3 a, double d, double eps)
{
    vec3 far = v3(a.x >= 0 ? hi.x : lo.x, a.y >= 0 ? hi.y : lo.y, a.z >= 0 ? hi.z : lo.z);
    return v3_dot(a, far) + d < -eps;
}

/* The faces of the pyramid from x over polygon q (n corners, centroid c)
 * as planes fa . p + fd = 0, positive inside; returns their count. */
static int pyramid_faces(vec3 x, const vec3 *q, int n, vec3 c, vec3 *fa, double *fd)
{
    int faces = 0;
    for (int k = 0; k < n; k++) {
        vec3 a = v3_cross(v3_sub(q[k], x), v3_sub(q[(k + 1) % n], x));
        double len = v3_length(a);
        if (len <= 0)
            continue;
        a = v3_scale(a, 1.0 / len);
        double d = -v3_dot(a, x);
        if (v3_dot(a, c) + d < 0) {
            a = v3_scale(a, -1);
            d = -d;
        }
        fa[faces] = a;
        fd[faces++] = d;
    }
    vec3 base = v3_cross(v3_sub(q[1], q[0]), v3_sub(q[2], q[0]));
    double blen = v3_length(base);
    if (blen > 0) {
        base = v3_scale(base, 1.0 / blen);
        double d = -v3_dot(base, q[0]);
        if (v3_dot(base, x) + d < 0) {
            base = v3_scale(base, -1);
            d = -d;
        }
        fa[faces] = base;
        fd[faces++] = d;
    }
    return faces;
}

/* Whether something may hide part of polygon q (n corners) from x: a part
 * whose box meets the pyramid from x over q, or a plane between them. */
static int maybe_blocked(const transfer_blockers *b, int receiver, int source, vec3 x,
                         const vec3 *q, int n)
{
    if (!b || b->boxes < 0)
        return 1;
    vec3 lo = x, hi = x, c = v3(0, 0, 0);
    for (int k = 0; k < n; k++) {
        lo = v3_min3(lo, q[k]);
        hi = v3_max3(hi, q[k]);
        c = v3_add(c, q[k]);
    }
    c = v3_scale(c, 1.0 / n);
    /* The pyramid's faces (each plane oriented to have the inside
     * positive), made when a box first meets the pyramid's box. */
    vec3 fa[PIECE_MAX + 1];
    double fd[PIECE_MAX + 1];
    int faces = -1;
    for (int i = 0; i < b->boxes; i++) {
        if (b->box_part[i] == receiver || b->box_part[i] == source)
            continue;
        if (!(b->lo[i].x <= hi.x && b->hi[i].x >= lo.x && b->lo[i].y <= hi.y &&
              b->hi[i].y >= lo.y && b->lo[i].z <= hi.z && b->hi[i].z >= lo.z))
            continue;
        if (faces < 0)
            faces = pyramid_faces(x, q, n, c, fa, fd);
        int out = 0;
        for (int k = 0; k < faces && !out; k++)
            out = box_outside(b->lo[i], b->hi[i], fa[k], fd[k], b->eps);
        if (!out)
            return 1;
    }
    for (int i = 0; i < b->planes; i++) {
        if (b->plane_part[i] == receiver || b->plane_part[i] == source)
            continue;
        double dx = v3_dot(b->pn[i], x) - b->pd[i];
        for (int k = 0; k < n; k++) {
            double dk = v3_dot(b->pn[i], q[k]) - b->pd[i];
            if ((dx > b->eps && dk < -b->eps) || (dx < -b->eps && dk > b->eps))
                return 1;
        }
    }
    return 0;
}

typedef struct source {
    const part_map *m;
    int index, level, side;
    int background;    /* its flag, for visibility rays */
    vec3 scale;        /* w_d * rho / pi: radiance per irradiance */
    int pierced;       /* the receiver's surface pierces it (a crossing) */
} source;

typedef struct receiver {
    zone_trace *t;
    vec3 x, n;
    vec3f origin;      /* x moved off its surface */
    double theta;
    int part;
} receiver;

/* Whether the receiver sees point c of the source (a ray short of it). */
static int sees(const receiver *r, const source *src, vec3 c)
{
    vec3f d = f3_sub(f3((float)c.x, (float)c.y, (float)c.z), r->origin);
    float len = f3_length(d);
    r->t->rays++;
    return len > 0 && !accel_occluded(&r->t->r->rs, r->origin, f3_scale(d, 1.0f / len),
                                      len * 0.999f, src->background);
}

/* Whether the receiver sees polygon q (n corners): with no ray when nothing
 * can stand in between, else by a ray to its centroid.  (Rays to its
 * corners as well, splitting pieces they disagree on, measured 1.85%
 * instead of 2.17% at level 2 for 7x the rays; a finer quality pays
 * better.) */
static int seen(const receiver *r, const source *src, const vec3 *q, int n)
{
    if (!maybe_blocked(r->t->f->blockers, r->part, src->index, r->x, q, n))
        return 1;
    vec3 c = v3(0, 0, 0);
    for (int i = 0; i < n; i++)
        c = v3_add(c, q[i]);
    return sees(r, src, v3_scale(c, 1.0 / n));
}

static vec3 piece(const receiver *r, const source *src, int i0, int j0, int i1, int j1);

/* Which crossing of map m is part q's (-1: none). */
static int crossing_of(const part_map *m, int q)
{
    for (int k = 0; k < m->crossings; k++)
        if (m->cross[k].part == q)
            return k;
    return -1;
}

/* The irradiance of texel (i, j) on the receiver's side of its own
 * surface, where that surface pierces the source: the texel's half in front
 * of the receiver when the crossing cuts it, else the texel. */
static vec3 front_half(const part_map *m, int level, int side, int i, int j, const receiver *r)
{
    const map_layout *l = &m->layout;
    size_t k = (size_t)j * l->nu + i, ka = (size_t)side * l->nv * l->nu + k;
    const float *v = map_texel(m, level, side, i, j);
    double w = m->weight[0][ka];
    int c = m->cut[k];
    if (c >= 0 && m->cross[c].part == r->part &&
        (v3_dot(m->cross[c].n, r->n) > 0 ? 1 : -1) == m->alt_sign[k]) {
        v = m->alt + ((size_t)level * l->sides * l->nv * l->nu + ka) * 3;
        w = m->alt_weight[ka];
    }
    return w > 0 ? v3(v[0], v[1], v[2]) : v3(0, 0, 0);
}

/* The piece in two halves, across its longer side. */
static vec3 split(const receiver *r, const source *src, int i0, int j0, int i1, int j1)
{
    const map_layout *l = &src->m->layout;
    double ls = (axis_edge(&l->au, i1) - axis_edge(&l->au, i0)) * l->au.len;
    double lt = (axis_edge(&l->av, j1) - axis_edge(&l->av, j0)) * l->av.len;
    if ((ls >= lt && i1 - i0 > 1) || j1 - j0 < 2) {
        int im = (i0 + i1) / 2;
        return v3_add(piece(r, src, i0, j0, im, j1), piece(r, src, im, j0, i1, j1));
    }
    int jm = (j0 + j1) / 2;
    return v3_add(piece(r, src, i0, j0, i1, jm), piece(r, src, i0, jm, i1, j1));
}

/* Polygon q (n corners) of a source cut to the surface that exists (a
 * triangle, a plane inside its room); returns its corners left (< 3:
 * nothing). */
static int clip_to_surface(const map_layout *l, vec3 *q, int n)
{
    for (int k = 0; k < l->clips && n >= 3; k++)
        n = poly3_clip(q, n, PIECE_MAX, l->clip_n[k], l->clip_d[k]);
    return n;
}

/* The form factor from the receiver of source polygon q (*n corners, fewer
 * than 3: none), cut in place to the receiver's horizon; 0 where nothing
 * is left or a ray finds the polygon hidden. */
static double seen_form_factor(const receiver *r, const source *src, vec3 *q, int *n)
{
    if (*n >= 3)
        *n = poly3_clip(q, *n, PIECE_MAX, r->n, -v3_dot(r->n, r->x));
    if (*n < 3)
        return 0;
    double ff = lambert_polygon(r->x, r->n, q, *n);
    return ff > 0 && seen(r, src, q, *n) ? ff : 0;
}

/* Rectangle [s0, s1] x [t0, t1] of a refined texel, close to the receiver:
 * split until it looks small (at most `depth` times), each part sending the
 * light read at its centroid (texels and fine cells) instead of the texel's
 * mean.  Near a crossing the light on the source changes fastest right
 * where the receiver is closest: triangletest's pixel (22, 34) at level 2
 * went from 2.8% to 0.2% with exact light at such parts. */
static vec3 near_piece(const receiver *r, const source *src, double s0, double s1, double t0,
                       double t1, int depth)
{
    const map_layout *l = &src->m->layout;
    vec3 q[PIECE_MAX];
    q[0] = map_point(l, s0, t0);
    q[2] = map_point(l, s1, t1);
    vec3 centre = v3_scale(v3_add(q[0], q[2]), 0.5);
    double size = v3_length(v3_sub(q[2], q[0]));
    if (depth > 0 && size > r->theta * v3_length(v3_sub(centre, r->x))) {
        double sm = 0.5 * (s0 + s1), tm = 0.5 * (t0 + t1);
        vec3 a = v3_add(near_piece(r, src, s0, sm, t0, tm, depth - 1),
                        near_piece(r, src, sm, s1, t0, tm, depth - 1));
        vec3 b = v3_add(near_piece(r, src, s0, sm, tm, t1, depth - 1),
                        near_piece(r, src, sm, s1, tm, t1, depth - 1));
        return v3_add(a, b);
    }
    q[1] = map_point(l, s1, t0);
    q[3] = map_point(l, s0, t1);
    int n = clip_to_surface(l, q, 4);
    double ff = seen_form_factor(r, src, q, &n);
    if (ff <= 0)
        return v3(0, 0, 0);
    vec3 c = v3(0, 0, 0);
    for (int k = 0; k < n; k++)
        c = v3_add(c, q[k]);
    vec3 e = map_lookup_wide(src->m, src->level, src->side, v3_scale(c, 1.0 / n), 0.0);
    return v3_scale(v3_mul(e, src->scale), ff);
}

static vec3 piece(const receiver *r, const source *src, int i0, int j0, int i1, int j1)
{
    const map_layout *l = &src->m->layout;
    double s0 = axis_edge(&l->au, i0), s1 = axis_edge(&l->au, i1);
    double t0 = axis_edge(&l->av, j0), t1 = axis_edge(&l->av, j1);
    vec3 q[PIECE_MAX]; /* not zeroed: this runs for every piece */
    q[0] = map_point(l, s0, t0);
    q[2] = map_point(l, s1, t1);
    vec3 centre = v3_scale(v3_add(q[0], q[2]), 0.5);
    double size = v3_length(v3_sub(q[2], q[0]));
    double dist = v3_length(v3_sub(centre, r->x));
    int splittable = i1 - i0 > 1 || j1 - j0 > 1;
    if (size > r->theta * dist && splittable)
        return split(r, src, i0, j0, i1, j1);
    if (size > r->theta * dist && src->m->detail_live &&
        map_refined_texel(src->m, src->level, src->side, i0, j0))
        return near_piece(r, src, s0, s1, t0, t1, NEAR_DEPTH);
    double area;
    vec3 sum = sat_sum(src->m, src->level, src->side, i0, j0, i1, j1, &area);
    if (area <= 0 || (sum.x <= 0 && sum.y <= 0 && sum.z <= 0))
        return v3(0, 0, 0);
    vec3 radiance = v3_mul(v3_scale(sum, 1.0 / area), src->scale);
    q[1] = map_point(l, s1, t0);
    q[3] = map_point(l, s0, t1);
    /* Only the surface that exists (a triangle, a plane inside its room)... */
    int n = clip_to_surface(l, q, 4);
    /* ...above the receiver's horizon.  Where the receiver's surface
     * pierces the source, the part of the source in front of it is lit
     * differently from the part behind: such pieces go down to texels, and
     * a texel the crossing cuts gives the light of its half in front. */
    if (n >= 3 && src->pierced) {
        int behind = 0, front = 0;
        for (int k = 0; k < n; k++) {
            double h = v3_dot(r->n, v3_sub(q[k], r->x));
            behind |= h < 0;
            front |= h > 0;
        }
        if (behind && front) {
            if (splittable)
                return split(r, src, i0, j0, i1, j1);
            radiance = v3_mul(front_half(src->m, src->level, src->side, i0, j0, r), src->scale);
        }
    }
    double ff = seen_form_factor(r, src, q, &n);
    return ff > 0 ? v3_scale(radiance, ff) : v3(0, 0, 0);
}

vec3 transfer_irradiance(zone_trace *t, int receiver_part, vec3 x, vec3 n, int level,
                         double theta)
{
    const zone_forest *f = t->f;
    const zt_scene *sc = t->r->scene;
    receiver r = {t, x, n, f3(0, 0, 0), theta, receiver_part};
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
        source src = {m, i, level - 1, side, o->background,
                      v3_scale(o->mat.color, o->mat.weight[LOBE_DIFFUSE] / 3.14159265358979),
                      crossing_of(m, receiver_part) >= 0};
        e = v3_add(e, piece(&r, &src, 0, 0, m->layout.nu, m->layout.nv));
    }
    return e;
}
