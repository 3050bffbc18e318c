#include "zone/light/direct.h"

#include <pthread.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/transmittance.h"
#include "render/prim.h"
#include "geom/ray_offset.h"
#include "util/vec3_convert.h"
#include "zone/light/lambert.h"
#include "zone/light/poly2.h"
#include "zone/light/zprim.h"

#define MAX_PIECES 192
#define POLY3_MAX 48

/* The plane the light's polygon lies on, with a 2D frame. */
typedef struct light_frame {
    vec3 origin, u, v, n;
    double hx;     /* signed height of the shaded point above the plane */
} light_frame;

typedef struct poly3 {
    int n;
    vec3 p[POLY3_MAX];
} poly3;

static double height(const light_frame *f, vec3 p)
{
    return v3_dot(f->n, v3_sub(p, f->origin));
}

/* Keeps the part of a 3D polygon where a.p + b >= 0. */
static void poly3_clip(poly3 *poly, vec3 a, double b)
{
    poly3 out;
    out.n = 0;
    if (poly->n == 0)
        return;
    int j = poly->n - 1;
    double dj = v3_dot(a, poly->p[j]) + b;
    for (int i = 0; i < poly->n; i++) {
        double di = v3_dot(a, poly->p[i]) + b;
        if ((dj >= 0) != (di >= 0) && out.n < POLY3_MAX) {
            double t = dj / (dj - di);
            out.p[out.n++] = v3_add(poly->p[j], v3_scale(v3_sub(poly->p[i], poly->p[j]), t));
        }
        if (di >= 0 && out.n < POLY3_MAX)
            out.p[out.n++] = poly->p[i];
        j = i;
        dj = di;
    }
    *poly = out;
}

/* Orthonormal u, v around unit n. */
static void basis(vec3 n, vec3 *u, vec3 *v)
{
    vec3 a = fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0);
    *u = v3_normalize(v3_cross(a, n));
    *v = v3_cross(n, *u);
}

/* Projects the occluding polygon from x onto the light plane and cuts it
 * out of the pieces.  beyond: parts past the light plane block too (a
 * background light behind foreground objects). */
static void cut_shadow(const light_frame *f, vec3 x, poly3 *occ, int beyond,
                       poly2_set *set, poly2 *scratch)
{
    double s = f->hx > 0 ? 1.0 : -1.0, hx = fabs(f->hx);
    /* Keep what is nearer the plane than x (s*h < hx) and, unless beyond,
     * on x's side of it (s*h > 0). */
    poly3_clip(occ, v3_scale(f->n, -s), s * v3_dot(f->n, f->origin) + hx * (1.0 - 1e-9));
    if (!beyond)
        poly3_clip(occ, v3_scale(f->n, s), -s * v3_dot(f->n, f->origin) - hx * 1e-9);
    if (occ->n < 3)
        return;
    poly2 hole;
    hole.n = 0;
    for (int i = 0; i < occ->n && hole.n < POLY2_MAX; i++) {
        double h = height(f, occ->p[i]);
        double t = f->hx / (f->hx - h);
        vec3 q = v3_add(x, v3_scale(v3_sub(occ->p[i], x), t));
        vec3 d = v3_sub(q, f->origin);
        hole.x[hole.n] = v3_dot(d, f->u);
        hole.y[hole.n] = v3_dot(d, f->v);
        hole.n++;
    }
    if (fabs(poly2_area(&hole)) <= 0.0)
        return;
    poly2_make_ccw(&hole);
    poly2_set_subtract(set, &hole, scratch);
}

/* A disk (centre c, unit normal w, radius r) as a polygon of equal area. */
/* The cosines and sines of a regular polygon's corners, i x 2 pi / n for
 * n up to POLY3_MAX (and the factor that gives it a disk's area), made
 * once: spheres' shadows take them at every sample, where sin and cos
 * cost a seventh of Phase Two on a Cornell box with balls. */
typedef struct ring {
    double cs[POLY3_MAX][2];
    double area; /* sqrt(step / sin(step)) */
} ring;
static ring rings[POLY3_MAX + 1], circles[POLY3_MAX + 1];
static pthread_once_t rings_once = PTHREAD_ONCE_INIT;

static void rings_make(void)
{
    for (int n = 1; n <= POLY3_MAX; n++) {
        double step = 2.0 * 3.14159265358979323846 / n;
        rings[n].area = sqrt(step / sin(step));
        for (int i = 0; i < n; i++) {
            rings[n].cs[i][0] = cos(i * step);
            rings[n].cs[i][1] = sin(i * step);
            double a = 2.0 * 3.14159265358979323846 * i / n; /* circle_points' */
            circles[n].cs[i][0] = cos(a);
            circles[n].cs[i][1] = sin(a);
        }
    }
}

static void disk_polygon(vec3 c, vec3 w, double r, int sides, poly3 *out)
{
    vec3 u, v;
    basis(w, &u, &v);
    if (sides > POLY3_MAX)
        sides = POLY3_MAX;
    pthread_once(&rings_once, rings_make);
    const ring *g = &rings[sides];
    double re = r * g->area; /* same area as the disk */
    out->n = sides;
    for (int i = 0; i < sides; i++)
        out->p[i] = v3_add(c, v3_add(v3_scale(u, re * g->cs[i][0]), v3_scale(v, re * g->cs[i][1])));
}

