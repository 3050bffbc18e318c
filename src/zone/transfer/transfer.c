/* The transfer (transfer.h): a cut per receiver through the sender tree,
 * elements taken exactly. */
#include "zone/transfer/transfer.h"

#include <math.h>
#include <string.h>

#include "geom/ray_offset.h"
#include "render/prim.h"
#include "util/vec3_convert.h"
#include "zone/light/lambert.h"
#include "zone/transfer/cut.h"

#define SPLIT_DEPTH 1
#define VIS_DEPTH 1
/* Pieces smaller than this share of theta x distance are point sources. */
#define POINT_SHARE 0.5
/* Heights over the receiver's plane below this share of the distance are
 * rounding (single-precision vertices). */
#define PLANE_TOLERANCE 1e-5
#define POLY_MAX 12

typedef struct gather {
    const transfer_ctx *c;
    vec3 x, n;
    vec3f xo;           /* ray origin off the surface */
    cut_stats *st;
    /* The sender's sphere, when it sends from its outer side (radius 0:
     * not): its elements are flat cells between nodes on the sphere,
     * inside it, so rays toward them aim at the surface above them
     * instead, or the sphere would hide them all. */
    vec3 sphere_c;
    double sphere_r;
} gather;

static double visible(gather *g, vec3 to, int background)
{
    if (g->sphere_r > 0) {
        vec3 d = v3_sub(to, g->sphere_c);
        double len = v3_length(d);
        if (len > 0)
            to = v3_add(g->sphere_c, v3_scale(d, g->sphere_r / len));
    }
    return cut_visible(g->c->rs, g->xo, to, background, g->st);
}

/* Keeps the part of polygon q where a . p + b >= 0. */
static int clip(vec3 *q, int n, vec3 a, double b, double *val, int vals)
{
    vec3 out[POLY_MAX];
    double ov[POLY_MAX * 3];
    int m = 0;
    for (int i = 0, j = n - 1; i < n; j = i++) {
        double dj = v3_dot(a, q[j]) + b, di = v3_dot(a, q[i]) + b;
        if ((dj >= 0) != (di >= 0) && m < POLY_MAX) {
            double t = dj / (dj - di);
            out[m] = v3_add(q[j], v3_scale(v3_sub(q[i], q[j]), t));
            for (int k = 0; k < vals; k++)
                ov[3 * m + k] = val[3 * j + k] + t * (val[3 * i + k] - val[3 * j + k]);
            m++;
        }
        if (di >= 0 && m < POLY_MAX) {
            out[m] = q[i];
            for (int k = 0; k < vals; k++)
                ov[3 * m + k] = val[3 * i + k];
            m++;
        }
    }
    memcpy(q, out, (size_t)m * sizeof *q);
    memcpy(val, ov, (size_t)m * 3 * sizeof *val);
    return m;
}

/* A piece of an element with a radiance per corner (b: 3 per corner):
 * split while it looks large, else Lambert's formula over it (above the
 * receiver's horizon) times its mean radiance, if a ray reaches it. */
