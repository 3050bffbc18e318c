/* The forest around the light: its frame (nodes, occluders, directions,
 * quality), its zones, and what both phases ask of it. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "light/env_map.h"
#include "render/memory.h"
#include "render/prim.h"
#include "scene/mesh.h"
#include "util/error.h"
#include "util/sampler.h"
#include "util/vec3_convert.h"
#include "geom/ray_offset.h"
#include "zone/light/sky_gather.h"
#include "zone/phase_one/glint.h"
#include "zone/phase_one/specular_targets.h"
#include "zone/transfer/bounce_gather.h"
#include "zone/transfer/cut.h"
#include "zone/zone.h"

int zone_surface_of(const rscene *rs, int prim)
{
    if (prim < rs->part_count)
        return prim;
    const rs_mesh *mm = rs_mesh_of(rs, prim);
    return rs->part_count + rs_mesh_object(mm, prim);
}

int zone_photon_surface(const rscene *rs, int prim)
{
    if (prim < rs->part_count && rs->parts[prim].shape == SHAPE_TRIANGLE)
        return rs->part_count + rs->parts[prim].object;
    return zone_surface_of(rs, prim);
}

static void box_add(vec3 *lo, vec3 *hi, vec3 q)
{
    *lo = v3_min3(*lo, q);
    *hi = v3_max3(*hi, q);
}

/* Whether q, where planes a, b and c meet, is a corner of the room the
 * objects (centred at `centre`) stand in: they are in front of all three,
 * and q is on or in front of every plane of the scene. */
static int inside_corner(const zt_scene *sc, int a, int b, int c, vec3 centre, vec3 q,
                         int finite)
{
    if (!finite)
        return 0;
    const int abc[3] = {a, b, c};
    for (int i = 0; i < 3; i++) {
        const part *p = &sc->parts[abc[i]];
        if (!(v3_dot(p->normal, centre) > p->offset))
            return 0;
    }
    for (int i = 0; i < sc->part_count; i++) {
        const part *p = &sc->parts[i];
        if (p->shape == SHAPE_PLANE && i != a && i != b && i != c &&
            v3_dot(p->normal, q) < p->offset - 1e-6 * (1 + fabs(p->offset)))
            return 0;
    }
    return 1;
}

void zone_scene_bounds(const zt_scene *sc, const rscene *rs, vec3 *lo, vec3 *hi)
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
    for (int k = 0; k < rs->mesh_count; k++) {
        vec3 a, b;
        mesh_bounds(rs->meshes[k].m, &a, &b);
        if (a.x <= b.x) {
            box_add(lo, hi, a);
            box_add(lo, hi, b);
        }
    }
    int finite = lo->x <= hi->x;
    vec3 centre = finite ? v3_scale(v3_add(*lo, *hi), 0.5) : v3(0, 0, 0);
    double reach = finite ? 2.0 * v3_length(v3_sub(*hi, *lo)) + 1e-9 : 1e6;
    /* Rooms made of planes reach past the objects in them: add the corners
     * where three planes meet, unless they lie far away and the objects
     * are not in front of all three (a corner of the room they stand in,
     * however small they are: else its walls fall inside growing cells). */
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
                if (inside_corner(sc, a, b, k, centre, q, finite) ||
                    v3_length(v3_sub(q, centre)) <= reach)
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

