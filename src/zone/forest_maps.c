/* Phase One, the light: irradiance maps of every diffuse surface, level by
 * level.  Level 0 (direct light) is exact at every texel; level k >= 1
 * gathers the level-k radiance arriving at the texel over a fixed set of
 * cosine-distributed directions, the same set for every texel, so what error
 * remains varies smoothly over a surface instead of appearing as noise. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "util/error.h"
#include "util/vec3_convert.h"
#include "zone/caustic.h"
#include "zone/glint.h"
#include "zone/map_layout.h"
#include "zone/refine.h"
#include "zone/transfer.h"
#include "zone/zone_internal.h"

static void box_add(vec3 *lo, vec3 *hi, vec3 q)
{
    *lo = v3(fmin(lo->x, q.x), fmin(lo->y, q.y), fmin(lo->z, q.z));
    *hi = v3(fmax(hi->x, q.x), fmax(hi->y, q.y), fmax(hi->z, q.z));
}

void forest_scene_bounds(const zt_scene *sc, vec3 *lo, vec3 *hi)
{
    *lo = v3(1e300, 1e300, 1e300);
    *hi = v3(-1e300, -1e300, -1e300);
    for (int i = 0; i < sc->part_count; i++) {
        const part *p = &sc->parts[i];
        if (p->shape == SHAPE_TRIANGLE) {
            for (int k = 0; k < 3; k++)
                box_add(lo, hi, p->p[k]);
        } else if (p->shape == SHAPE_SPHERE) {
            box_add(lo, hi, v3_sub(p->p[0], v3(p->radius, p->radius, p->radius)));
            box_add(lo, hi, v3_add(p->p[0], v3(p->radius, p->radius, p->radius)));
        } else if (p->shape == SHAPE_POINT) {
            box_add(lo, hi, p->p[0]);
        }
    }
    int finite = lo->x <= hi->x;
    vec3 centre = finite ? v3_scale(v3_add(*lo, *hi), 0.5) : v3(0, 0, 0);
    double reach = finite ? 2.0 * v3_length(v3_sub(*hi, *lo)) + 1e-9 : 1e6;
    /* Rooms made of planes reach past the objects in them: add the corners
     * where three planes meet, unless they lie far away. */
    vec3 add_lo = *lo, add_hi = *hi;
    for (int a = 0; a < sc->part_count; a++) {
        const part *pa = &sc->parts[a];
        for (int b = a + 1; b < sc->part_count && pa->shape == SHAPE_PLANE; b++) {
            const part *pb = &sc->parts[b];
            for (int k = b + 1; k < sc->part_count && pb->shape == SHAPE_PLANE; k++) {
                const part *pc = &sc->parts[k];
                if (pc->shape != SHAPE_PLANE)
                    continue;
                vec3 bc = v3_cross(pb->normal, pc->normal);
                double det = v3_dot(pa->normal, bc);
                if (fabs(det) < 1e-9)
                    continue;
                /* Cramer's rule for the point on all three planes. */
                vec3 q = v3_scale(v3_add(v3_add(v3_scale(bc, pa->offset),
                                                v3_scale(v3_cross(pc->normal, pa->normal), pb->offset)),
                                         v3_scale(v3_cross(pa->normal, pb->normal), pc->offset)),
                                  1.0 / det);
                if (v3_length(v3_sub(q, centre)) <= reach)
                    box_add(&add_lo, &add_hi, q);
            }
        }
    }
    *lo = add_lo;
    *hi = add_hi;
    if (lo->x > hi->x) {
        /* Nothing finite and no corners: a unit box at the origin. */
        *lo = v3(-1, -1, -1);
        *hi = v3(1, 1, 1);
    }
}

/* A fixed cosine-weighted direction set: a Hammersley point set through
 * the disk-to-hemisphere map. */
