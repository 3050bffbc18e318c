/* Which nodes light can reach (node_life.h). */
#include "zone/phase_one/node_life.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "geom/accel.h"
#include "geom/shapes.h"
#include "render/prim.h"
#include "util/vec3_convert.h"
#include "zone/phase_one/closed_surfaces.h"
#include "zone/light/zprim.h"

#define PROBES 8

/* Whether plane part q hides the open half-space behind it from every
 * light: opaque, a thing, the sky black (no map, no sun), every light in
 * front of it. */
static int is_wall(const zt_scene *sc, const rscene *rs, int q)
{
    const part *pq = &sc->parts[q];
    const object *oq = &sc->objects[pq->object];
    if (pq->shape != SHAPE_PLANE || oq->is_light || oq->mat.weight[LOBE_REFRACTIVE] > 0 ||
        !f3_is_black(rs->sky) || rs->distant.any)
        return 0;
    double eps = 1e-9 * (1.0 + fabs(pq->offset));
    for (int l = 0; l < rs->light_count; l++) {
        zprim lp;
        zprim_get(sc, rs, rs->lights[l].part, &lp);
        switch (lp.shape) {
        case SHAPE_TRIANGLE:
            for (int k = 0; k < 3; k++)
                if (v3_dot(pq->normal, lp.p[k]) - pq->offset < -eps)
                    return 0;
            break;
        case SHAPE_SPHERE:
            if (v3_dot(pq->normal, lp.p[0]) - pq->offset < lp.radius - eps)
                return 0;
            break;
        case SHAPE_POINT:
            if (v3_dot(pq->normal, lp.p[0]) - pq->offset < -eps)
                return 0;
            break;
        default:
            return 0;
        }
    }
    /* Point lights switched off are not in rs->lights but must not be
     * behind it either (the forest is the same with lights off). */
    for (int i = 0; i < rs->point_light_count; i++) {
        const part *lp = &sc->parts[rs->point_lights[i]];
        if (v3_dot(pq->normal, lp->p[0]) - pq->offset < -eps)
            return 0;
    }
    return 1;
}

/* Ray against one primitive in double precision, culling ignored:
 * distance in (tmin, tmax) or -1; *back when it meets the back side. */
static double hit_prim(const zprim *p, vec3 o, vec3 d, double tmax, int *back)
{
    switch (p->shape) {
    case SHAPE_TRIANGLE: {
        vec3 e1 = v3_sub(p->p[1], p->p[0]), e2 = v3_sub(p->p[2], p->p[0]);
        vec3 pv = v3_cross(d, e2);
        double det = v3_dot(e1, pv);
        if (det == 0)
            return -1;
        double inv = 1.0 / det;
        vec3 tv = v3_sub(o, p->p[0]);
        double u = v3_dot(tv, pv) * inv;
        if (u < 0 || u > 1)
            return -1;
        vec3 qv = v3_cross(tv, e1);
        double v = v3_dot(d, qv) * inv;
        if (v < 0 || u + v > 1)
            return -1;
        double t = v3_dot(e2, qv) * inv;
        if (!(t > 0 && t < tmax))
            return -1;
        *back = det < 0; /* det = -d . (e1 x e2) */
        return t;
    }
    case SHAPE_SPHERE: {
        vec3 f = v3_sub(o, p->p[0]);
        double b = v3_dot(f, d), c = v3_dot(f, f) - p->radius * p->radius;
        double disc = b * b - c;
        if (disc < 0)
            return -1;
        double s = sqrt(disc), t0 = -b - s, t1 = -b + s;
        if (t0 > 0 && t0 < tmax) {
            *back = 0;
            return t0;
        }
        if (t1 > 0 && t1 < tmax) {
            *back = 1;
            return t1;
        }
        return -1;
    }
    case SHAPE_PLANE: {
        double dn = v3_dot(d, p->normal);
        if (dn == 0)
            return -1;
        double t = (p->offset - v3_dot(o, p->normal)) / dn;
        if (!(t > 0 && t < tmax))
            return -1;
        *back = dn > 0;
        return t;
    }
    default:
        return -1;
    }
}

/* The distance at which ray (o, 1 / inv) enters box b before tmax, or -1
 * when it misses it. */