/* The silhouette of a sphere seen from x: the circle where the tangent cone
 * touches it.  Returns 0 when x is inside. */
static int sphere_silhouette(vec3 centre, double r, vec3 x, vec3 *c, vec3 *w,
                             double *rs)
{
    vec3 d = v3_sub(centre, x);
    double dist = v3_length(d);
    if (dist <= r)
        return 0;
    *w = v3_scale(d, 1.0 / dist);
    *c = v3_sub(centre, v3_scale(*w, r * r / dist));
    *rs = r * sqrt(1.0 - (r * r) / (dist * dist));
    return 1;
}

/* Points of the circle where plane (pn . p = po) meets the sphere. */
static int circle_points(vec3 centre, double r, vec3 pn, double po, int k, vec3 *out)
{
    double d = v3_dot(pn, centre) - po;
    if (fabs(d) >= r)
        return 0;
    vec3 c = v3_sub(centre, v3_scale(pn, d)), u, v;
    double rr = sqrt(r * r - d * d);
    basis(pn, &u, &v);
    pthread_once(&rings_once, rings_make);
    const ring *g = &circles[k];
    for (int i = 0; i < k; i++)
        out[i] = v3_add(c, v3_add(v3_scale(u, rr * g->cs[i][0]), v3_scale(v, rr * g->cs[i][1])));
    return k;
}

/* The shadow of a sphere that crosses the light's plane or the level of
 * x: the projection of the convex part of the sphere between them, whose
 * outline comes from the silhouette (where it lies between), the circle on
 * the light's plane, and the circle at x's level (just inside it). */
static void sphere_cut(const direct_ctx *c, const light_frame *f, vec3 x, const zprim *o,
                       vec3 sc, vec3 sw, double sr, poly2_set *set, poly2 *scratch)
{
    enum { K = 24 };
    vec3 pts[POLY3_MAX + 2 * K];
    int n = 0;
    double s = f->hx > 0 ? 1.0 : -1.0, hx = fabs(f->hx);
    poly3 sil;
    disk_polygon(sc, sw, sr, K < c->sides ? c->sides : K, &sil);
    for (int i = 0; i < sil.n; i++) {
        double h = s * height(f, sil.p[i]);
        if (h > 0 && h < hx)
            pts[n++] = sil.p[i];
    }
    double po = v3_dot(f->n, f->origin);
    n += circle_points(o->p[0], o->radius, f->n, po, K, pts + n);
    n += circle_points(o->p[0], o->radius, f->n, po + s * hx * (1.0 - 1e-3), K, pts + n);
    if (n < 3)
        return;
    double xs[POLY3_MAX + 2 * K], ys[POLY3_MAX + 2 * K];
    for (int i = 0; i < n; i++) {
        double h = height(f, pts[i]);
        double t = f->hx / (f->hx - h);
        vec3 q = v3_add(x, v3_scale(v3_sub(pts[i], x), t));
        vec3 d = v3_sub(q, f->origin);
        xs[i] = v3_dot(d, f->u);
        ys[i] = v3_dot(d, f->v);
    }
    poly2 hole;
    poly2_hull(xs, ys, n, &hole);
    if (hole.n >= 3)
        poly2_set_subtract(set, &hole, scratch);
}

/* Cuts the shadow of part `o` (seen from x) out of the light's pieces.
 * Returns 1 when x is wholly enclosed (inside an opaque sphere). */
/* The pyramid from x through the light's polygon: a triangle wholly
 * outside one of its side planes casts no shadow on the light. */
#define FRUSTUM_MAX 16
typedef struct frustum {
    int n;                   /* 0: no test */
    vec3 normal[FRUSTUM_MAX];/* inward normals of the planes through x */
} frustum;

static int outside_frustum(const frustum *fr, vec3 x, const vec3 *p, int count)
{
    for (int k = 0; k < fr->n; k++) {
        int out = 1;
        for (int i = 0; i < count && out; i++)
            out = v3_dot(fr->normal[k], v3_sub(p[i], x)) < 0;
        if (out)
            return 1;
    }
    return 0;
}

/* Whether triangle o surely casts no shadow at x: wholly outside one of the
 * pyramid's side planes, culled from x's side, or below x's horizon. */
static int triangle_misses(const frustum *fr, vec3 x, vec3 n, const zprim *o)
{
    if (outside_frustum(fr, x, o->p, 3))
        return 1;
    vec3 nt = v3_cross(v3_sub(o->p[1], o->p[0]), v3_sub(o->p[2], o->p[0]));
    /* A culled triangle lets rays from behind through. */
    if (o->culled && v3_dot(nt, v3_sub(x, o->p[0])) <= 0)
        return 1;
    int above = 0;
    for (int i = 0; i < 3; i++)
        above |= v3_dot(n, v3_sub(o->p[i], x)) > 0;
    return !above;
}