vec3 *forest_gather_directions(int n)
{
    vec3 *d = malloc((size_t)n * sizeof *d);
    if (!d)
        return NULL;
    for (int i = 0; i < n; i++) {
        uint32_t b = (uint32_t)i;
        b = (b << 16) | (b >> 16);
        b = ((b & 0x55555555u) << 1) | ((b & 0xAAAAAAAAu) >> 1);
        b = ((b & 0x33333333u) << 2) | ((b & 0xCCCCCCCCu) >> 2);
        b = ((b & 0x0F0F0F0Fu) << 4) | ((b & 0xF0F0F0F0u) >> 4);
        b = ((b & 0x00FF00FFu) << 8) | ((b & 0xFF00FF00u) >> 8);
        double u1 = (i + 0.5) / n, u2 = b * (1.0 / 4294967296.0);
        double r = sqrt(u1), phi = 2 * 3.14159265358979 * u2;
        d[i] = v3(r * cos(phi), r * sin(phi), sqrt(fmax(0.0, 1.0 - u1)));
    }
    return d;
}

static void frame(vec3 n, vec3 *t, vec3 *b)
{
    vec3 a = fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0);
    *t = v3_normalize(v3_cross(a, n));
    *b = v3_cross(n, *t);
}


vec3 forest_lights_at(zone_trace *t, int part_index, vec3 x, vec3 n)
{
    const rscene *rs = &t->r->rs;
    vec3 e = v3(0, 0, 0);
    for (int i = 0; i < rs->part_count; i++) {
        const rs_part *lp = &rs->parts[i];
        if (!lp->is_light || f3_is_black(rs->objects[lp->object].emission))
            continue;
        vec3f em = rs->objects[lp->object].emission;
        double g = direct_irradiance(&t->f->direct, i, x, n, part_index);
        e = v3_add(e, v3_scale(v3(em.x, em.y, em.z), g));
    }
    return e;
}

/* One texel of one level and side. */
static vec3 texel_value(zone_trace *t, const zone_forest *f, int part_index, int level,
                        vec3 x, vec3 n, const vec3 *dirs, double theta)
{
    const rscene *rs = &t->r->rs;
    vec3 e = v3(0, 0, 0);
    if (level == 0) {
        e = forest_lights_at(t, part_index, x, n);
        if (f3_is_black(rs->sky))
            return e;
    } else {
        /* Flat diffuse surfaces by exact transfer over their maps; lights
         * in mirror spheres by their images. */
        e = transfer_irradiance(t, part_index, x, n, level, theta);
        if (level == 1 && f->glint_count)
            e = v3_add(e, glint_irradiance(t, f->glint_spheres, f->glint_count, x, n,
                                           f->q.glint_cuts));
        if (!f->need_gather)
            return e;
    }
    /* The rest by gathering: E = pi * mean radiance over cosine-distributed
     * directions, counting only what the transfer left out (the sky at
     * level 0; specular surfaces and spheres above). */
    vec3 tt, bb;
    frame(n, &tt, &bb);
    vec3f o = ray_offset(v3_to_f3(x), v3_to_f3(n));
    vec3 sum = v3(0, 0, 0);
    /* Each direction stands for a cone of solid angle about 2 pi / N. */
    t->cone = (float)sqrt(2.0 / f->q.gather);
    for (int k = 0; k < f->q.gather; k++) {
        vec3 d = v3_add(v3_add(v3_scale(tt, dirs[k].x), v3_scale(bb, dirs[k].y)),
                        v3_scale(n, dirs[k].z));
        vec3 l;
        if (level == 0) {
            hit h = accel_intersect(rs, o, v3_to_f3(d));
            t->rays++;
            l = h.part < 0 ? v3(rs->sky.x, rs->sky.y, rs->sky.z) : v3(0, 0, 0);
        } else {
            l = zone_radiance(t, o, v3_to_f3(v3_normalize(d)), level, level,
                              ZR_SKIP_FLAT_DIFFUSE | ZR_NO_GLINT | ZR_NO_CAUSTIC, NULL, 0);
        }
        sum = v3_add(sum, l);
    }
    t->cone = 0.0f;
    return v3_add(e, v3_scale(sum, 3.14159265358979 / f->q.gather));
}

