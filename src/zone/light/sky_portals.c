/* Window panes as portals for the sky's light (sky_portals.h). */
#include "zone/light/sky_portals.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/ray_offset.h"
#include "geom/transmittance.h"
#include "render/prim.h"
#include "util/sampler.h"
#include "util/vec3_convert.h"

#define PI 3.14159265358979323846
/* Pane triangles whose normals are this close (|cos|) lie in one window
 * (and so must the first triangles of the sets they join). */
#define PARALLEL 0.98
/* Two windows' rectangles within this share of the smaller one's size (in
 * their plane and across it) are one portal: the sheets of a double
 * glazing, the lights of a window between its bars. */
#define NEAR_SHARE 0.1
/* Portals with less sky than this behind them are left to the gather. */
#define OPEN_MIN 0.02
/* Rays from a portal's surface into each side that measure its sky. */
#define OPEN_POINTS 3
#define OPEN_DIRS 16
/* Merging windows pairwise is quadratic: above this many, each stays its
 * own portal. */
#define MERGE_MAX 4096
/* Triangles of a window whose edges are tried as its rectangle's side. */
#define EDGE_TRIES 16
/* Below this solid angle a portal is sampled evenly in area. */
#define SMALL_OMEGA 1e-6

typedef struct pane_corner {
    float x, y, z;
    int tri;
} pane_corner;

static int corner_cmp(const void *a, const void *b)
{
    const pane_corner *p = a, *q = b;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    if (p->y != q->y)
        return p->y < q->y ? -1 : 1;
    if (p->z != q->z)
        return p->z < q->z ? -1 : 1;
    return p->tri - q->tri;
}

static int find(int *up, int i)
{
    while (up[i] != i)
        i = up[i] = up[up[i]];
    return i;
}

/* A window while the portals are found: its plane, its extent in the
 * plane's frame and the spread of its panes across it. */
typedef struct window {
    vec3 n, t, b;
    double umin, umax, vmin, vmax;
    double area, wmin, wmax;
    int alive;
} window;

static void window_add(window *w, vec3 p)
{
    double u = v3_dot(p, w->t), v = v3_dot(p, w->b), h = v3_dot(p, w->n);
    w->umin = fmin(w->umin, u);
    w->umax = fmax(w->umax, u);
    w->vmin = fmin(w->vmin, v);
    w->vmax = fmax(w->vmax, v);
    w->wmin = fmin(w->wmin, h);
    w->wmax = fmax(w->wmax, h);
}

static void window_reset(window *w)
{
    w->umin = w->vmin = w->wmin = 1e300;
    w->umax = w->vmax = w->wmax = -1e300;
}

static void window_add_triangle(window *w, const rscene *rs, int prim)
{
    rs_part tmp;
    const rs_part *p = rs_prim(rs, prim, &tmp);
    vec3 p0 = f3_to_v3(p->p0);
    window_add(w, p0);
    window_add(w, v3_add(p0, f3_to_v3(p->e1)));
    window_add(w, v3_add(p0, f3_to_v3(p->e2)));
}

static double window_size(const window *w)
{
    return fmax(w->umax - w->umin, w->vmax - w->vmin);
}

/* The point (u, v) of the window's plane frame at height h across it. */
static vec3 window_point(const window *w, double u, double v, double h)
{
    return v3_add(v3_add(v3_scale(w->t, u), v3_scale(w->b, v)), v3_scale(w->n, h));
}

/* Corner k (0..7) of the window's box: its rectangle at either side of
 * its panes' spread across it. */
static vec3 window_corner(const window *w, int k)
{
    return window_point(w, k & 1 ? w->umax : w->umin, k & 2 ? w->vmax : w->vmin,
                        k & 4 ? w->wmax : w->wmin);
}

/* Whether b fits a: b's corners lie near a's plane and near its rectangle
 * in that plane, within NEAR_SHARE of the smaller one's size (so that
 * merged windows do not reach ever further).  A pane's thin edges fit its
 * face, and so do a double glazing's sheets. */
static int window_fits(const window *a, const window *b)
{
    double tol = NEAR_SHARE * fmin(window_size(a), window_size(b));
    window c = *a;
    window_reset(&c);
    for (int k = 0; k < 8; k++)
        window_add(&c, window_corner(b, k));
    return c.wmin > a->wmin - tol && c.wmax < a->wmax + tol && c.umin < a->umax + tol &&
           c.umax > a->umin - tol && c.vmin < a->vmax + tol && c.vmax > a->vmin - tol;
}