zone_quality zone_quality_for(const zt_scene *sc, const rscene *rs, int q)
{
    /* The scene's size (not the camera's: the forest must not depend on
     * it) sets the node spacing; each quality step halves the area per
     * node, doubles the gather directions and refines the transfer. */
    vec3 lo, hi;
    zone_scene_bounds(sc, rs, &lo, &hi);
    double extent = v3_length(v3_sub(hi, lo));
    double step = pow(sqrt(2.0), q);
    zone_quality z;
    memset(&z, 0, sizeof z);
    z.gather = 64 << q;
    z.texel_divisor = 20.0 * step;
    z.texel = extent / z.texel_divisor;
    z.max_texels = (int)(48.0 * step);
    z.sides = 16 << (q / 2);
    z.aa = q < 3 ? 1 : 2;
    z.glint_cuts = 2 << (q / 2);
    z.photons = 131072 << (q < 12 ? q : 12); /* 2^29 at most: an int */
    z.theta = 0.5 / step;
    /* The cut's error bound: at quality 2 (0.01) the Cornell box's level 2 is
     * 2.4% at 128 x 128 for 0.6 s of Phase One (0.02: 3.2%, 0.45 s; 0.005:
     * 2.1%, 0.9 s; a cut to every element: 1.9%, 8 s). */
    z.eps = 0.02 / step;
    z.fallback = 16 << q;
    /* Coverage where an edge crosses a pixel: the grid's counting error
     * along a straight edge (Cornell, 64x64, quality 4: 0.97% with
     * 16 x 16, 0.67% with 32, 0.56% with 64). */
    z.edge_grid = q < 3 ? 16 : q == 3 ? 32 : 64;
    z.edge_shade = q < 4 ? 4 : q == 4 ? 8 : 16;
    /* A regular grid counts a thin surface parallel to one of its
     * diagonals or axes with the same bias in every row; a quasi-random
     * set has no such direction (triangletest at quality 5). */
    z.cover_quasi = q >= 5;
    /* Signatures that look for edges inside smooth-looking pixels (thin
     * lit slivers between shadows: triangletest's level 1 at quality 4
     * went from 6.1% to 0.96% with 8 x 8). */
    z.probe = q < 3 ? z.aa : q == 3 ? 4 : 8;
    /* Gathers on meshes (gather.c): on the engine room at quality 2, 32 a
     * pixel and 2 a sample of its mesh detail's 64 gave 0.894% per pixel,
     * 256 and 4 0.840%.  Fewer below quality 2 would save little (gathers
     * are a sixth of the engine room's Phase Two) and make the image
     * noisy. */
    int qg = q < 2 ? 0 : q > 10 ? 8 : q - 2;
    z.mesh_gather_pixel = 32 << qg;
    z.mesh_gather_sample = 2 << qg / 2;
    /* Rough lobes (rough.c): directions that read the forest, and
     * directions and light samples for level 0, that a pixel shares.  On
     * scenes/cornell_rough.json at 256 x 256 (Phase Two time, per-pixel
     * error on the rough mirror / the rough glass): 32 and 256 2.8 s,
     * 4.6% / 6.4%; 64 and 256 4.3 s, 4.4% / 3.9%; 64 and 1024 7.3 s,
     * 2.7% / 3.9% (the highlight's samples are the cheaper ones). */
    z.rough_pixel = 32 << qg;
    z.rough_light_pixel = 256 << qg;
    z.rough_sample = 1 << qg / 2;
    return z;
}

/* A fixed cosine-weighted direction set: a Hammersley point set through
 * the disk-to-hemisphere map. */
vec3 *zone_gather_directions(int n)
{
    vec3 *d = malloc((size_t)n * sizeof *d);
    if (!d)
        return NULL;
    for (int i = 0; i < n; i++) {
        uint32_t b = sampler_reverse_bits((uint32_t)i);
        double u1 = (i + 0.5) / n, u2 = b * (1.0 / 4294967296.0);
        double r = sqrt(u1), phi = 2 * 3.14159265358979 * u2;
        d[i] = v3(r * cos(phi), r * sin(phi), sqrt(fmax(0.0, 1.0 - u1)));
    }
    return d;
}