/* Whether a texel centre lies on a surface light can reach: from inside a
 * closed object, or from outside a room of culled walls, most directions
 * first meet the back of a culled surface. */
static float texel_weight(const rscene *rs, int own, vec3 x, vec3 n, const vec3 *dirs, int ndirs)
{
    vec3 t, b;
    frame(n, &t, &b);
    vec3f o = ray_offset(v3_to_f3(x), v3_to_f3(n));
    int inside = 0, step = ndirs / 8 > 0 ? ndirs / 8 : 1, count = 0;
    for (int k = 0; k < ndirs; k += step) {
        vec3 dd = v3_add(v3_add(v3_scale(t, dirs[k].x), v3_scale(b, dirs[k].y)), v3_scale(n, dirs[k].z));
        vec3f d = v3_to_f3(v3_normalize(dd));
        float best = 1e30f;
        int hit_part = -1;
        for (int i = 0; i < rs->part_count; i++) {
            if (i == own)
                continue;
            rs_part p = rs->parts[i];
            p.culled = 0;
            float th = shape_hit(&p, o, d, 0.0f, best);
            if (th > 0.0f) {
                best = th;
                hit_part = i;
            }
        }
        count++;
        if (hit_part >= 0) {
            const rs_part *p = &rs->parts[hit_part];
            vec3f hn = shape_normal(p, f3_madd(o, d, best));
            if (p->culled && f3_dot(hn, d) > 0.0f)
                inside++;
        }
    }
    return 2 * inside >= count ? 0.0f : 1.0f;
}

/* The sky's share of E_0: cosine-distributed directions that escape. */
static vec3 sky_texel(zone_trace *t, const zone_forest *f, vec3 x, vec3 n, const vec3 *dirs)
{
    const rscene *rs = &t->r->rs;
    vec3 tt, bb;
    frame(n, &tt, &bb);
    vec3f o = ray_offset(v3_to_f3(x), v3_to_f3(n));
    int open = 0;
    for (int k = 0; k < f->q.gather; k++) {
        vec3 d = v3_add(v3_add(v3_scale(tt, dirs[k].x), v3_scale(bb, dirs[k].y)),
                        v3_scale(n, dirs[k].z));
        hit h = accel_intersect(rs, o, v3_to_f3(d));
        t->rays++;
        open += h.part < 0;
    }
    return v3_scale(v3(rs->sky.x, rs->sky.y, rs->sky.z), 3.14159265358979 * open / f->q.gather);
}

vec3 forest_direct_at(zone_trace *t, int part_index, vec3 x, vec3 n)
{
    vec3 e = forest_lights_at(t, part_index, x, n);
    if (t->f->sky_slot >= 0)
        e = v3_add(e, sky_texel(t, t->f, x, n, t->f->dirs));
    return e;
}

vec3 forest_sky_irradiance(zone_trace *t, vec3 x, vec3 n)
{
    return sky_texel(t, t->f, x, n, t->f->dirs);
}

/* How much coarser the transfer into texel (u, j) may be: the square root
 * of how many times wider it is than the core's texels.  A texel far out on
 * a plane stands for a large area that matters little; the full width
 * ratio measured 3.5% instead of 3.0% at level 3 of the Cornell box, the
 * square root 3.1%, and demo's Phase One 5.3 s, 6.6 s (30-90 s without). */
static double texel_growth(const part_map *m, int u, int j)
{
    const map_layout *l = &m->layout;
    if (l->shape == SHAPE_SPHERE)
        return 1.0;
    double gu = (axis_edge(&l->au, u + 1) - axis_edge(&l->au, u)) * l->au.len / l->au.w;
    double gv = (axis_edge(&l->av, j + 1) - axis_edge(&l->av, j)) * l->av.len / l->av.w;
    return sqrt(fmax(1.0, fmax(gu, gv)));
}