static void window_absorb(window *a, window *b)
{
    for (int k = 0; k < 8; k++)
        window_add(a, window_corner(b, k));
    a->area += b->area;
    b->alive = 0;
}

/* The share of directions into side s (+1: along n) from points of the
 * portal that reach the sky. */
static float portal_open(const rscene *rs, const sky_portal *p, double s)
{
    vec3 nn = v3_scale(p->n, s), t, b;
    v3_frame(nn, &t, &b);
    double seen = 0;
    int cast = 0;
    for (int i = 0; i < OPEN_POINTS; i++)
        for (int j = 0; j < OPEN_POINTS; j++) {
            vec3 x = v3_add(p->corner, v3_add(v3_scale(p->eu, (i + 0.5) / OPEN_POINTS),
                                              v3_scale(p->ev, (j + 0.5) / OPEN_POINTS)));
            vec3f o = ray_offset(v3_to_f3(x), v3_to_f3(nn));
            for (int k = 0; k < OPEN_DIRS; k++) {
                double u1 = (k + 0.5) / OPEN_DIRS;
                double u2 = sampler_reverse_bits((uint32_t)(k + OPEN_DIRS * (i * OPEN_POINTS + j))) *
                            (1.0 / 4294967296.0);
                double r = sqrt(u1), phi = 2 * PI * u2;
                vec3 d = v3_add(v3_add(v3_scale(t, r * cos(phi)), v3_scale(b, r * sin(phi))),
                                v3_scale(nn, sqrt(1 - u1)));
                seen += accel_transmittance_mean(rs, o, v3_to_f3(d), 3.4e38f, 1);
                cast++;
            }
        }
    return (float)(seen / cast);
}

