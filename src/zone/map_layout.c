/* How each part's surface is laid out on its map's grid: triangles over
 * their parallelogram, spheres by latitude and longitude, planes over the
 * room they lie in, reaching far with growing texels. */
#include "zone/map_layout.h"

#include <string.h>

#include "zone/poly2.h"

static int clampi(double v, int lo, int hi)
{
    int i = (int)ceil(v);
    return i < lo ? lo : i > hi ? hi : i;
}

/* Outside the scene's core a plane's texels grow by this factor each, and
 * its map reaches this many core extents away. */
#define OUTER_GROWTH 1.25
#define OUTER_REACH 64.0


/* Whether no light can reach the open half-space behind plane part q: q
 * is opaque and every light lies in front of it.  Culled or not makes no
 * difference here: light from the front stops at it either way, and an
 * infinite plane has no edge to pass around. */
static int walls_off(const zt_scene *sc, int q)
{
    const part *pq = &sc->parts[q];
    const object *oq = &sc->objects[pq->object];
    if (pq->shape != SHAPE_PLANE || oq->is_light ||
        oq->mat.weight[LOBE_REFRACTIVE] > 0 || (sc->sky.x > 0 || sc->sky.y > 0 || sc->sky.z > 0))
        return 0;
    for (int i = 0; i < sc->part_count; i++) {
        const part *l = &sc->parts[i];
        if (!sc->objects[l->object].is_light)
            continue;
        double eps = 1e-9 * (1.0 + fabs(pq->offset));
        switch (l->shape) {
        case SHAPE_TRIANGLE:
            for (int k = 0; k < 3; k++)
                if (v3_dot(pq->normal, l->p[k]) - pq->offset < -eps)
                    return 0;
            break;
        case SHAPE_SPHERE:
            if (v3_dot(pq->normal, l->p[0]) - pq->offset < l->radius - eps)
                return 0;
            break;
        case SHAPE_POINT:
            if (v3_dot(pq->normal, l->p[0]) - pq->offset < -eps)
                return 0;
            break;
        default: /* a light plane crosses q or lies beside it */
            return 0;
        }
    }
    return 1;
}

int map_layout_walls(const zt_scene *sc, int *walls)
{
    int count = 0;
    for (int q = 0; q < sc->part_count; q++)
        if (walls_off(sc, q))
            walls[count++] = q;
    return count;
}

/* The room planar part p lies in: the half-planes of the walls, as clips
 * of the layout (after those it has).  A background wall does not hide a
 * foreground surface behind it (it is drawn behind everything). */
static void room_clips(const zt_scene *sc, const map_walls *w, int p, vec3 pn, map_layout *l)
{
    int fore = !sc->objects[sc->parts[p].object].background;
    for (int k = 0; k < w->count && l->clips < MAP_CLIPS; k++) {
        int q = w->part[k];
        const part *pq = &sc->parts[q];
        if (q == p || (fore && sc->objects[pq->object].background))
            continue;
        if (fabs(v3_dot(pq->normal, pn)) > 1.0 - 1e-9)
            continue; /* parallel: all of p is on one side */
        l->clip_n[l->clips] = pq->normal;
        l->clip_d[l->clips] = -pq->offset;
        l->clips++;
    }
}

/* An axis over [d0, d1] with uniform texels of about `texel` over the core
 * [c0, c1] (at most max of them) and growing ones outside it; *start is
 * where its first edge lies. */
static map_axis axis_build(double d0, double d1, double c0, double c1, double texel,
                           int max, int grade, double *start)
{
    map_axis a = {0};
    a.r = OUTER_GROWTH;
    int core = (int)ceil((c1 - c0) / texel);
    core = core < 1 ? 1 : core > max ? max : core;
    a.w = (c1 - c0) / core;
    a.grade = core >= 2 ? grade : 0;
    /* Outer texels until the domain's end is covered. */
    double left = c0 - d0, right = d1 - c1;
    double k = (a.r - 1.0) / (a.w * a.r);
    int ml = left > 1e-6 * a.w ? (int)ceil(log1p(left * k) / log(a.r) - 1e-9) : 0;
    int mr = right > 1e-6 * a.w ? (int)ceil(log1p(right * k) / log(a.r) - 1e-9) : 0;
    double span_l = axis_outer_span(&a, ml), span_r = axis_outer_span(&a, mr);
    a.k0 = ml;
    a.k1 = ml + core + 2 * a.grade;
    a.n = a.k1 + mr;
    a.len = span_l + core * a.w + span_r;
    *start = c0 - span_l;
    return a;
}