static int occlude_with(const direct_ctx *c, const light_frame *f, vec3 x,
                        vec3 n, const zprim *o, int beyond,
                        const frustum *fr, poly2_set *set, poly2 *scratch)
{
    poly3 poly;
    switch (o->shape) {
    case SHAPE_TRIANGLE: {
        if (triangle_misses(fr, x, n, o))
            return 0;
        poly.n = 3;
        for (int i = 0; i < 3; i++)
            poly.p[i] = o->p[i];
        break;
    }
    case SHAPE_SPHERE: {
        vec3 sc, sw;
        double sr;
        if (!sphere_silhouette(o->p[0], o->radius, x, &sc, &sw, &sr))
            return !o->culled; /* inside: opaque unless culled */
        if (v3_dot(n, v3_sub(o->p[0], x)) <= -o->radius)
            return 0;
        double hc = height(f, o->p[0]), s = f->hx > 0 ? 1.0 : -1.0;
        if (!beyond && (s * hc - o->radius <= 0 || s * hc + o->radius >= fabs(f->hx))) {
            /* The sphere crosses the light's plane or x's level: its shadow
             * is the projection of the part between them. */
            sphere_cut(c, f, x, o, sc, sw, sr, set, scratch);
            return 0;
        }
        disk_polygon(sc, sw, sr, c->sides, &poly);
        break;
    }
    case SHAPE_PLANE: {
        double sx = v3_dot(o->normal, x) - o->offset;
        if (o->culled && sx <= 0)
            return 0;
        /* Points q of the light plane whose segment from x crosses this
         * plane are hidden: keep the side of x. */
        double s = sx > 0 ? 1.0 : -1.0;
        double a = s * v3_dot(o->normal, f->u), b = s * v3_dot(o->normal, f->v);
        double k = s * (v3_dot(o->normal, f->origin) - o->offset);
        if (beyond)
            return 0; /* background light behind a foreground plane: rare, left out */
        for (int i = 0; i < set->count; i++)
            poly2_clip(&set->piece[i], a, b, k);
        return 0;
    }
    default:
        return 0;
    }
    cut_shadow(f, x, &poly, beyond, set, scratch);
    return 0;
}

/* Light `light` as a primitive seen from x: a part, or the sun. */
static void light_prim(const direct_ctx *c, int light, vec3 x, zprim *out)
{
    if (light != DIRECT_SUN) {
        zprim_get(c->scene, c->rs, light, out);
        return;
    }
    /* Rays to the disc stop where they enter the sphere, (1 - sin r) of the
     * way: that must lie beyond every primitive. */
    double dist = (v3_length(v3_sub(x, c->far_centre)) + 2.0 * c->far_radius + 1.0) /
                  (1.0 - c->sun_sin);
    *out = (zprim){.shape = SHAPE_SPHERE, .radius = dist * c->sun_sin, .is_light = 1,
                   .object = -1};
    out->p[0] = v3_add(x, v3_scale(c->sun_dir, dist));
}

/* The light's polygon on its plane as seen from x, in the frame's 2D
 * coordinates.  Returns 0 when x sees no side of it that emits. */
static int light_polygon(const direct_ctx *c, int light, vec3 x, light_frame *f,
                         poly2 *out)
{
    zprim lpp;
    light_prim(c, light, x, &lpp);
    const zprim *lp = &lpp;
    poly3 light_poly;
    if (lp->shape == SHAPE_TRIANGLE) {
        vec3 nl = v3_normalize(v3_cross(v3_sub(lp->p[1], lp->p[0]), v3_sub(lp->p[2], lp->p[0])));
        if (lp->culled && v3_dot(nl, v3_sub(x, lp->p[0])) <= 0)
            return 0;
        f->origin = lp->p[0];
        f->n = nl;
        light_poly.n = 3;
        for (int i = 0; i < 3; i++)
            light_poly.p[i] = lp->p[i];
    } else if (lp->shape == SHAPE_SPHERE) {
        vec3 dc, w;
        double dr;
        if (!sphere_silhouette(lp->p[0], lp->radius, x, &dc, &w, &dr))
            return 0; /* inside a light sphere: not handled here */
        f->origin = dc;
        f->n = w;
        disk_polygon(dc, w, dr, c->sides, &light_poly);
    } else {
        return 0; /* light planes: not handled by the direct term */
    }
    basis(f->n, &f->u, &f->v);
    f->hx = height(f, x);
    if (fabs(f->hx) <= 1e-12)
        return 0;
    out->n = light_poly.n;
    for (int i = 0; i < light_poly.n; i++) {
        vec3 d = v3_sub(light_poly.p[i], f->origin);
        out->x[i] = v3_dot(d, f->u);
        out->y[i] = v3_dot(d, f->v);
    }
    poly2_make_ccw(out);
    return 1;
}

/* occlude_with for primitive i under the background rule: background
 * objects never block foreground lights; foreground objects block
 * background lights even beyond them. */