static double slab(const occ_node *b, vec3 o, vec3 inv, double tmax)
{
    double t0 = 0, t1 = tmax;
    double oo[3] = {o.x, o.y, o.z}, ii[3] = {inv.x, inv.y, inv.z};
    for (int a = 0; a < 3; a++) {
        double u = (b->lo[a] - oo[a]) * ii[a], v = (b->hi[a] - oo[a]) * ii[a];
        if (u > v) {
            double w = u;
            u = v;
            v = w;
        }
        /* Comparisons rather than fmax and fmin, which are calls here; a
         * NaN u or v is passed over, as they would. */
        t0 = u > t0 ? u : t0;
        t1 = v * 1.0000001 < t1 ? v * 1.0000001 : t1;
        if (t0 > t1)
            return -1;
    }
    return t0;
}

/* The nearest plane on ray (o, d) closer than *best, lowering *best:
 * its part, or `found` when none is nearer. */
static int planes_first_hit(const zt_scene *scene, const rscene *rs, vec3 o, vec3 d,
                            double *best, int found, int *back)
{
    for (int i = 0; i < rs->part_count; i++) {
        if (scene->parts[i].shape != SHAPE_PLANE)
            continue;
        zprim p;
        zprim_get(scene, rs, i, &p);
        int b;
        double t = hit_prim(&p, o, d, *best, &b);
        if (t > 0) {
            *best = t;
            found = i;
            *back = b;
        }
    }
    return found;
}

/* The nearest hit of ray (o, d) closer than tmax (node_life_first_hit);
 * *dist its distance. */
static int first_hit(const occluder_index *occ, const zt_scene *scene, const rscene *rs, vec3 o,
                     vec3 d, double tmax, int *back, double *dist)
{
    double best = tmax;
    int found = planes_first_hit(scene, rs, o, d, &best, -1, back);
    *dist = best;
    if (occ->prim_count == 0)
        return found;
    vec3 inv = v3(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    /* Nearer child first, each with the distance it is entered at: a box
     * entered beyond the nearest hit so far is skipped. */
    int32_t stack[OCC_STACK];
    double enter[OCC_STACK];
    int sp = 0;
    if (slab(&occ->nodes[0], o, inv, best) >= 0) {
        stack[sp] = 0;
        enter[sp++] = 0;
    }
    while (sp > 0) {
        sp--;
        if (enter[sp] > best)
            continue;
        const occ_node *node = &occ->nodes[stack[sp]];
        if (node->count > 0) {
            int first = -1 - node->left;
            for (int k = 0; k < node->count; k++) {
                int prim = occ->prims[first + k];
                zprim p;
                zprim_get(scene, rs, prim, &p);
                int b;
                double t = hit_prim(&p, o, d, best, &b);
                /* Ties to the lower number, for a fixed answer. */
                if (t > 0 && (t < best || (t == best && prim < found))) {
                    best = t;
                    found = prim;
                    *back = b;
                }
            }
        } else {
            double tl = slab(&occ->nodes[node->left], o, inv, best);
            double tr = slab(&occ->nodes[node->left + 1], o, inv, best);
            int near = node->left, far = node->left + 1;
            if (tr >= 0 && (tl < 0 || tr < tl)) {
                double w = tl;
                tl = tr;
                tr = w;
                near = node->left + 1;
                far = node->left;
            }
            if (tr >= 0) {
                stack[sp] = far;
                enter[sp++] = tr;
            }
            if (tl >= 0) {
                stack[sp] = near;
                enter[sp++] = tl;
            }
        }
    }
    *dist = best;
    return found;
}

int node_life_first_hit(const occluder_index *occ, const zt_scene *scene, const rscene *rs,
                        vec3 o, vec3 d, int *back)
{
    /* Where the renderer's structure can take culling off (Embree), the
     * primitives go to it, the planes as first_hit takes them: the index's
     * walk in double was up to 40% of Phase One on a large model (the
     * engine room at quality 0). */
    hit h;
    vec3f df = v3_to_f3(d);
    if (accel_nearest_all_sides(rs, v3_to_f3(o), df, FLT_MAX, &h)) {
        double best = h.part >= 0 ? (double)h.t : INFINITY;
        int found = planes_first_hit(scene, rs, o, d, &best, h.part, back);
        if (found >= 0 && found == h.part) {
            rs_part tmp;
            const rs_part *p = rs_prim(rs, h.part, &tmp);
            vec3f x = shape_hit_point(p, v3_to_f3(o), df, h.t);
            *back = f3_dot(shape_normal(p, x), df) > 0.0f;
        }
        return found;
    }
    double t;
    return first_hit(occ, scene, rs, o, d, INFINITY, back, &t);
}

/* A fixed set of directions around the normal (a golden-angle spiral over
 * the hemisphere, cosine-distributed). */
static vec3 probe_dir(vec3 n, int k)
{
    vec3 a = fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0);
    vec3 t = v3_normalize(v3_cross(a, n)), b = v3_cross(n, t);
    double u = (k + 0.5) / PROBES, r = sqrt(u), phi = k * 2.39996322972865332;
    return v3_normalize(v3_add(v3_add(v3_scale(t, r * cos(phi)), v3_scale(b, r * sin(phi))),
                               v3_scale(n, sqrt(1.0 - u))));
}