static void plane_layout(const zt_scene *sc, const map_walls *w, int index, vec3 lo, vec3 hi, double texel,
                         int max_texels, int grade, map_layout *l)
{
    const part *p = &sc->parts[index];
    vec3 n = p->normal;
    vec3 a = fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0);
    vec3 u = v3_normalize(v3_cross(a, n)), v = v3_cross(n, u);
    vec3 base = v3_scale(n, p->offset);
    room_clips(sc, w, index, n, l);
    /* The mapped domain: a square reaching far around the core, clipped to
     * the room, in plane coordinates (x along u, y along v). */
    vec3 mid = v3_sub(v3_scale(v3_add(lo, hi), 0.5), base);
    double reach = OUTER_REACH * v3_length(v3_sub(hi, lo));
    poly2 dom;
    double cx = v3_dot(mid, u), cy = v3_dot(mid, v);
    dom.n = 4;
    dom.x[0] = cx - reach, dom.y[0] = cy - reach;
    dom.x[1] = cx + reach, dom.y[1] = cy - reach;
    dom.x[2] = cx + reach, dom.y[2] = cy + reach;
    dom.x[3] = cx - reach, dom.y[3] = cy + reach;
    for (int k = 0; k < l->clips; k++) /* clip_n . (base + x u + y v) + clip_d >= 0 */
        poly2_clip(&dom, v3_dot(l->clip_n[k], u), v3_dot(l->clip_n[k], v),
                   v3_dot(l->clip_n[k], base) + l->clip_d[k]);
    double dx0 = 1e300, dx1 = -1e300, dy0 = 1e300, dy1 = -1e300;
    for (int k = 0; k < dom.n; k++) {
        dx0 = fmin(dx0, dom.x[k]), dx1 = fmax(dx1, dom.x[k]);
        dy0 = fmin(dy0, dom.y[k]), dy1 = fmax(dy1, dom.y[k]);
    }
    if (dom.n < 3) /* nothing of the plane can be lit: a token map */
        dx0 = cx - texel, dx1 = cx + texel, dy0 = cy - texel, dy1 = cy + texel;
    /* The core: the scene's bounds seen on the plane, inside the domain. */
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (int k = 0; k < 8; k++) {
        vec3 c = v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        vec3 d = v3_sub(c, base);
        x0 = fmin(x0, v3_dot(d, u)), x1 = fmax(x1, v3_dot(d, u));
        y0 = fmin(y0, v3_dot(d, v)), y1 = fmax(y1, v3_dot(d, v));
    }
    x0 = fmax(x0, dx0), x1 = fmin(x1, dx1), y0 = fmax(y0, dy0), y1 = fmin(y1, dy1);
    if (x1 - x0 < 1e-3 * texel)
        x0 = dx0, x1 = fmin(dx1, dx0 + texel * max_texels);
    if (y1 - y0 < 1e-3 * texel)
        y0 = dy0, y1 = fmin(dy1, dy0 + texel * max_texels);
    double sx, sy;
    l->au = axis_build(dx0, dx1, x0, x1, texel, max_texels, grade, &sx);
    l->av = axis_build(dy0, dy1, y0, y1, texel, max_texels, grade, &sy);
    /* du x dv must point along the normal. */
    l->origin = v3_add(base, v3_add(v3_scale(u, sx), v3_scale(v, sy)));
    l->du = v3_scale(u, l->au.len);
    l->dv = v3_scale(v, l->av.len);
    l->nu = l->au.n;
    l->nv = l->av.n;
}