int sky_portals_build(sky_portals *sp, const rscene *rs)
{
    memset(sp, 0, sizeof *sp);
    int any = 0;
    for (int i = 0; i < rs->object_count; i++)
        any |= rs->objects[i].thin && !rs->objects[i].is_light;
    if (!any)
        return 1;
    /* The pane triangles, and their corners for finding the ones that
     * touch. */
    int n = 0;
    int *tri = NULL;
    pane_corner *c = NULL;
    int *up = NULL, *live = NULL;
    vec3f *nrm = NULL;
    window *w = NULL;
    int cap = 0, ok = 0;
    for (int q = 0; q < rs->prim_count; q++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, q, &tmp);
        const rs_object *m = &rs->objects[p->object];
        /* What accel_transmittance_panes reports as a pane. */
        if (p->shape != SHAPE_TRIANGLE || !m->thin || p->is_light || m->is_light || p->area <= 0)
            continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            int *g = realloc(tri, (size_t)cap * sizeof *g);
            if (!g)
                goto done;
            tri = g;
        }
        tri[n++] = q;
    }
    if (!n) {
        ok = 1;
        goto done;
    }
    c = malloc((size_t)n * 3 * sizeof *c);
    up = malloc((size_t)n * sizeof *up);
    w = calloc((size_t)n, sizeof *w);
    live = malloc((size_t)n * sizeof *live);
    nrm = malloc((size_t)n * sizeof *nrm);
    sp->of_prim = malloc((size_t)rs->prim_count * sizeof *sp->of_prim);
    sp->prim_count = rs->prim_count;
    if (!c || !up || !w || !live || !nrm || !sp->of_prim)
        goto done;
    for (int i = 0; i < n; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, tri[i], &tmp);
        vec3f v[3] = {p->p0, f3_add(p->p0, p->e1), f3_add(p->p0, p->e2)};
        for (int k = 0; k < 3; k++)
            c[3 * i + k] = (pane_corner){v[k].x, v[k].y, v[k].z, i};
        nrm[i] = p->n;
        up[i] = i;
    }
    /* Triangles that share a corner join when they are parallel, and so
     * are the sets they belong to (their first triangles): a curved pane
     * of small facets does not become one flat window. */
    qsort(c, (size_t)n * 3, sizeof *c, corner_cmp);
    for (int lo = 0, hi; lo < 3 * n; lo = hi) {
        for (hi = lo + 1; hi < 3 * n && c[hi].x == c[lo].x && c[hi].y == c[lo].y &&
                          c[hi].z == c[lo].z;
             hi++)
            ;
        for (int i = lo; i < hi; i++)
            for (int j = i + 1; j < hi; j++) {
                int a = c[i].tri, b = c[j].tri, ra = find(up, a), rb = find(up, b);
                if (ra != rb && fabsf(f3_dot(nrm[a], nrm[b])) >= PARALLEL &&
                    fabsf(f3_dot(nrm[ra], nrm[rb])) >= PARALLEL)
                    up[rb] = ra;
            }
    }
    /* A window per set of touching triangles: its first triangle's
     * normal, and the smallest rectangle around its corners whose side
     * lies along one of its triangles' edges (the first EDGE_TRIES
     * triangles'); a window's glass is a rectangle, and a rectangle on the
     * slant of a diagonal would be twice the glass. */
    int *order = malloc((size_t)n * sizeof *order);
    int *start = malloc((size_t)(n + 1) * sizeof *start);
    int *fill = malloc((size_t)n * sizeof *fill);
    if (!order || !start || !fill) {
        free(order);
        free(start);
        free(fill);
        goto done;
    }
    for (int i = 0; i <= n; i++)
        start[i] = 0;
    for (int i = 0; i < n; i++)
        start[find(up, i) + 1]++;
    for (int i = 0; i < n; i++)
        start[i + 1] += start[i];
    for (int i = 0; i < n; i++)
        fill[i] = start[i];
    for (int i = 0; i < n; i++)
        order[fill[find(up, i)]++] = i;
    for (int r = 0; r < n; r++) {
        int a = start[r], b = start[r + 1];
        if (a == b)
            continue;
        window *wr = &w[r];
        wr->n = v3_normalize(f3_to_v3(nrm[r]));
        double best = -1;
        vec3 best_t = v3(0, 0, 0);
        for (int k = a; k < b && k < a + EDGE_TRIES; k++) {
            rs_part tk;
            const rs_part *p = rs_prim(rs, tri[order[k]], &tk);
            vec3 e[3] = {f3_to_v3(p->e1), f3_to_v3(p->e2), f3_to_v3(f3_sub(p->e2, p->e1))};
            for (int m = 0; m < 3; m++) {
                vec3 t = v3_sub(e[m], v3_scale(wr->n, v3_dot(e[m], wr->n)));
                double len = v3_length(t);
                if (!(len > 0))
                    continue;
                window trial = {.n = wr->n, .t = v3_scale(t, 1 / len)};
                trial.b = v3_cross(trial.n, trial.t);
                window_reset(&trial);
                for (int q = a; q < b; q++)
                    window_add_triangle(&trial, rs, tri[order[q]]);
                double area = (trial.umax - trial.umin) * (trial.vmax - trial.vmin);
                if (best < 0 || area < best) {
                    best = area;
                    best_t = trial.t;
                }
            }
        }
        if (best < 0)
            v3_frame(wr->n, &best_t, &wr->b);
        wr->t = best_t;
        wr->b = v3_cross(wr->n, wr->t);
        window_reset(wr);
        for (int q = a; q < b; q++) {
            rs_part tq;
            window_add_triangle(wr, rs, tri[order[q]]);
            wr->area += rs_prim(rs, tri[order[q]], &tq)->area;
        }
        wr->alive = 1;
    }
    free(start);
    free(fill);
    free(order);
    int windows = 0;
    for (int i = 0; i < n; i++)
        if (w[i].alive)
            live[windows++] = i;
    /* Windows that fit one another become one (the one fitted into leads
     * to the other's root through up[]). */
    if (windows <= MERGE_MAX) {
        for (int changed = 1; changed;) {
            changed = 0;
            for (int a = 0; a < windows; a++)
                for (int b = a + 1; b < windows && w[live[a]].alive; b++) {
                    int i = live[a], j = live[b];
                    if (!w[j].alive)
                        continue;
                    if (window_fits(&w[i], &w[j])) {
                        window_absorb(&w[i], &w[j]);
                        up[j] = i;
                        changed = 1;
                    } else if (window_fits(&w[j], &w[i])) {
                        window_absorb(&w[j], &w[i]);
                        up[i] = j;
                        changed = 1;
                    }
                }
        }
    }
    sp->p = malloc((size_t)n * sizeof *sp->p);
    if (!sp->p)
        goto done;
    int *portal_of = malloc((size_t)n * sizeof *portal_of);
    if (!portal_of)
        goto done;
    for (int i = 0; i < n; i++) {
        portal_of[i] = -1;
        if (!w[i].alive)
            continue;
        window *wi = &w[i];
        sky_portal *p = &sp->p[sp->count];
        p->corner = window_point(wi, wi->umin, wi->vmin, 0.5 * (wi->wmin + wi->wmax));
        p->eu = v3_scale(wi->t, wi->umax - wi->umin);
        p->ev = v3_scale(wi->b, wi->vmax - wi->vmin);
        p->n = wi->n;
        p->half = 0.5 * (wi->wmax - wi->wmin);
        p->area = (wi->umax - wi->umin) * (wi->vmax - wi->vmin);
        p->open[0] = portal_open(rs, p, 1.0);
        p->open[1] = portal_open(rs, p, -1.0);
        portal_of[i] = sp->count++;
    }
    for (int q = 0; q < rs->prim_count; q++)
        sp->of_prim[q] = -1;
    /* A triangle's portal: its window's, or that of the window its window
     * was merged into (up[] leads there). */
    for (int i = 0; i < n; i++) {
        int r = i;
        while (portal_of[r] < 0 && up[r] != r)
            r = up[r];
        sp->of_prim[tri[i]] = portal_of[r];
    }
    free(portal_of);
    sky_portal *fit = realloc(sp->p, (size_t)(sp->count > 0 ? sp->count : 1) * sizeof *sp->p);
    if (fit)
        sp->p = fit;
    ok = 1;