static vec3 node_pos(const surface_nodes *sn, int32_t k)
{
    return v3(sn->pos[3 * k], sn->pos[3 * k + 1], sn->pos[3 * k + 2]);
}

/* A model's vertex sunk into another closed part (a fin's root in the
 * cylinder it stands on) is dead, yet the triangles around it show outside
 * that part, and read from their live corners alone they would carry the
 * light of those corners right down to the junction (on the engine room
 * its fins were 8% too bright at the first bounce).  Such a vertex is
 * raised: along an element's edge from a live corner to just before the
 * first surface on the way, where the edge leaves the open space, and
 * lives there, so its light is the junction's.  Of several live corners,
 * the one whose junction lies nearest the vertex wins.  A vertex dead with
 * no surface in between stays dead.  Only the vertices: raising a large
 * triangle's own grid nodes as well made the engine room's first bounce
 * worse (2.82% -> 2.88% over 4 x 4 blocks), by nodes raised onto the very
 * part that hides them.  Returns the rays traced. */
static uint64_t raise_sunk_vertices(surface_nodes *sn, const occluder_index *occ,
                                    const zt_scene *scene, const rscene *rs)
{
    double *gap = malloc((size_t)sn->node_count * sizeof *gap);
    vec3 *to = malloc((size_t)sn->node_count * sizeof *to);
    uint64_t rays = 0;
    if (!gap || !to) {
        /* Without memory the nodes stay dead, as they were. */
        free(gap);
        free(to);
        return 0;
    }
    for (int k = 0; k < sn->node_count; k++)
        gap[k] = INFINITY;
    double lift = 1e-4 * sn->h;
    for (int prim = 0; prim < sn->prim_count; prim++) {
        const node_prim *np = &sn->prim[prim];
        if (np->kind != NODE_TRIANGLE || !np->shared || np->first < 0)
            continue;
        int elements = surface_element_count(sn, prim);
        for (int side = 0; side < np->sides; side++)
            for (int e = 0; e < elements; e++) {
                vec3 q[4];
                int32_t c[4];
                surface_element(sn, rs, prim, side, e, q, c);
                int alive = sn->live[c[0]] + sn->live[c[1]] + sn->live[c[2]];
                if (alive == 0 || alive == 3)
                    continue;
                for (int a = 0; a < 3; a++)
                    for (int b = 0; b < 3; b++) {
                        int32_t k = c[a], j = c[b];
                        /* (A grid node of its own is not a vertex.) */
                        if (sn->live[k] || !sn->live[j] ||
                            (k >= np->first && k < np->first + np->sides * np->count))
                            continue;
                        vec3 nj = v3(sn->nrm[3 * j], sn->nrm[3 * j + 1], sn->nrm[3 * j + 2]);
                        vec3 o = v3_add(node_pos(sn, j), v3_scale(nj, lift));
                        vec3 w = v3_sub(node_pos(sn, k), o);
                        double len = v3_length(w), t;
                        if (!(len > 0))
                            continue;
                        vec3 d = v3_scale(w, 1.0 / len);
                        int back;
                        rays++;
                        if (first_hit(occ, scene, rs, o, d, len, &back, &t) < 0 ||
                            !(len - t < gap[k]))
                            continue;
                        gap[k] = len - t;
                        to[k] = v3_add(o, v3_scale(d, 0.99 * t));
                    }
            }
    }
    for (int k = 0; k < sn->node_count; k++)
        if (gap[k] < INFINITY) {
            sn->pos[3 * k] = (float)to[k].x;
            sn->pos[3 * k + 1] = (float)to[k].y;
            sn->pos[3 * k + 2] = (float)to[k].z;
            sn->live[k] = 1;
        }
    free(gap);
    free(to);
    return rays;
}