void map_layout_part(const zt_scene *sc, const map_walls *w, int i, vec3 lo, vec3 hi,
                     double texel, int max_texels, int grade, map_layout *l)
{
    const part *p = &sc->parts[i];
    memset(l, 0, sizeof *l);
    l->shape = p->shape;
    l->sides = sc->objects[p->object].backculled ? 1 : 2;
    if (p->shape == SHAPE_TRIANGLE) {
        l->origin = p->p[0];
        l->du = v3_sub(p->p[1], p->p[0]);
        l->dv = v3_sub(p->p[2], p->p[0]);
        l->nu = clampi(v3_length(l->du) / texel, 2, max_texels);
        l->nv = clampi(v3_length(l->dv) / texel, 2, max_texels);
        l->au = axis_uniform(l->nu, v3_length(l->du), grade);
        l->av = axis_uniform(l->nv, v3_length(l->dv), grade);
        l->nu = l->au.n;
        l->nv = l->av.n;
        /* The map covers the parallelogram around the triangle: keep
         * s + t <= 1, the side of the line p1 p2 where p0 lies. */
        vec3 nrm = v3_cross(l->du, l->dv);
        vec3 mdir = v3_cross(v3_sub(p->p[2], p->p[1]), nrm);
        if (v3_dot(mdir, v3_sub(p->p[0], p->p[1])) > 0)
            mdir = v3_scale(mdir, -1);
        l->clip_n[0] = v3_scale(mdir, -1);
        l->clip_d[0] = v3_dot(mdir, p->p[1]);
        l->clips = 1;
        room_clips(sc, w, i, v3_normalize(nrm), l);
    } else if (p->shape == SHAPE_SPHERE) {
        l->centre = p->p[0];
        l->radius = p->radius;
        l->nv = clampi(3.14159265358979 * p->radius / texel, 4, max_texels);
        l->nu = 2 * l->nv;
        l->au = axis_uniform(l->nu, 1.0, 0);
        l->av = axis_uniform(l->nv, 1.0, 0);
    } else {
        plane_layout(sc, w, i, lo, hi, texel, max_texels, grade, l);
    }
}


/* The chord of triangle t where it crosses the plane n . p = d, as its two
 * ends; 0 when t does not strictly cross the plane. */
static int chord(const vec3 *t, vec3 n, double d, double eps, vec3 *a, vec3 *b)
{
    double s[3];
    int pos = 0, neg = 0;
    for (int k = 0; k < 3; k++) {
        s[k] = v3_dot(n, t[k]) - d;
        pos += s[k] > eps;
        neg += s[k] < -eps;
    }
    if (!pos || !neg)
        return 0;
    vec3 e[2];
    int m = 0;
    for (int k = 0; k < 3 && m < 2; k++) {
        int k1 = (k + 1) % 3;
        if ((s[k] > 0) != (s[k1] > 0))
            e[m++] = v3_add(t[k], v3_scale(v3_sub(t[k1], t[k]), s[k] / (s[k] - s[k1])));
    }
    if (m < 2)
        return 0;
    *a = e[0];
    *b = e[1];
    return 1;
}

int map_layout_crossings(const zt_scene *sc, int i, map_crossing *out, int max)
{
    const part *pi = &sc->parts[i];
    if (pi->shape != SHAPE_TRIANGLE)
        return 0;
    vec3 ni = v3_normalize(v3_cross(v3_sub(pi->p[1], pi->p[0]), v3_sub(pi->p[2], pi->p[0])));
    double di = v3_dot(ni, pi->p[0]);
    int count = 0;
    for (int j = 0; j < sc->part_count && count < max; j++) {
        const part *pj = &sc->parts[j];
        if (j == i || pj->shape != SHAPE_TRIANGLE)
            continue;
        vec3 nj = v3_normalize(v3_cross(v3_sub(pj->p[1], pj->p[0]), v3_sub(pj->p[2], pj->p[0])));
        double dj = v3_dot(nj, pj->p[0]);
        double size = 0;
        for (int k = 0; k < 3; k++)
            size = fmax(size, fmax(v3_length(v3_sub(pi->p[k], pi->p[(k + 1) % 3])),
                                   v3_length(v3_sub(pj->p[k], pj->p[(k + 1) % 3]))));
        double eps = 1e-7 * size;
        vec3 a, b, c, e;
        /* Each must cross the other's plane (touching is not piercing: a
         * block standing on a floor does not cut it). */
        if (!chord(pi->p, nj, dj, eps, &a, &b) || !chord(pj->p, ni, di, eps, &c, &e))
            continue;
        /* Both chords lie on the planes' common line: keep their overlap. */
        vec3 dir = v3_sub(b, a);
        double len2 = v3_dot(dir, dir);
        if (len2 <= eps * eps)
            continue;
        double tc = v3_dot(v3_sub(c, a), dir) / len2, te = v3_dot(v3_sub(e, a), dir) / len2;
        double t0 = fmax(0.0, fmin(tc, te)), t1 = fmin(1.0, fmax(tc, te));
        if (t1 - t0 <= 1e-9)
            continue;
        map_crossing *x = &out[count++];
        x->n = nj;
        x->d = dj;
        x->a = v3_add(a, v3_scale(dir, t0));
        x->b = v3_add(a, v3_scale(dir, t1));
        x->part = j;
    }
    return count;
}