static int occlude_by(const direct_ctx *c, int i, const zprim *light, const light_frame *f,
                      vec3 x, vec3 n, const frustum *fr, poly2_set *set, poly2 *scratch)
{
    zprim o;
    zprim_get(c->scene, c->rs, i, &o);
    if (o.background && !light->background)
        return 0;
    return occlude_with(c, f, x, n, &o, light->background && !o.background, fr, set, scratch);
}

static vec3 lift(const light_frame *f, double a, double b)
{
    return v3_add(f->origin, v3_add(v3_scale(f->u, a), v3_scale(f->v, b)));
}

/* Where a shadow of the light at x can come from: the box around x and
 * the light's pieces, cut by the pyramid from x through the light (fr, its
 * side planes, also returned). */
static void shadow_region(const zprim *light, const light_frame *f, vec3 x, const poly2_set *set,
                          occ_region *out, frustum *out_fr)
{
    occ_region region;
    region.lo = x;
    region.hi = x;
    region.planes = 0;
    for (int k = 0; k < set->count; k++)
        for (int i = 0; i < set->piece[k].n; i++) {
            vec3 q = lift(f, set->piece[k].x[i], set->piece[k].y[i]);
            region.lo = v3_min3(region.lo, q);
            region.hi = v3_max3(region.hi, q);
        }
    /* Side planes of the pyramid from x through the (one, convex) light
     * polygon, facing inward; background lights are blocked beyond it
     * too, which the pyramid does not bound, so they skip the test. */
    frustum fr = {0, {{0, 0, 0}}};
    const poly2 *lp = &set->piece[0];
    if (set->count == 1 && lp->n >= 3 && lp->n <= FRUSTUM_MAX && !light->background) {
        vec3 q0 = lift(f, lp->x[lp->n - 1], lp->y[lp->n - 1]), inside = v3(0, 0, 0);
        for (int i = 0; i < lp->n; i++)
            inside = v3_add(inside, lift(f, lp->x[i], lp->y[i]));
        inside = v3_scale(inside, 1.0 / lp->n);
        for (int i = 0; i < lp->n; i++) {
            vec3 q1 = lift(f, lp->x[i], lp->y[i]);
            vec3 nn = v3_cross(v3_sub(q0, x), v3_sub(q1, x));
            if (v3_dot(nn, v3_sub(inside, x)) < 0)
                nn = v3_scale(nn, -1);
            fr.normal[fr.n++] = nn;
            if (region.planes < OCC_PLANES_MAX) {
                region.n[region.planes] = nn;
                region.d[region.planes++] = -v3_dot(nn, x);
            }
            q0 = q1;
        }
    }
    if (light->background) {
        /* Foreground primitives beyond the light hide it too. */
        region.lo = v3(-INFINITY, -INFINITY, -INFINITY);
        region.hi = v3(INFINITY, INFINITY, INFINITY);
    }
    *out = region;
    *out_fr = fr;
}

/* Whether primitive o, which lets part of the light through (a pane, or a
 * surface with holes or partial coverage), can shadow the light seen from
 * x at all: the occluder index tests boxes, and a large masked panel's box
 * meets many pyramids that its triangles miss.  A triangle that clipping
 * would pass over (triangle_misses) or that lies wholly beyond the light's
 * plane (cut_shadow keeps only what is between it and x) casts no shadow
 * there; other shapes may. */
static int passing_may_shadow(const zprim *light, const light_frame *f, vec3 x, vec3 n,
                              const zprim *o, const frustum *fr)
{
    if (o->background && !light->background)
        return 0;
    if (o->shape != SHAPE_TRIANGLE || light->background)
        return 1;
    if (triangle_misses(fr, x, n, o))
        return 0;
    double s = f->hx > 0 ? 1.0 : -1.0;
    for (int i = 0; i < 3; i++)
        if (s * height(f, o->p[i]) > 0)
            return 1;
    return 0;
}

/* Cuts the shadows of every primitive but the receiver and the light out
 * of the pieces.  Returns 1 when done, 0 when x is enclosed and sees
 * nothing, -1 when more occluders stand in the way than clipping takes
 * (the caller then sees the light by rays). */
static int cut_occluders(const direct_ctx *c, int light, const light_frame *f, vec3 x,
                         vec3 n, int receiver, poly2_set *set, poly2 *scratch)
{
    const zt_scene *sc = c->scene;
    zprim lpp;
    light_prim(c, light, x, &lpp);
    occ_region region;
    frustum fr;
    shadow_region(&lpp, f, x, set, &region, &fr);
    /* Infinite planes are few and in no index. */
    for (int i = 0; i < sc->part_count; i++)
        if (i != receiver && i != light && sc->parts[i].shape == SHAPE_PLANE) {
            if (rs_passes(&c->rs->objects[c->rs->parts[i].object]))
                return -1;
            if (occlude_by(c, i, &lpp, f, x, n, &fr, set, scratch))
                return 0;
        }
    int32_t cand[DIRECT_MAX_OCCLUDERS];
    int found = occluders_query(c->occ, &region, cand, DIRECT_MAX_OCCLUDERS);
    if (found > DIRECT_MAX_OCCLUDERS)
        return -1;
    for (int k = 0; k < found; k++) {
        if (cand[k] == receiver || cand[k] == light)
            continue;
        /* A pane, or a surface with holes or partial coverage (alpha),
         * lets part of the light through: not a shadow that clipping can
         * draw, so where it may cast one the point takes rays (which see
         * through it). */
        rs_part tmp;
        if (c->rs->pane_count && rs_passes(&c->rs->objects[rs_prim(c->rs, cand[k], &tmp)->object])) {
            zprim o;
            zprim_get(c->scene, c->rs, cand[k], &o);
            if (passing_may_shadow(&lpp, f, x, n, &o, &fr))
                return -1;
            continue;
        }
        if (occlude_by(c, cand[k], &lpp, f, x, n, &fr, set, scratch))
            return 0;
    }
    return set->overflow ? -1 : 1;
}