/* A texel whose centre is unreachable (under an object standing on the
 * surface) may still be partly lit: it then takes its value at the
 * reachable one of a 4 x 4 set of points inside it nearest their centroid.
 * Returns whether one was found. */
static int texel_rescue(const rscene *rs, part_map *m, int own, int u, int j, int side,
                        const vec3 *dirs, int ndirs)
{
    const map_layout *l = &m->layout;
    double s0 = axis_edge(&l->au, u), s1 = axis_edge(&l->au, u + 1);
    double t0 = axis_edge(&l->av, j), t1 = axis_edge(&l->av, j + 1);
    vec3 n = v3_normalize(v3_cross(l->du, l->dv));
    if (side)
        n = v3_scale(n, -1);
    double ss[16], ts[16], cs = 0, ct = 0;
    int found = 0;
    for (int b = 0; b < 4; b++)
        for (int a = 0; a < 4; a++) {
            double s = s0 + (a + 0.5) / 4 * (s1 - s0), t = t0 + (b + 0.5) / 4 * (t1 - t0);
            vec3 x = map_point(l, s, t);
            int inside = 1;
            for (int k = 0; k < l->clips && inside; k++)
                inside = v3_dot(l->clip_n[k], x) + l->clip_d[k] >= 0;
            if (!inside || texel_weight(rs, own, x, n, dirs, ndirs) <= 0)
                continue;
            ss[found] = s, ts[found] = t;
            cs += s, ct += t;
            found++;
        }
    if (!found)
        return 0;
    cs /= found, ct /= found;
    int best = 0;
    for (int k = 1; k < found; k++)
        if (hypot((ss[k] - cs) * l->au.len, (ts[k] - ct) * l->av.len) <
            hypot((ss[best] - cs) * l->au.len, (ts[best] - ct) * l->av.len))
            best = k;
    float *st = m->eval_st + 2 * (((size_t)side * l->nv + j) * l->nu + u);
    st[0] = (float)ss[best];
    st[1] = (float)ts[best];
    return 1;
}