zt_status zone_forest_frame(zone_forest *f, const zt_renderer *r, zt_error *err)
{
    const rscene *rs = &r->rs;
    vec3 lo, hi;
    zone_scene_bounds(r->scene, rs, &lo, &hi);
    /* The nodes decide the forest's size: counted first and checked against
     * the memory limit before anything large is allocated. */
    const zt_render_options *o = &r->options;
    int depth = o->level >= 0 ? o->level : o->depth;
    int map_levels = depth >= 2 ? depth : 0; /* as zone_phase_one sets them */
    uint64_t per_node = memory_zone_nodes(1, map_levels);
    const char *source;
    uint64_t limit = memory_limit(o->max_memory, &source);
    uint64_t room = limit > r->memory_estimate ? limit - r->memory_estimate : 0;
    long long wanted = 0;
    uint64_t fit = room / per_node;
    int built = surface_nodes_build(&f->sn, rs, r->scene, f->q.texel, f->q.max_texels, lo, hi,
                                    fit > (uint64_t)LLONG_MAX ? LLONG_MAX : (long long)fit, &wanted);
    if (built < 0) {
        char what[160];
        snprintf(what, sizeof what, "the zone tracer's forest (%lld surface nodes at quality %d, "
                 "depth %d) with the rest of the render", wanted, o->quality, depth);
        if (wanted > INT32_MAX - 1)
            return zt_fail(err, ZT_ERR_MEMORY, "the zone tracer's forest would have %lld surface "
                           "nodes at quality %d, more than 2^31: use a lower quality",
                           wanted, o->quality);
        return memory_check(r->memory_estimate + memory_zone_nodes(wanted, map_levels), what, o,
                            err);
    }
    if (!built)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the surfaces' nodes");
    if (!occluders_build(&f->occ, rs))
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the occluder index");
    f->direct.scene = r->scene;
    f->direct.rs = rs;
    f->direct.occ = &f->occ;
    f->direct.sides = f->q.sides;
    f->direct.fallback = f->q.fallback;
    f->dirs = zone_gather_directions(f->q.gather);
    f->bounce_dirs = bounce_directions(f->q.gather);
    f->glint_spheres = malloc(((size_t)rs->part_count + 1) * sizeof(int));
    if (!f->dirs || !f->bounce_dirs || !f->glint_spheres)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    f->glint_count = 0;
    for (int i = 0; i < rs->part_count; i++)
        if (glint_sphere(rs, i))
            f->glint_spheres[f->glint_count++] = i;
    /* Light by way of mirrors, metal and glass is gathered; diffuse
     * surfaces of every shape are the transfer's. */
    f->need_gather = 0;
    for (int i = 0; i < rs->object_count; i++) {
        const rs_object *o = &rs->objects[i];
        if (!o->is_light && o->weight[LOBE_DIFFUSE] < 1.0f &&
            (o->weight[LOBE_METALLIC] > 0 || o->weight[LOBE_REFLECTING] > 0 ||
             o->weight[LOBE_REFRACTIVE] > 0))
            f->need_gather = 1;
    }
    if (f->need_gather) {
        f->spec_target_count = specular_targets_make(rs, &f->spec_targets, &f->spec_unaimable);
        if (f->spec_target_count < 0)
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    }
    /* Where the scene has specular lobes, the light that the gathers on
     * meshes leave out (caustics, glints) is kept apart in f->c for them
     * to add (phase_one.c). */
    f->specular = 0;
    for (int i = 0; i < rs->object_count; i++) {
        const rs_object *o = &rs->objects[i];
        if (!o->is_light && (o->weight[LOBE_METALLIC] > 0 || o->weight[LOBE_REFLECTING] > 0 ||
                             o->weight[LOBE_REFRACTIVE] > 0))
            f->specular = 1;
    }
    f->sky = !f3_is_black(rs->sky) || rs->distant.map;
    if (!zone_sky_build(f, rs))
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the sky's directions");
    if (f->sky && !sky_portals_build(&f->portals, rs))
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the sky's portals");
    if (rs->distant.sun) {
        /* The sun's disc lies beyond a ball holding the scene (direct.h). */
        int finite = lo.x <= hi.x;
        f->direct.sun_dir = r->scene->sun.direction; /* in double, as written */
        f->direct.sun_sin = sin(0.5 * r->scene->sun.angle);
        f->direct.far_centre = finite ? v3_scale(v3_add(lo, hi), 0.5) : v3(0, 0, 0);
        f->direct.far_radius = finite ? 0.5 * v3_length(v3_sub(hi, lo)) : 1.0;
    }
    if (rs->light_count > ZONE_LIGHTS_EXACT && !sender_tree_build_lights(&f->light_tree, rs))
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the light tree");
    return ZT_OK;
}