/* The pieces of convex polygon p (on the light's plane) in order: each
 * triangle of its fan from vertex 0 cut into m^2 by midpoints, row by row,
 * each upright piece followed by the upside-down one beside it. */
typedef struct fan_walk {
    const light_frame *f;
    const poly2 *p;
    int m, t, j, i, up;
    vec3 a, e1, e2;
} fan_walk;

static void fan_start(fan_walk *w, const light_frame *f, const poly2 *p, int m)
{
    *w = (fan_walk){.f = f, .p = p, .m = m, .a = lift(f, p->x[0], p->y[0])};
}

/* The next piece into q; 0 when there are no more. */
static int fan_next(fan_walk *w, vec3 q[3])
{
    for (;;) {
        if (w->t == 0 || w->j >= w->m) {
            if (++w->t + 1 >= w->p->n)
                return 0;
            vec3 b = lift(w->f, w->p->x[w->t], w->p->y[w->t]);
            vec3 c = lift(w->f, w->p->x[w->t + 1], w->p->y[w->t + 1]);
            w->e1 = v3_scale(v3_sub(b, w->a), 1.0 / w->m);
            w->e2 = v3_scale(v3_sub(c, w->a), 1.0 / w->m);
            w->j = w->i = w->up = 0;
        }
        if (w->i + w->j >= w->m) {
            w->j++;
            w->i = w->up = 0;
            continue;
        }
        int i = w->i, j = w->j, up = w->up;
        if (up) {
            w->up = 0;
            w->i++;
            if (i + j + 1 >= w->m)
                continue; /* no upside-down piece at a row's end */
        } else {
            w->up = 1;
        }
        vec3 base = v3_add(w->a, v3_add(v3_scale(w->e1, i), v3_scale(w->e2, j)));
        q[0] = up ? v3_add(base, w->e1) : base;
        q[1] = up ? v3_add(v3_add(base, w->e1), w->e2) : v3_add(base, w->e1);
        q[2] = v3_add(base, w->e2);
        return 1;
    }
}

/* A sphere light's pieces lie on its silhouette's disc, inside the sphere:
 * a ray towards one ends where it enters the sphere (or at the disc, if
 * it somehow misses), so the light does not hide itself. */
static float sphere_entry(const zprim *lp, vec3f o, vec3f d, float dist)
{
    vec3 oc = v3_sub(lp->p[0], f3_to_v3(o)), dd = f3_to_v3(d);
    double b = v3_dot(dd, oc), disc = b * b - (v3_dot(oc, oc) - lp->radius * lp->radius);
    if (disc < 0)
        return dist;
    double t = b - sqrt(disc);
    return t > 0 && t < dist ? (float)t : dist;
}

/* Whether the scene has no more primitives than are clipped exactly: then
 * no point sees a light by rays (a Cornell box). */
static int clips_every_point(const direct_ctx *c)
{
    return c->occ->prim_count <= DIRECT_MAX_OCCLUDERS;
}

/* Pieces whose rays' results by_rays keeps, to weigh the smaller side. */
#define BY_RAYS_KEPT 1024
/* Rays by_rays casts together. */
#define BY_RAYS_PACKET 64

/* Casts n rays from xo (unit directions dir, distances reach) together and
 * marks the pieces ray_of[i] they see in seen; returns how many see. */
static int by_rays_cast(const rscene *rs, vec3f xo, int background, const vec3f *dir,
                        const float *reach, const int *ray_of, int n, vec3f *seen)
{
    unsigned char hidden[BY_RAYS_PACKET];
    accel_occluded_n(rs, xo, dir, reach, n, background, hidden);
    int count = 0;
    for (int i = 0; i < n; i++)
        if (!hidden[i]) {
            seen[ray_of[i]] = f3_splat(1.0f);
            count++;
        }
    return count;
}

static _Thread_local uint64_t rays_cast;

uint64_t direct_rays_take(void)
{
    uint64_t n = rays_cast;
    rays_cast = 0;
    return n;
}

/* The centre of the sub-piece of triangle q that split point `index`
 * names at `levels` levels (direct.h): each base-4 digit, lowest first,
 * takes the quarter at corner d (d < 3) or the middle one (d = 3). */