done:
    free(tri);
    free(c);
    free(up);
    free(live);
    free(nrm);
    free(w);
    if (!ok)
        sky_portals_free(sp);
    return ok;
}

void sky_portals_free(sky_portals *sp)
{
    free(sp->p);
    free(sp->of_prim);
    memset(sp, 0, sizeof *sp);
}

/* Clamping without fmin/fmax's NaN rules (which cost a call). */
static inline double clamp(double v, double lo, double hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

int sky_portal_view_make(const sky_portal *p, vec3 x, sky_portal_view *v)
{
    double lu = v3_length(p->eu), lv = v3_length(p->ev);
    v->ex = v3_scale(p->eu, 1 / lu);
    v->ey = v3_scale(p->ev, 1 / lv);
    v->ez = p->n;
    vec3 d = v3_sub(p->corner, x);
    double x0 = v3_dot(d, v->ex), y0 = v3_dot(d, v->ey), z0 = v3_dot(d, v->ez);
    if (z0 > 0) {
        v->ez = v3_scale(v->ez, -1);
        z0 = -z0;
    }
    /* The rectangle on the panes' side toward x: a direction's first pane
     * lies there. */
    z0 += p->half;
    if (!(z0 < 0))
        return 0;
    double x1 = x0 + lu, y1 = y0 + lv;
    /* The spherical rectangle: its edges' planes' normals and inner
     * angles (Urena et al. 2013). */
    vec3 v00 = v3(x0, y0, z0), v01 = v3(x0, y1, z0), v10 = v3(x1, y0, z0), v11 = v3(x1, y1, z0);
    vec3 n0 = v3_normalize(v3_cross(v00, v10)), n1 = v3_normalize(v3_cross(v10, v11));
    vec3 n2 = v3_normalize(v3_cross(v11, v01)), n3 = v3_normalize(v3_cross(v01, v00));
    double g0 = acos(clamp(-v3_dot(n0, n1), -1.0, 1.0));
    double g1 = acos(clamp(-v3_dot(n1, n2), -1.0, 1.0));
    double g2 = acos(clamp(-v3_dot(n2, n3), -1.0, 1.0));
    double g3 = acos(clamp(-v3_dot(n3, n0), -1.0, 1.0));
    v->x0 = x0;
    v->y0 = y0;
    v->z0 = z0;
    v->x1 = x1;
    v->y1 = y1;
    v->b0 = n0.z;
    v->b1 = n2.z;
    v->g23 = g2 + g3;
    v->area = p->area;
    v->omega = g0 + g1 + g2 + g3 - 2 * PI;
    v->by_area = v->omega < SMALL_OMEGA;
    if (v->by_area) {
        /* Far and small: the formula loses its digits; the rectangle's
         * area over the distance squared instead. */
        vec3 c = v3(x0 + 0.5 * lu, y0 + 0.5 * lv, z0);
        double r2 = v3_dot(c, c);
        v->omega = p->area * -z0 / (r2 * sqrt(r2));
    }
    return v->omega > 0;
}

double sky_portal_view_direction(const sky_portal_view *v, int j, int count, vec3 *dir)
{
    /* A stratified point of the unit square (Hammersley, shifted by half
     * a stratum in both: no point on the rectangle's rim, which the
     * window's frame would hide). */
    double u = (j + 0.5) / count;
    double w = sampler_reverse_bits((uint32_t)j) * (1.0 / 4294967296.0) + 0.5 / count;
    w -= floor(w);
    vec3 local;
    double share;
    if (v->by_area) {
        /* Even in area, weighed by its solid angle there. */
        local = v3(v->x0 + u * (v->x1 - v->x0), v->y0 + w * (v->y1 - v->y0), v->z0);
        double r2 = v3_dot(local, local);
        share = v->area * -v->z0 / (r2 * sqrt(r2)) / count;
    } else {
        /* u picks the slice of the solid angle, w the point along it. */
        double au = u * v->omega - v->g23;
        double fu = (cos(au) * v->b0 - v->b1) / sin(au);
        double cu = copysign(1 / sqrt(fu * fu + v->b0 * v->b0), fu);
        cu = clamp(cu, -1 + 1e-12, 1 - 1e-12);
        double z0 = v->z0;
        double xu = clamp(-cu * z0 / sqrt(1 - cu * cu), v->x0, v->x1);
        double dd2 = xu * xu + z0 * z0, dd = sqrt(dd2);
        double h0 = v->y0 / sqrt(dd2 + v->y0 * v->y0), h1 = v->y1 / sqrt(dd2 + v->y1 * v->y1);
        double hv = h0 + w * (h1 - h0);
        double yv = hv * hv < 1 - 1e-12 ? hv * dd / sqrt(1 - hv * hv) : v->y1;
        local = v3(xu, yv, z0);
        share = v->omega / count;
    }
    vec3 d = v3_add(v3_add(v3_scale(v->ex, local.x), v3_scale(v->ey, local.y)),
                    v3_scale(v->ez, local.z));
    *dir = v3_normalize(d);
    return share;
}

int sky_portals_pick(const sky_portals *sp, vec3 x, vec3 n, int budget, sky_portal_pick *picks)
{
    if (budget > SKY_PORTAL_BUDGET_MAX)
        budget = SKY_PORTAL_BUDGET_MAX;
    double weight[SKY_PORTAL_PICKS_MAX], total = 0;
    int count = 0;
    for (int g = 0; g < sp->count; g++) {
        const sky_portal *p = &sp->p[g];
        double side = v3_dot(v3_sub(x, p->corner), p->n);
        /* Looking through from the n side leads into the other one. */
        float open = p->open[side > 0 ? 1 : 0];
        if (open < OPEN_MIN || side == 0)
            continue;
        /* Some of it above x's horizon. */
        vec3 c = v3_sub(p->corner, x);
        double h0 = v3_dot(c, n), hu = v3_dot(p->eu, n), hv = v3_dot(p->ev, n);
        if (h0 <= 0 && h0 + hu <= 0 && h0 + hv <= 0 && h0 + hu + hv <= 0)
            continue;
        /* The solid angle roughly (the weights only share the budget out):
         * the area at the centre's distance and slant, at most a
         * hemisphere; the cosine there, at least a tenth. */
        vec3 mid = v3_add(c, v3_scale(v3_add(p->eu, p->ev), 0.5));
        double r2 = v3_dot(mid, mid), r = sqrt(r2);
        double omega = p->area * fabs(v3_dot(mid, p->n)) / (r2 * r);
        double cos_mid = v3_dot(mid, n) / r;
        double wgt = (omega < 2 * PI ? omega : 2 * PI) * (cos_mid > 0.1 ? cos_mid : 0.1) * open;
        if (!(wgt > 0))
            continue;
        /* Keep the largest: a full list drops its smallest. */
        int at = count;
        if (count == SKY_PORTAL_PICKS_MAX) {
            at = 0;
            for (int i = 1; i < count; i++)
                if (weight[i] < weight[at])
                    at = i;
            if (weight[at] >= wgt)
                continue;
            total -= weight[at];
        } else {
            count++;
        }
        picks[at].portal = g;
        weight[at] = wgt;
        total += wgt;
    }
    /* Directions in proportion, each at least one; those below half a
     * direction are left to the gather. */
    int kept = 0;
    for (int i = 0; i < count; i++) {
        int m = (int)(budget * weight[i] / total + 0.5);
        if (m < 1 || !sky_portal_view_make(&sp->p[picks[i].portal], x, &picks[kept].view))
            continue;
        picks[kept].portal = picks[i].portal;
        picks[kept++].count = m;
    }
    return kept;
}