void zone_forest_free(zone_forest *f)
{
    free(f->zones);
    surface_nodes_free(&f->sn);
    occluders_free(&f->occ);
    free(f->e);
    free(f->c);
    free(f->caustic);
    photon_map_free(&f->photons);
    free(f->glint_spheres);
    free(f->spec_targets);
    free(f->dirs);
    free(f->bounce_dirs);
    zone_sky_free(f);
    sky_portals_free(&f->portals);
    sender_tree_free(&f->light_tree);
    memset(f, 0, sizeof *f);
}

static vec3 map_read(const zone_forest *f, const float *map, const rscene *rs, int level,
                     int prim, int side, vec3 x)
{
    if (!map || level < 0 || level >= f->map_levels)
        return v3(0, 0, 0);
    int32_t node[4];
    float w[4];
    int n = surface_nodes_weights(&f->sn, rs, prim, side, x, node, w);
    vec3 e = v3(0, 0, 0);
    for (int k = 0; k < n; k++) {
        const float *v = map + ((size_t)level * (size_t)f->sn.node_count + (size_t)node[k]) * 3;
        e = v3_add(e, v3_scale(v3(v[0], v[1], v[2]), w[k]));
    }
    return e;
}

vec3 zone_map_read(const zone_forest *f, const rscene *rs, int level, int prim, int side, vec3 x)
{
    return map_read(f, f->e, rs, level, prim, side, x);
}

vec3 zone_map_read_levels(const zone_forest *f, const rscene *rs, int first, int last, int prim,
                          int side, vec3 x, vec3 e)
{
    if (!f->e || first < 0)
        return e;
    if (last >= f->map_levels)
        last = f->map_levels - 1;
    if (first > last)
        return e;
    int32_t node[4];
    float w[4];
    int n = surface_nodes_weights(&f->sn, rs, prim, side, x, node, w);
    for (int level = first; level <= last; level++) {
        vec3 acc = v3(0, 0, 0);
        for (int k = 0; k < n; k++) {
            const float *v = f->e + ((size_t)level * (size_t)f->sn.node_count + (size_t)node[k]) * 3;
            acc = v3_add(acc, v3_scale(v3(v[0], v[1], v[2]), w[k]));
        }
        e = v3_add(e, acc);
    }
    return e;
}

vec3 zone_specular_map_read(const zone_forest *f, const rscene *rs, int level, int prim,
                            int side, vec3 x)
{
    return map_read(f, f->c, rs, level, prim, side, x);
}

/* The disc a camera path's point reads the photons over: at least
 * PHOTON_MAP_K photons, and at least a pixel's width in radius (what the
 * image can show; narrower, the photons' fine structure shows as noise);
 * at most the nodes' spacing h, beyond which the photons are no sharper
 * than the nodes.  Measured (tests/test_zone_caustic.c at quality 2 as 512
 * pixels over 90 degrees see it; materials.json at 128 x 128 and
 * cornell_rough.json at 256 x 256 against path references): radii of 0.5,
 * 1, 1.5 and 2 pixel widths gave 1.37%, 1.35%, 2.5% and 3.9% on materials
 * (its glass ball's bright focus blurred by the wider ones), 1.48%,
 * 1.45%, 1.42% and 1.42% on cornell_rough. */
#define CAUSTIC_FOOTPRINT 1.0

vec3 zone_caustic_read(const zone_trace *t, int first, int last, int prim, int side, vec3 x,
                       vec3 nf)
{
    const zone_forest *f = t->f;
    const rscene *rs = &t->r->rs;
    vec3 e = v3(0, 0, 0);
    if (!f->caustic)
        return e;
    if (first < 1)
        first = 1;
    if (last >= f->map_levels)
        last = f->map_levels - 1;
    int surface = zone_photon_surface(rs, prim);
    double footprint =
        CAUSTIC_FOOTPRINT * t->pixel_angle * v3_length(v3_sub(x, f3_to_v3(t->eye)));
    for (int level = first; level <= last; level++) {
        vec3 p = photon_map_irradiance(&f->photons, level, surface, x, nf, footprint, f->sn.h);
        e = v3_add(e, v3_sub(p, map_read(f, f->caustic, rs, level, prim, side, x)));
    }
    return e;
}