static vec3 split_centre(const vec3 q[3], int levels, int index)
{
    vec3 a = q[0], b = q[1], c = q[2];
    for (int l = 0; l < levels; l++, index >>= 2) {
        int d = index & 3;
        vec3 ab = v3_scale(v3_add(a, b), 0.5), bc = v3_scale(v3_add(b, c), 0.5),
             ca = v3_scale(v3_add(c, a), 0.5);
        if (d == 0) {
            b = ab;
            c = ca;
        } else if (d == 1) {
            a = ab;
            c = bc;
        } else if (d == 2) {
            a = ca;
            b = bc;
        } else {
            a = ab;
            b = bc;
            c = ca;
        }
    }
    return v3_scale(v3_add(v3_add(a, b), c), 1.0 / 3.0);
}

/* The midpoint levels k that cut a polygon of `fan` fan triangles into
 * at least `count` pieces (fan x 4^k, at most 4^6 a triangle). */
static int fan_levels(int fan, int count)
{
    int k = 0;
    while (fan * (1 << (2 * k)) < count && k < 6)
        k++;
    return k;
}

/* The irradiance of polygon piece p (on the light's plane) at x, with
 * visibility by rays: p is cut into triangles of about 1/count of the
 * light each, and each counts if a ray from x reaches its centre.  A split
 * point (direct.h) takes triangles 4^j times as large and sends its ray to
 * the centre of the sub-piece it names.  When the block has more points
 * than that leaves levels to cut (a polygon of many sides, the sun's or a
 * sphere light's disc, whose fan already has about `count` triangles), the
 * block's points also share the fan's triangles: each takes every s-th of
 * them, s = what is left of the block, and weighs what it sees by s, so
 * that a block of 64 points sees the disc's triangles between them for one
 * point's rays instead of each point all of them (on the IFC house at the
 * default quality, every edge sample cast 30 rays at the sun). */
static vec3 by_rays(const direct_ctx *c, const zprim *lp, const light_frame *f, const poly2 *p,
                    vec3 x, vec3 n, int count, int split)
{
    /* Fan triangles, each cut into 4^k by midpoints. */
    int fan = p->n - 2, k = fan_levels(fan, count);
    int levels = DIRECT_SPLIT_LEVELS(split), index = DIRECT_SPLIT_INDEX(split);
    if ((split & DIRECT_SPLIT_BLOCK) && levels + 1 > k) {
        /* A point standing for four a level finer, which share the fan's
         * triangles: their rays, one after the other. */
        vec3 e = v3(0, 0, 0);
        for (int d = 0; d < 4; d++)
            e = v3_add(e, by_rays(c, lp, f, p, x, n, count,
                                  DIRECT_SPLIT(levels + 1, 4 * index + d)));
        return v3_scale(e, 0.25);
    }
    int used = levels > k ? k : levels;
    int share = 1, offset = 0;
    if (levels > used) {
        int rest = 1 << (2 * (levels - used));
        share = rest < fan ? rest : fan;
        offset = ((index >> (2 * used)) % rest) % share;
    }
    levels = used;
    k -= levels;
    int m = 1 << k, per_fan = m * m, pieces = fan * per_fan;
    vec3f xo = ray_offset(v3_to_f3(x), v3_to_f3(n));
    /* First every piece's ray; then Lambert's formula over the seen pieces
     * or, when most are seen, over the whole polygon less the hidden ones:
     * the formula costs more than a ray, and most points see all or none.
     * A ray's result is 1 or 0, or by colour what panes let through.  A
     * point that takes every share-th fan triangle weighs each by share. */
    vec3f seen[BY_RAYS_KEPT];
    int keep = pieces <= BY_RAYS_KEPT, at = 0, taken = 0;
    double seen_count = 0;
    vec3 e = v3(0, 0, 0);
    fan_walk w;
    vec3 q[3];
    /* Without panes a ray's answer is 0 or 1, and the point's rays go
     * together as packets (nearly parallel: they all aim at the light). */
    int packed = keep && !c->rs->pane_count;
    vec3f dir[BY_RAYS_PACKET];
    float reach[BY_RAYS_PACKET];
    int ray_of[BY_RAYS_PACKET], rays = 0;
    fan_start(&w, f, p, m);
    for (int g = 0; fan_next(&w, q); g++) {
        vec3f s = f3_splat(0.0f);
        if (share == 1 || (g / per_fan) % share == offset) {
            taken++;
            vec3 ctr = split_centre(q, levels, index);
            vec3f to = f3_sub(v3_to_f3(ctr), xo);
            float dist = f3_length(to);
            if (dist > 0.0f) {
                vec3f d = f3_scale(to, 1.0f / dist);
                if (lp->shape == SHAPE_SPHERE)
                    dist = sphere_entry(lp, xo, d, dist);
                rays_cast++;
                if (packed) {
                    dir[rays] = d;
                    reach[rays] = dist * 0.9999f;
                    ray_of[rays++] = at;
                } else
                    s = accel_transmittance(c->rs, xo, d, dist * 0.9999f, lp->background);
            }
            if (!keep && !f3_is_black(s))
                e = v3_add(e, v3_scale(f3_to_v3(s), share * lambert_polygon(x, n, q, 3)));
            seen_count += f3_max(s);
        }
        if (keep)
            seen[at++] = s;
        if (rays == BY_RAYS_PACKET) {
            seen_count += by_rays_cast(c->rs, xo, lp->background, dir, reach, ray_of, rays, seen);
            rays = 0;
        }
    }
    if (rays)
        seen_count += by_rays_cast(c->rs, xo, lp->background, dir, reach, ray_of, rays, seen);
    if (!keep)
        return e;
    if (seen_count == 0)
        return e;
    int by_hidden = 2 * seen_count > taken;
    if (by_hidden) {
        vec3 whole[POLY2_MAX];
        for (int i = 0; i < p->n; i++)
            whole[i] = lift(f, p->x[i], p->y[i]);
        e = v3_splat(lambert_polygon(x, n, whole, p->n));
    }
    at = 0;
    fan_start(&w, f, p, m);
    for (int g = 0; fan_next(&w, q); g++) {
        /* By the hidden ones, each takes away what it does not pass. */
        vec3 s = f3_to_v3(seen[at++]);
        if (share > 1 && (g / per_fan) % share != offset)
            continue;
        vec3 part = by_hidden ? v3_sub(v3_splat(1.0), s) : s;
        if (part.x > 0 || part.y > 0 || part.z > 0) {
            double gl = share * lambert_polygon(x, n, q, 3);
            e = by_hidden ? v3_sub(e, v3_scale(part, gl)) : v3_add(e, v3_scale(part, gl));
        }
    }
    return v3(e.x > 0 ? e.x : 0, e.y > 0 ? e.y : 0, e.z > 0 ? e.z : 0);
}