uint64_t node_life_mark(surface_nodes *sn, const occluder_index *occ, const zt_scene *scene,
                        const rscene *rs, int threads)
{
    int *walls = malloc(((size_t)rs->part_count + 1) * sizeof *walls);
    int nw = 0;
    if (walls)
        for (int q = 0; q < rs->part_count; q++)
            if (is_wall(scene, rs, q))
                walls[nw++] = q;
    double h = sn->h, seam = 1e-4 * h;
    uint64_t rays = 0;
    closed_surfaces closed;
    closed_surfaces_find(&closed, scene, rs);
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads) reduction(+ : rays)
    for (int k = 0; k < sn->node_count; k++) {
        if (!sn->live[k])
            continue;
        vec3 x = v3(sn->pos[3 * k], sn->pos[3 * k + 1], sn->pos[3 * k + 2]);
        vec3 n = v3(sn->nrm[3 * k], sn->nrm[3 * k + 1], sn->nrm[3 * k + 2]);
        int prim = sn->prim_of[k];
        rs_part tmp;
        int fore = !rs_prim(rs, prim, &tmp)->background;
        int dead = 0;
        for (int w = 0; w < nw && !dead; w++) {
            const part *pw = &scene->parts[walls[w]];
            if (walls[w] == prim || (fore && scene->objects[pw->object].background))
                continue;
            double s = v3_dot(pw->normal, x) - pw->offset;
            if (s < -seam)
                dead = 1;
            else if (s < seam)
                /* On the seam: lit a quarter cell inside the room, where
                 * the light no longer sees the wall edge-on. */
                x = v3_add(x, v3_scale(pw->normal, seam - s + 0.25 * h));
        }
        if (!dead) {
            /* Inside a closed object most directions meet a back face. */
            vec3 o = v3_add(x, v3_scale(n, 1e-4 * h));
            int inside = 0;
            /* (Until the majority is settled: the same answer.) */
            for (int p = 0; p < PROBES && 2 * inside < PROBES && 2 * (p - inside) <= PROBES;
                 p++) {
                int back = 0;
                int hit = node_life_first_hit(occ, scene, rs, o, probe_dir(n, p), &back);
                rays++;
                /* Only the back of a culled or a closed surface is a wall
                 * nothing passes: the back of an open two-sided one (a
                 * sheet of roof) is a surface like any. */
                rs_part hp;
                inside += hit >= 0 && back &&
                          (rs_prim(rs, hit, &hp)->culled ||
                           closed_surfaces_has(&closed, hit));
            }
            dead = 2 * inside >= PROBES;
        }
        sn->live[k] = (uint8_t)!dead;
        sn->pos[3 * k] = (float)x.x;
        sn->pos[3 * k + 1] = (float)x.y;
        sn->pos[3 * k + 2] = (float)x.z;
    }
    free(walls);
    closed_surfaces_free(&closed);
    return rays + raise_sunk_vertices(sn, occ, scene, rs);
}

float *node_life_reach(const surface_nodes *sn, const rscene *rs)
{
    float *reach = malloc(((size_t)sn->node_count + 1) * sizeof *reach);
    if (!reach)
        return NULL;
    for (int k = 0; k < sn->node_count; k++)
        reach[k] = (float)(0.3 * sn->h);
    for (int mi = 0; mi < sn->mesh_count && mi < rs->mesh_count; mi++) {
        if (sn->vertex_first[mi] < 0)
            continue;
        const mesh *m = rs->meshes[mi].m;
        int sides = rs->meshes[mi].culled ? 1 : 2;
        for (int t = 0; t < m->triangle_count; t++)
            for (int c = 0; c < 3; c++) {
                uint32_t v = m->index[3 * (size_t)t + c];
                uint32_t w = m->index[3 * (size_t)t + (c + 1) % 3];
                float d = f3_length(
                    f3_sub(rs_mesh_vertex(&rs->meshes[mi], v), rs_mesh_vertex(&rs->meshes[mi], w)));
                for (int s = 0; s < sides; s++) {
                    int32_t base = sn->vertex_first[mi] + s * m->vertex_count;
                    reach[base + (int32_t)v] = fmaxf(reach[base + (int32_t)v], d);
                    reach[base + (int32_t)w] = fmaxf(reach[base + (int32_t)w], d);
                }
            }
    }
    return reach;
}