typedef struct light_leaf_ctx {
    zone_trace *t;
    int receiver;
} light_leaf_ctx;

/* A light element's share of the `whole` that the cut estimates x
 * receives: its irradiance from afar (area x cosines / distance squared
 * at its centroid), unoccluded; 1 where that cannot be told (a sphere or
 * point, x at the element, no whole). */
static double leaf_share(const sender_elem *el, const float em[3], vec3 x, vec3 n, double whole)
{
    if (el->any_way || !(whole > 0))
        return 1.0;
    vec3 w = v3_sub(x, v3(el->c[0], el->c[1], el->c[2]));
    double r2 = v3_dot(w, w);
    if (!(r2 > el->area))
        return 1.0;
    double r = sqrt(r2);
    double ce = (el->n[0] * w.x + el->n[1] * w.y + el->n[2] * w.z) / r;
    double cr = -v3_dot(n, w) / r;
    if (ce <= 0)
        return 0.0;
    if (cr <= 0) {
        /* The centroid below x's horizon: a part of the element above it
         * may still be near and bright. */
        vec3 hi = v3(n.x >= 0 ? el->hi[0] : el->lo[0], n.y >= 0 ? el->hi[1] : el->lo[1],
                     n.z >= 0 ? el->hi[2] : el->lo[2]);
        return v3_dot(n, v3_sub(hi, x)) > 0 ? 1.0 : 0.0;
    }
    return f3_luminance(f3(em[0], em[1], em[2])) * el->area * ce * cr / (r2 * whole);
}

/* One light of the light tree, exactly (the side facing x only), with its
 * share of the point's rays. */
static void light_leaf(void *user, int i, vec3 x, vec3 n, double whole, double acc[3],
                       cut_stats *st)
{
    (void)st;
    const light_leaf_ctx *lc = user;
    const zone_forest *f = lc->t->f;
    const sender_elem *el = &f->light_tree.elems[i];
    if (!el->any_way && (el->n[0] * (x.x - el->c[0]) + el->n[1] * (x.y - el->c[1]) +
                         el->n[2] * (x.z - el->c[2])) <= 0)
        return;
    const float *em = &f->light_tree.elem_radiance[3 * (size_t)i];
    /* (A split point's block shares the pieces: one ray a point already.) */
    int count = lc->t->light_split
                    ? f->direct.fallback
                    : direct_rays_by_share(&f->direct, leaf_share(el, em, x, n, whole));
    vec3 g = direct_irradiance_rays(&f->direct, el->prim, x, n, lc->receiver,
                                    lc->t->light_split, count);
    acc[0] += g.x * em[0];
    acc[1] += g.y * em[1];
    acc[2] += g.z * em[2];
}

/* The sun's direct irradiance at x, exactly (direct.h). */
static vec3 sun_at(zone_trace *t, int receiver, vec3 x, vec3 n)
{
    const rs_distant *d = &t->r->rs.distant;
    if (!d->sun)
        return v3(0, 0, 0);
    vec3 g = direct_irradiance_rgb(&t->f->direct, DIRECT_SUN, x, n, receiver, t->light_split);
    return v3_mul(f3_to_v3(d->sun_radiance), g);
}

vec3 zone_lights_at(zone_trace *t, int receiver, vec3 x, vec3 n)
{
    const rscene *rs = &t->r->rs;
    if (t->f->light_tree.elem_count > 0) {
        light_leaf_ctx lc = {t, receiver};
        cut_params p = {.eps = t->f->q.eps, .max_cut = 4096, .leaf = light_leaf, .user = &lc};
        cut_stats st = {0};
        vec3 e = cut_gather(&t->f->light_tree, rs, x, n, ray_offset(v3_to_f3(x), v3_to_f3(n)),
                            &p, &st, NULL);
        t->rays += st.rays;
        return v3_add(e, sun_at(t, receiver, x, n));
    }
    vec3 e = sun_at(t, receiver, x, n);
    for (int i = 0; i < rs->light_count; i++) {
        int prim = rs->lights[i].part;
        rs_part tmp;
        const rs_part *lp = rs_prim(rs, prim, &tmp);
        vec3f em = rs_emission_mean(rs, prim, &rs->objects[lp->object]);
        if (f3_is_black(em))
            continue;
        vec3 g = direct_irradiance_rgb(&t->f->direct, prim, x, n, receiver, t->light_split);
        e = v3_add(e, v3_mul(f3_to_v3(em), g));
    }
    return e;
}