zt_status forest_build_maps(zone_forest *f, const zt_renderer *r, zt_error *err)
{
    const zt_scene *sc = r->scene;
    int depth = r->options.level >= 0 ? r->options.level : r->options.depth;
    /* Pixel level L reads E_{L-1}; level 1 is exact, so maps are needed
     * from depth 2 on, and then all of E_0 .. E_{depth-1}. */
    f->map_levels = depth >= 2 ? depth : 0;
    f->maps = calloc((size_t)sc->part_count + 1, sizeof(part_map));
    if (!f->maps)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
    f->map_count = sc->part_count;
    /* The sky's direct light has no closed form: it gets a level of its
     * own, gathered, which the camera's level 1 reads. */
    f->sky_slot = f3_is_black(r->rs.sky) ? -1 : f->map_levels;
    if (f->map_levels == 0 && f->sky_slot < 0)
        return ZT_OK;
    vec3 lo, hi;
    forest_scene_bounds(sc, &lo, &hi);
    /* Planes are mapped far beyond this core (plane_layout): open rooms
     * (the Cornell box has no front wall) send light out that comes back. */
    map_walls walls = {malloc(((size_t)sc->part_count + 1) * sizeof(int)), 0};
    if (!walls.part)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
    walls.count = map_layout_walls(sc, walls.part);
    for (int i = 0; i < sc->part_count; i++) {
        const object *o = &sc->objects[sc->parts[i].object];
        if (o->is_light || o->mat.weight[LOBE_DIFFUSE] <= 0)
            continue;
        part_map *m = &f->maps[i];
        map_layout_part(sc, &walls, i, lo, hi, f->q.texel, f->q.max_texels, f->q.edge_grade,
                        &m->layout);
        m->levels = f->map_levels + (f->sky_slot >= 0);
        size_t n = (size_t)m->levels * (size_t)m->layout.sides * (size_t)m->layout.nu *
                   (size_t)m->layout.nv * 3;
        m->texels = calloc(n, sizeof(float));
        m->weight[0] = calloc((size_t)m->layout.sides * m->layout.nu * m->layout.nv, sizeof(float));
        if (!m->texels || !m->weight[0] || !map_layout_cache(&m->layout) || !map_build_cover(m)) {
            free(walls.part);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
        }
        /* Where other triangles pierce it, its texels are cut in two. */
        map_crossing cross[MAP_CROSSINGS];
        int nc = map_layout_crossings(sc, i, cross, MAP_CROSSINGS);
        if (nc > 0) {
            m->cross = malloc((size_t)nc * sizeof *m->cross);
            if (!m->cross) {
                free(walls.part);
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
            }
            memcpy(m->cross, cross, (size_t)nc * sizeof *m->cross);
            m->crossings = nc;
            if (!map_build_cuts(m)) {
                free(walls.part);
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
            }
        }
    }
    free(walls.part);
    f->blockers = transfer_blockers_build(sc);
    vec3 *dirs = forest_gather_directions(f->q.gather);
    f->dirs = dirs;
    if (!dirs || !f->blockers)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    /* Gathers are needed for what transfer does not cover: light arriving
     * from specular surfaces or diffuse spheres. */
    f->need_gather = 0;
    f->glint_spheres = malloc(((size_t)r->rs.part_count + 1) * sizeof(int));
    if (!f->glint_spheres)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    f->glint_count = 0;
    for (int i = 0; i < r->rs.part_count; i++)
        if (glint_sphere(&r->rs, i))
            f->glint_spheres[f->glint_count++] = i;
    for (int i = 0; i < sc->part_count; i++) {
        const object *o = &sc->objects[sc->parts[i].object];
        if (o->is_light)
            continue;
        if (o->mat.weight[LOBE_DIFFUSE] < 1.0 || sc->parts[i].shape == SHAPE_SPHERE)
            f->need_gather = 1;
    }
    for (int i = 0; i < sc->part_count; i++) {
        part_map *m = &f->maps[i];
        if (!m->texels)
            continue;
        int rows = m->layout.nv * m->layout.sides;
#pragma omp parallel for schedule(dynamic, 1) num_threads(render_thread_count(r->options.threads))
        for (int row = 0; row < rows; row++) {
            int side = row / m->layout.nv, j = row % m->layout.nv;
            for (int u = 0; u < m->layout.nu; u++) {
                vec3 x, n;
                map_texel_eval_point(m, u, j, side, &x, &n);
                float w = m->cover[(size_t)j * m->layout.nu + u] <= 0
                              ? 0.0f
                              : texel_weight(&r->rs, i, x, n, dirs, f->q.gather);
                if (w <= 0 && m->cover[(size_t)j * m->layout.nu + u] > 0 &&
                    texel_rescue(&r->rs, m, i, u, j, side, dirs, f->q.gather))
                    w = 1.0f;
                m->weight[0][((size_t)side * m->layout.nv + j) * m->layout.nu + u] = w;
                size_t k = (size_t)j * m->layout.nu + u;
                if (m->crossings && m->cut[k] >= 0) {
                    /* The other half of a cut texel: reachable at its own
                     * point, on its own side of the crossing (a rescued
                     * point may have moved over: then the texel is whole). */
                    vec3 xa, na;
                    map_texel_alt_point(m, u, j, side, &xa, &na);
                    map_texel_eval_point(m, u, j, side, &x, &n);
                    const map_crossing *c = &m->cross[m->cut[k]];
                    int main_sign = v3_dot(c->n, x) - c->d > 0 ? 1 : -1;
                    m->alt_weight[(size_t)side * m->layout.nv * m->layout.nu + k] =
                        main_sign == m->alt_sign[k] ? 0.0f : texel_weight(&r->rs, i, xa, na, dirs, f->q.gather);
                }
            }
        }
    }
    /* Light by way of specular surfaces, traced from the lights into the
     * texels of levels 1 and up; the level loop below adds the rest. */
    zt_status cst = caustic_build(f, r, err);
    if (cst != ZT_OK)
        return cst;
    int threads = render_thread_count(r->options.threads);
    uint64_t rays = 0;
    int last = f->sky_slot >= 0 ? f->sky_slot : f->map_levels - 1;
    for (int level = 0; level <= last; level++) {
        /* One work item per texel row of every map and side. */
        for (int i = 0; i < sc->part_count; i++) {
            part_map *m = &f->maps[i];
            if (!m->texels)
                continue;
            int rows = m->layout.nv * m->layout.sides;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : rays)
            for (int row = 0; row < rows; row++) {
                zone_trace t = {f, r, 0, 0.0f};
                int side = row / m->layout.nv, j = row % m->layout.nv;
                for (int u = 0; u < m->layout.nu; u++) {
                    vec3 x, n;
                    map_texel_eval_point(m, u, j, side, &x, &n);
                    /* Texels off the reachable surface (outside the room,
                     * inside objects) are never read: no need to light them. */
                    int reachable = m->weight[0][((size_t)side * m->layout.nv + j) * m->layout.nu + u] > 0;
                    vec3 e = !reachable             ? v3(0, 0, 0)
                             : level == f->sky_slot ? sky_texel(&t, f, x, n, dirs)
                                                    : texel_value(&t, f, i, level, x, n, dirs,
                                                                  f->q.theta * texel_growth(m, u, j));
                    float *px = map_texel(m, level, side, u, j);
                    px[0] += (float)e.x; /* onto the caustics (caustic.c) */
                    px[1] += (float)e.y;
                    px[2] += (float)e.z;
                    size_t k = (size_t)j * m->layout.nu + u;
                    if (m->crossings && m->cut[k] >= 0) {
                        size_t ka = (size_t)side * m->layout.nv * m->layout.nu + k;
                        vec3 ea = v3(0, 0, 0);
                        if (m->alt_weight[ka] > 0) {
                            map_texel_alt_point(m, u, j, side, &x, &n);
                            ea = level == f->sky_slot ? sky_texel(&t, f, x, n, dirs)
                                                      : texel_value(&t, f, i, level, x, n, dirs,
                                                                    f->q.theta * texel_growth(m, u, j));
                        }
                        float *pa = m->alt + (((size_t)level * m->layout.sides) * m->layout.nv * m->layout.nu + ka) * 3;
                        pa[0] = (float)ea.x;
                        pa[1] = (float)ea.y;
                        pa[2] = (float)ea.z;
                    }
                }
                rays += t.rays;
            }
            if (!map_build_mips(m, level) || !transfer_build_tables(m, level)) {
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
            }
        }
        /* Before the next level sends from this one. */
        if (level != f->sky_slot && !refine_level(f, r, level))
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
    }
    f->rays += rays;
    refine_drop_level0(f);
    if (!caustic_finish(f))
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for maps");
    /* What only the transfer needed goes: Phase Two reads texels, weights
     * and their coarser copies, as a forest read from a file does. */
    for (int i = 0; i < sc->part_count; i++)
        map_free_phase_one(&f->maps[i]);
    return ZT_OK;
}

void forest_free(zone_forest *f)
{
    if (f->maps)
        for (int i = 0; i < f->map_count; i++)
            map_free(&f->maps[i]);
    free(f->maps);
    free(f->dirs);
    free(f->glint_spheres);
    transfer_blockers_free(f->blockers);
    free(f->zones);
    free(f->occluders);
}