double direct_irradiance(const direct_ctx *c, int light, vec3 x, vec3 n,
                         int receiver)
{
    return direct_irradiance_split(c, light, x, n, receiver, 0);
}

double direct_irradiance_split(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver,
                               int split)
{
    vec3 e = direct_irradiance_rgb(c, light, x, n, receiver, split);
    return e.x == e.y && e.y == e.z ? e.x : (e.x + e.y + e.z) / 3.0;
}

vec3 direct_irradiance_rgb(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver,
                           int split)
{
    return direct_irradiance_rays(c, light, x, n, receiver, split, c->fallback);
}

int direct_rays_by_share(const direct_ctx *c, double share)
{
    if (!(share < 1.0))
        return c->fallback;
    double k = floor(c->fallback * share);
    return k < 1 ? 1 : (int)k;
}

vec3 direct_irradiance_rays(const direct_ctx *c, int light, vec3 x, vec3 n, int receiver,
                            int split, int count)
{
    zprim lpp;
    light_prim(c, light, x, &lpp);
    const zprim *lp = &lpp;

    if (lp->shape == SHAPE_POINT) {
        vec3 d = v3_sub(lp->p[0], x);
        double d2 = v3_dot(d, d), cosx = v3_dot(n, d) / sqrt(d2);
        if (cosx <= 0)
            return v3(0, 0, 0);
        vec3f xf = f3((float)x.x, (float)x.y, (float)x.z);
        vec3f nf = f3((float)n.x, (float)n.y, (float)n.z);
        vec3f df = f3((float)d.x, (float)d.y, (float)d.z);
        float dist = f3_length(df);
        vec3f s = accel_transmittance(c->rs, ray_offset(xf, nf), f3_scale(df, 1.0f / dist),
                                      dist * 0.9999f, lp->background);
        rays_cast++;
        return v3(s.x * cosx / d2, s.y * cosx / d2, s.z * cosx / d2);
    }

    light_frame f;
    poly2 pieces[MAX_PIECES], scratch;
    poly2_set set = {pieces, 1, MAX_PIECES, 0};
    if (!light_polygon(c, light, x, &f, &pieces[0]))
        return v3(0, 0, 0);
    /* Above x's horizon only. */
    poly2_clip(&pieces[0], v3_dot(n, f.u), v3_dot(n, f.v), v3_dot(n, v3_sub(f.origin, x)));
    if (pieces[0].n < 3)
        return v3(0, 0, 0);
    poly2 whole = pieces[0];
    /* Split points are only taken where shadows are busy, and there the
     * search nearly always finds too many: it is skipped (direct.h).  So
     * is it for a part whose rays are fewer pieces than the fallback's
     * (one of a light cut into many): a search per part costs as much as
     * tens of rays, where the parts' rays are one point's budget between
     * them. */
    int fan = whole.n - 2;
    int fewer = fan_levels(fan, count) < fan_levels(fan, c->fallback);
    int cut = (split > 0 || fewer) && !clips_every_point(c)
                  ? -1
                  : cut_occluders(c, light, &f, x, n, receiver, &set, &scratch);
    if (cut < 0)
        return by_rays(c, lp, &f, &whole, x, n, count, split);
    if (cut == 0)
        return v3(0, 0, 0);
    double e = 0;
    for (int k = 0; k < set.count; k++) {
        const poly2 *p = &set.piece[k];
        if (p->n < 3)
            continue;
        vec3 q[POLY2_MAX];
        for (int i = 0; i < p->n; i++)
            q[i] = lift(&f, p->x[i], p->y[i]);
        e += lambert_polygon(x, n, q, p->n);
    }
    return v3_splat(e);
}