/* ---- the zones ---- */

static int push_zone(zone_forest *f, zone z)
{
    if (f->zone_count == f->zone_capacity) {
        int cap = f->zone_capacity ? 2 * f->zone_capacity : 256;
        zone *nz = realloc(f->zones, (size_t)cap * sizeof *nz);
        if (!nz)
            return 0;
        f->zones = nz;
        f->zone_capacity = cap;
    }
    f->zones[f->zone_count++] = z;
    return 1;
}

static const int lobe_kind[LOBE_COUNT] = {ZONE_DIFFUSE, ZONE_METALLIC, ZONE_MIRROR,
                                          ZONE_REFRACT};

/* The representative object of a surface. */
static const rs_object *surface_object(const rscene *rs, int s)
{
    return s < rs->part_count ? &rs->objects[rs->parts[s].object]
                              : &rs->objects[s - rs->part_count];
}

/* Whether surface s has any primitive (mesh slots may be unused). */
static void surfaces_present(const rscene *rs, unsigned char *present)
{
    for (int i = 0; i < rs->part_count; i++)
        present[i] = 1;
    for (int k = 0; k < rs->mesh_count; k++) {
        const rs_mesh *mm = &rs->meshes[k];
        for (int t = 0; t < mm->m->triangle_count; t++)
            present[rs->part_count + rs_mesh_object(mm, mm->prim_base + t)] = 1;
    }
}

/* Flux arriving at each surface at each map level: the elements' mean
 * irradiance times their areas. */
static int incident_flux(const zone_forest *f, const rscene *rs, double *flux)
{
    int ns = zone_surface_count(rs);
    for (int prim = 0; prim < f->sn.prim_count; prim++) {
        int ne = surface_element_count(&f->sn, prim);
        if (ne == 0)
            continue;
        int s = zone_surface_of(rs, prim);
        for (int side = 0; side < f->sn.prim[prim].sides; side++)
            for (int e = 0; e < ne; e++) {
                vec3 q[4];
                int32_t node[4];
                int corners = surface_element(&f->sn, rs, prim, side, e, q, node);
                double area = 0;
                for (int k = 1; k + 1 < corners; k++)
                    area += 0.5 * v3_length(v3_cross(v3_sub(q[k], q[0]), v3_sub(q[k + 1], q[0])));
                for (int level = 0; level < f->map_levels; level++) {
                    double sum = 0;
                    int live = 0;
                    for (int k = 0; k < corners; k++)
                        if (node[k] >= 0 && f->sn.live[node[k]]) {
                            const float *v = zone_e(f, level, node[k]);
                            sum += 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
                            live++;
                        }
                    if (live)
                        flux[(size_t)level * ns + s] += sum / live * area;
                }
            }
    }
    return 1;
}