static void piece(gather *g, const vec3 *q, const double *b, int corners, int background,
                  int depth, double vis, double acc[3])
{
    vec3 c = v3(0, 0, 0);
    double size = 0;
    for (int k = 0; k < corners; k++) {
        c = v3_add(c, q[k]);
        size = fmax(size, v3_length(v3_sub(q[k], q[(k + 1) % corners])));
    }
    c = v3_scale(c, 1.0 / corners);
    double dist = v3_length(v3_sub(c, g->x));
    if (depth < SPLIT_DEPTH && size > g->c->theta * dist) {
        /* Below VIS_DEPTH the pieces share their parent's ray: they refine
         * the form factor and the radiance, a ray each would cost more
         * than the shadows of occluders so near would show. */
        if (vis < 0 && depth >= VIS_DEPTH)
            vis = visible(g, c, background);
        if (vis == 0)
            return;
        /* Four pieces by the edges' midpoints (a quad also by its centre). */
        vec3 m[4];
        double mb[4][3], cb[3] = {0, 0, 0};
        for (int k = 0; k < corners; k++) {
            int k1 = (k + 1) % corners;
            m[k] = v3_scale(v3_add(q[k], q[k1]), 0.5);
            for (int ch = 0; ch < 3; ch++) {
                mb[k][ch] = 0.5 * (b[3 * k + ch] + b[3 * k1 + ch]);
                cb[ch] += b[3 * k + ch] / corners;
            }
        }
        if (corners == 3) {
            vec3 t[4][3] = {{q[0], m[0], m[2]}, {m[0], q[1], m[1]}, {m[2], m[1], q[2]},
                            {m[0], m[1], m[2]}};
            const double *tb[4][3] = {{&b[0], mb[0], mb[2]}, {mb[0], &b[3], mb[1]},
                                      {mb[2], mb[1], &b[6]}, {mb[0], mb[1], mb[2]}};
            for (int s = 0; s < 4; s++) {
                double vb[9];
                for (int k = 0; k < 3; k++)
                    for (int ch = 0; ch < 3; ch++)
                        vb[3 * k + ch] = tb[s][k][ch];
                piece(g, t[s], vb, 3, background, depth + 1, vis, acc);
            }
        } else {
            for (int s = 0; s < 4; s++) {
                int sp = (s + 3) % 4;
                vec3 t[4] = {q[s], m[s], c, m[sp]};
                double vb[12];
                for (int ch = 0; ch < 3; ch++) {
                    vb[ch] = b[3 * s + ch];
                    vb[3 + ch] = mb[s][ch];
                    vb[6 + ch] = cb[ch];
                    vb[9 + ch] = mb[sp][ch];
                }
                piece(g, t, vb, 4, background, depth + 1, vis, acc);
            }
        }
        return;
    }
    if (size < POINT_SHARE * g->c->theta * dist) {
        /* Small for its distance: a point source, its form factor
         * area x cos x cos / d^2 (within (size/dist)^2 / 4 of Lambert's,
         * at a tenth of the cost). */
        vec3 w = v3_sub(c, g->x);
        double cr = v3_dot(g->n, w) / dist;
        if (cr <= 0)
            return;
        vec3 cr3 = corners == 3 ? v3_cross(v3_sub(q[1], q[0]), v3_sub(q[2], q[0]))
                                : v3_cross(v3_sub(q[2], q[0]), v3_sub(q[3], q[1]));
        /* |cr3| / 2 is the area (a quad by its diagonals); cr3 . (-w) /
         * dist is area x 2 x cos_e. */
        double ff = 0.5 * -v3_dot(cr3, w) / dist * cr / (dist * dist);
        if (!(ff > 0))
            return;
        if (vis < 0)
            vis = visible(g, c, background);
        if (vis == 0)
            return;
        for (int ch = 0; ch < 3; ch++) {
            double mean = 0;
            for (int k = 0; k < corners; k++)
                mean += b[3 * k + ch];
            acc[ch] += ff * mean / corners * vis;
        }
        return;
    }
    vec3 p[POLY_MAX];
    double v[POLY_MAX * 3];
    memcpy(p, q, (size_t)corners * sizeof *p);
    memcpy(v, b, (size_t)corners * 3 * sizeof *v);
    int n = clip(p, corners, g->n, -v3_dot(g->n, g->x), v, 3);
    if (n < 3)
        return;
    /* A piece (nearly) in the receiver's tangent plane sends nothing, and
     * Lambert's formula is ill-conditioned there (its terms are the angles
     * at x, whose signs rounding decides): a neighbour on the same plane. */
    double hmax = 0;
    for (int k = 0; k < n; k++)
        hmax = fmax(hmax, v3_dot(g->n, v3_sub(p[k], g->x)));
    if (!(hmax > PLANE_TOLERANCE * dist))
        return;
    double ff = lambert_polygon(g->x, g->n, p, n);
    if (!(ff > 0))
        return;
    vec3 pc = v3(0, 0, 0);
    double mean[3] = {0, 0, 0};
    for (int k = 0; k < n; k++) {
        pc = v3_add(pc, p[k]);
        for (int ch = 0; ch < 3; ch++)
            mean[ch] += v[3 * k + ch] / n;
    }
    pc = v3_scale(pc, 1.0 / n);
    if (vis < 0)
        vis = visible(g, pc, background);
    if (vis == 0)
        return;
    for (int ch = 0; ch < 3; ch++)
        acc[ch] += ff * mean[ch] * vis;
}

/* Element i of the tree, exactly. */
static void element(gather *g, int i, double acc[3])
{
    const sender_tree *t = g->c->tree;
    const sender_elem *el = &t->elems[i];
    const float *rad = &t->elem_radiance[3 * (size_t)i];
    if (rad[0] <= 0.0f && rad[1] <= 0.0f && rad[2] <= 0.0f)
        return;
    /* It sends from its side only. */
    vec3 en = v3(el->n[0], el->n[1], el->n[2]), ec = v3(el->c[0], el->c[1], el->c[2]);
    vec3 to = v3_sub(g->x, ec);
    if (v3_dot(en, to) <= PLANE_TOLERANCE * v3_length(to))
        return;
    vec3 q[4];
    int32_t node[4];
    int corners = surface_element(g->c->sn, g->c->rs, el->prim, el->side, el->index, q, node);
    rs_part tmp;
    const rs_part *sp = rs_prim(g->c->rs, el->prim, &tmp);
    g->sphere_r = sp->shape == SHAPE_SPHERE && el->side == 0 ? sp->radius : 0;
    g->sphere_c = f3_to_v3(sp->p0);
    /* Each corner's radiance: its node's, or the element's mean where the
     * node is dead (or a sphere's pole). */
    double b[12];
    for (int k = 0; k < corners; k++)
        for (int ch = 0; ch < 3; ch++) {
            int live = node[k] >= 0 && g->c->sn->live[node[k]];
            b[3 * k + ch] = live ? (double)g->c->e[3 * (size_t)node[k] + ch] * el->albedo[ch]
                                 : rad[ch];
        }
    piece(g, q, b, corners, el->background, 0, -1, acc);
}

static void leaf(void *user, int i, vec3 x, vec3 n, double whole, double acc[3], cut_stats *st)
{
    (void)whole;
    gather g = {user, x, n, ray_offset(v3_to_f3(x), v3_to_f3(n)), st, {0, 0, 0}, 0};
    element(&g, i, acc);
}

vec3 transfer_irradiance(const transfer_ctx *c, vec3 x, vec3 n, int receiver,
                         transfer_stats *st, cut_record *rec)
{
    (void)receiver;
    cut_params p = {.eps = c->eps, .floor = c->floor, .max_cut = c->max_cut,
                    .leaf = leaf, .user = (void *)c};
    return cut_gather(c->tree, c->rs, x, n, ray_offset(v3_to_f3(x), v3_to_f3(n)), &p, st, rec);
}

vec3 transfer_irradiance_near(const transfer_ctx *c, vec3 x, vec3 n, const cut_record *from,
                              int more, transfer_stats *st)
{
    cut_params p = {.eps = c->eps, .floor = c->floor, .max_cut = more,
                    .leaf = leaf, .user = (void *)c};
    return cut_resume(c->tree, c->rs, x, n, ray_offset(v3_to_f3(x), v3_to_f3(n)), from, &p, st);
}