int direct_by_rays(const direct_ctx *c, int light, vec3 x, vec3 n)
{
    if (clips_every_point(c))
        return 0;
    zprim lpp;
    light_prim(c, light, x, &lpp);
    light_frame f;
    poly2 pieces[1];
    poly2_set set = {pieces, 1, 1, 0};
    if (!light_polygon(c, light, x, &f, &pieces[0]))
        return 0;
    poly2_clip(&pieces[0], v3_dot(n, f.u), v3_dot(n, f.v), v3_dot(n, v3_sub(f.origin, x)));
    if (pieces[0].n < 3)
        return 0;
    occ_region region;
    frustum fr;
    shadow_region(&lpp, &f, x, &set, &region, &fr);
    int32_t cand[DIRECT_MAX_OCCLUDERS];
    return occluders_query(c->occ, &region, cand, DIRECT_MAX_OCCLUDERS) > DIRECT_MAX_OCCLUDERS;
}

/* Where the line from a through b meets the plane (pn, po). */
static vec3 through_plane(vec3 a, vec3 b, vec3 pn, double po)
{
    vec3 d = v3_sub(b, a);
    double t = (po - v3_dot(pn, a)) / v3_dot(pn, d);
    return v3_add(a, v3_scale(d, t));
}

double direct_pixel_coverage(const direct_ctx *ctx, int light, vec3 eye,
                             const vec3 corner[4])
{
    /* Outlines of spheres as fine as polygons go: a light seen directly is
     * the brightest thing in the image, and its edge pixels show every
     * sliver a coarse outline gets wrong. */
    direct_ctx fine = *ctx;
    fine.sides = 32;
    const direct_ctx *c = &fine;
    light_frame f;
    poly2 pieces[MAX_PIECES], scratch;
    poly2_set set = {pieces, 1, MAX_PIECES, 0};
    zprim lpp;
    light_prim(c, light, eye, &lpp);
    if (lpp.shape == SHAPE_POINT || !light_polygon(c, light, eye, &f, &pieces[0]))
        return 0;
    /* The pixel's footprint on the light's plane: its corners seen from the
     * eye.  The corners run around the pixel, so the quad is convex. */
    poly2 quad;
    quad.n = 4;
    for (int i = 0; i < 4; i++) {
        vec3 q = through_plane(eye, corner[i], f.n, v3_dot(f.n, f.origin));
        vec3 d = v3_sub(q, f.origin);
        quad.x[i] = v3_dot(d, f.u);
        quad.y[i] = v3_dot(d, f.v);
    }
    poly2_make_ccw(&quad);
    for (int i = 0, j = quad.n - 1; i < quad.n; j = i++) {
        double a = quad.y[j] - quad.y[i], b = quad.x[i] - quad.x[j];
        poly2_clip(&pieces[0], a, b, -(a * quad.x[j] + b * quad.y[j]));
    }
    if (pieces[0].n < 3)
        return 0;
    /* The eye sees with no horizon: a normal pointing at the light. */
    vec3 toward = v3_scale(f.n, f.hx > 0 ? -1.0 : 1.0);
    int cut = cut_occluders(c, light, &f, eye, toward, -1, &set, &scratch);
    if (cut < 0)
        return -1;
    if (cut == 0)
        return 0;
    /* Back to the screen, where the pixel filter lives: areas there. */
    vec3 sn = v3_normalize(v3_cross(v3_sub(corner[1], corner[0]), v3_sub(corner[3], corner[0])));
    double so = v3_dot(sn, corner[0]);
    vec3 su = v3_normalize(v3_sub(corner[1], corner[0])), sv = v3_cross(sn, su);
    poly2 pix;
    pix.n = 4;
    for (int i = 0; i < 4; i++) {
        vec3 d = v3_sub(corner[i], corner[0]);
        pix.x[i] = v3_dot(d, su);
        pix.y[i] = v3_dot(d, sv);
    }
    double pixel_area = fabs(poly2_area(&pix)), covered = 0;
    for (int k = 0; k < set.count; k++) {
        const poly2 *p = &set.piece[k];
        if (p->n < 3)
            continue;
        poly2 s2;
        s2.n = p->n;
        for (int i = 0; i < p->n; i++) {
            vec3 q = through_plane(eye, lift(&f, p->x[i], p->y[i]), sn, so);
            vec3 d = v3_sub(q, corner[0]);
            s2.x[i] = v3_dot(d, su);
            s2.y[i] = v3_dot(d, sv);
        }
        covered += fabs(poly2_area(&s2));
    }
    return pixel_area > 0 ? fmin(1.0, covered / pixel_area) : 0;
}