zt_status zone_forest_zones(zone_forest *f, const zt_renderer *r, zt_error *err)
{
    const rscene *rs = &r->rs;
    int depth = r->options.level >= 0 ? r->options.level : r->options.depth;
    double cutoff = r->options.cutoff;
    int ns = zone_surface_count(rs);
    unsigned char *present = calloc((size_t)ns + 1, 1);
    double *flux = calloc((size_t)(f->map_levels + 1) * ns + 1, sizeof *flux);
    double *level_power = calloc((size_t)depth + 2, sizeof *level_power);
    /* The same with the pruned zones' power too: what a level sends at
     * most, whatever the image keeps of it. */
    double *level_sent = calloc((size_t)depth + 2, sizeof *level_sent);
    if (!present || !flux || !level_power || !level_sent) {
        free(present);
        free(flux);
        free(level_power);
        free(level_sent);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the zones");
    }
    surfaces_present(rs, present);
    incident_flux(f, rs, flux);
    /* Surfaces whose last level was left out (meshes: top_gathered) are
     * bounded at the level above it by all the light that level sends,
     * which is no less than what arrives at any one of them: no zone the
     * nodes' flux would keep is lost. */
    unsigned char *gathered = f->top_gathered ? calloc((size_t)ns + 1, 1) : NULL;
    if (f->top_gathered && !gathered) {
        free(present);
        free(flux);
        free(level_power);
        free(level_sent);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the zones");
    }
    for (int prim = rs->part_count; gathered && prim < rs->prim_count; prim++)
        gathered[zone_surface_of(rs, prim)] = 1;
    /* The sky and the sun are no zones, but what they send is light of
     * level 0: as much as all the surfaces could take in. */
    double sky_lum = f3_luminance(rs->sky);
    if (rs->distant.map)
        sky_lum += rs->distant.map->mean_luminance * rs->distant.strength;
    if (rs->distant.sun)
        sky_lum += f3_luminance(rs->distant.sun_radiance) * rs->distant.sun_sin2;
    if (sky_lum > 0) {
        double area = 0;
        for (int i = 0; i < rs->prim_count; i++) {
            rs_part tmp;
            const rs_part *p = rs_prim(rs, i, &tmp);
            area += p->shape == SHAPE_PLANE ? 0 : p->area;
        }
        level_power[0] += sky_lum * 3.14159265358979 * (area > 0 ? area : 1.0);
        if (rs->planes[0].count + rs->planes[1].count > 0)
            level_power[0] = INFINITY; /* an infinite plane under the sky */
    }
    level_sent[0] = level_power[0];
    int ok = 1;
    /* Roots: every light primitive that emits. */
    for (int i = 0; i < rs->light_count && ok; i++) {
        rs_part tmp;
        const rs_part *lp = rs_prim(rs, rs->lights[i].part, &tmp);
        const rs_object *o = &rs->objects[lp->object];
        double area = lp->shape == SHAPE_POINT ? 4.0 : lp->area * (lp->culled ? 1.0 : 2.0);
        zone z = {rs->lights[i].part, ZONE_EMIT, 0,
                  (float)(f3_luminance(rs_emission_mean(rs, rs->lights[i].part, o)) *
                          3.14159265358979 * area)};
        if (!(z.power > 0))
            continue;
        level_sent[0] += z.power;
        if (z.power <= cutoff) {
            f->pruned++;
            continue;
        }
        level_power[0] += z.power;
        ok = push_zone(f, z);
    }
    /* One zone per surface, lobe and level above; a pane's from level 0
     * (the light seen through it). */
    for (int level = 0; level <= depth && ok; level++) {
        for (int s = 0; s < ns && ok; s++) {
            if (!present[s])
                continue;
            const rs_object *o = surface_object(rs, s);
            if (o->is_light)
                continue;
            for (int k = 0; k < LOBE_COUNT && ok; k++) {
                int pane = k == LOBE_REFRACTIVE && o->thin;
                if (o->weight[k] <= 0.0f || (level == 0 && !pane))
                    continue;
                double arriving;
                if (pane)
                    /* It passes its own level on: bounded by the light of
                     * level 0, as every level is. */
                    arriving = level_power[0];
                else if (k != LOBE_DIFFUSE)
                    /* A specular lobe passes on whatever arrives: bounded
                     * by all the light of the level below. */
                    arriving = level_power[level - 1];
                else
                    arriving = gathered && gathered[s] && level == f->map_levels
                                   ? level_sent[level - 1]
                               : level - 1 < f->map_levels ? flux[(size_t)(level - 1) * ns + s]
                                                           : level_power[level - 1];
                zone z = {s, (uint8_t)lobe_kind[k], (uint8_t)level,
                          (float)(arriving * o->weight[k] * f3_max(o->color))};
                if (!(z.power > 0))
                    continue;
                level_sent[level] += z.power;
                if (z.power <= cutoff) {
                    f->pruned++;
                    continue;
                }
                level_power[level] += z.power;
                ok = push_zone(f, z);
            }
        }
    }
    free(present);
    free(flux);
    free(level_power);
    free(level_sent);
    free(gathered);
    if (!ok)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the zones");
    return ZT_OK;
}
