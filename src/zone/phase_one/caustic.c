#include "zone/phase_one/caustic.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "light/distant.h"
#include "light/light_sample.h"
#include "material/bsdf.h"
#include "render/memory.h"
#include "render/prim.h"
#include "scene/mesh.h"
#include "util/error.h"
#include "util/vec3_convert.h"
#include "zone/phase_two/media.h"
#include "zone/phase_one/glint.h"
#include "zone/phase_one/specular_targets.h"
#include "zone/maps/photon_map.h"

#define PI_D 3.14159265358979323846
#define CHUNK 1024        /* photons per work item */
#define MIN_PHOTONS 256   /* per (light, target): a small target still gets a few */
#define BRANCH_MIN 1e-3   /* a branch whose share of its photon's flux falls
                             below this is dropped: glass splits every ray in
                             two, and deep levels would otherwise follow 2^k
                             branches per photon (what is dropped is lost) */
#define LEVEL_MAX 250     /* deposits keep their level in a byte */

/* Flux arriving at one node at one level (a photon's share of it). */
typedef struct deposit {
    int32_t node;
    unsigned char level;
    float flux[3];
} deposit;

typedef struct deposits {
    deposit *d;
    size_t n, cap;
    int failed;
    photon_map photons; /* the same flux as points (photon_map.h) */
} deposits;

/* What a photon stored on a diffuse surface holds at the peak, while the
 * photons are traced: its point and its share on up to four nodes.  The
 * shares are freed before the trees are built, whose copy of the points
 * (and split axis) is smaller. */
#define PHOTON_PEAK_BYTES (sizeof(zone_photon) + 4 * sizeof(deposit))

/* One (light, target) pair, its photon count and the light's emission
 * whether switched off or not. */
typedef struct pair {
    int light, target, photons;
    vec3 emission;
} pair;

/* A run of photons of one pair: the unit of parallel work, whose deposits
 * are kept apart and added in job order (the same sums on any thread
 * count). */
typedef struct job {
    int pair, first, count;
    deposits out;
} job;

typedef struct tracer {
    const zone_forest *f;
    const rscene *rs;
    const specular_target *targets;
    deposits *out;
    uint64_t rays;
    int sun;    /* the sun's photons: glint.c takes lights' images only */
} tracer;

static double radical_inverse(uint32_t i, uint32_t base)
{
    double inv = 1.0 / base, f = inv, r = 0;
    while (i) {
        r += (i % base) * f;
        i /= base;
        f *= inv;
    }
    return r;
}

static void basis(vec3 w, vec3 *t, vec3 *b)
{
    *t = v3_normalize(v3_cross(fabs(w.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0), w));
    *b = v3_cross(w, *t);
}

static void push(deposits *o, deposit dep)
{
    if (o->failed)
        return;
    if (o->n == o->cap) {
        size_t cap = o->cap ? 2 * o->cap : 256;
        deposit *d = realloc(o->d, cap * sizeof *d);
        if (!d) {
            o->failed = 1;
            return;
        }
        o->d = d;
        o->cap = cap;
    }
    o->d[o->n++] = dep;
}

/* Flux arriving at x on a diffuse primitive, side `side`, after `level`
 * specular events: shared among the nodes that interpolate x by their
 * weights (their irradiance grows by their share over their area, below).
 * Splatting onto nodes blurs a caustic by about a node spacing. */
static void deposit_at(tracer *t, int prim, int level, int side, vec3 x, vec3 nf, vec3 flux)
{
    if (level >= t->f->map_levels)
        return;
    const surface_nodes *sn = &t->f->sn;
    if (prim >= sn->prim_count || sn->prim[prim].first < 0)
        return;
    if (side >= sn->prim[prim].sides)
        side = sn->prim[prim].sides - 1;
    int32_t node[4];
    float w[4];
    int n = surface_nodes_weights(sn, t->rs, prim, side, x, node, w);
    for (int k = 0; k < n; k++)
        push(t->out, (deposit){node[k], (unsigned char)level,
                               {(float)(flux.x * w[k]), (float)(flux.y * w[k]),
                                (float)(flux.z * w[k])}});
    zone_photon ph = {{(float)x.x, (float)x.y, (float)x.z},
                      {(float)flux.x, (float)flux.y, (float)flux.z},
                      zone_photon_surface(t->rs, prim),
                      {(int8_t)lrint(127.0 * nf.x), (int8_t)lrint(127.0 * nf.y),
                       (int8_t)lrint(127.0 * nf.z)},
                      (uint8_t)level};
    if (!t->out->failed && !photon_map_add(&t->out->photons, &ph))
        t->out->failed = 1;
}


static void follow(tracer *t, vec3f o, vec3f d, vec3 flux, double share, int k,
                   int glint, const specular_target *first, const int *media, int media_count);

/* A photon's flux leaving the rough lobes of part p's material m at xf (nf
 * facing it); sh: the hit's shading when it is known already (NULL: made
 * here). */
static void rough_on(tracer *t, const rs_part *p, int part, const rs_object *m,
                     const rs_shade *known, vec3f xf, vec3f nf, vec3f d, vec3 flux, double share,
                     int k, const int *media, int media_count)
{
    const rscene *rs = t->rs;
    float eta_i, eta_t;
    int entering = media_indices(rs, media, media_count, p->object, m, &eta_i, &eta_t);
    rs_shade own; /* its mat is filled only when the maps give it */
    own.ns = nf;
    own.albedo = m->color;
    own.m = NULL;
    if (!known && rs_needs_shade(rs, part, m))
        rs_shade_at(rs, part, p, m, xf, nf, &own);
    const rs_shade *sh = known ? known : &own;
    zone_rough_at at = {m,     part,  xf,       nf,         sh->ns, f3_to_v3(sh->albedo), d,
                        eta_i, eta_t, p->object, entering, media, media_count, 0.0f};
    vec3f wi, value;
    if (!zone_rough_scatter(&at, &wi, &value))
        return;
    int through = f3_dot(wi, nf) < 0.0f;
    /* Flux crosses the surface without the radiance's (eta_i/eta_t)^2. */
    if (through)
        value = f3_scale(value, (eta_t / eta_i) * (eta_t / eta_i));
    vec3 tint = v3_mul(at.color, f3_to_v3(value));
    vec3 out = v3_mul(flux, tint);
    double sp = share * v3_max(tint);
    if (sp < BRANCH_MIN)
        return;
    if (!through) {
        follow(t, ray_offset(xf, nf), wi, out, sp, k + 1, 0, NULL, media, media_count);
        return;
    }
    int next[MEDIA_MAX];
    int nc = media_cross(media, media_count, p->object, entering, next);
    follow(t, ray_offset(xf, f3_neg(nf)), wi, out, sp, k + 1, 0, NULL, next, nc);
}

/* Follows flux along (o, d) after k specular events.  `first`: the part
 * the ray must hit first (-1: any).  `glint`: the path so far is one
 * reflection off the outside of a glint sphere, which glint.c accounts for
 * when it lands on a texel. */
static void follow(tracer *t, vec3f o, vec3f d, vec3 flux, double share, int k,
                   int glint, const specular_target *first, const int *media, int media_count)
{
    const rscene *rs = t->rs;
    hit h = accel_intersect(rs, o, d);
    t->rays++;
    if (h.part < 0)
        return;
    rs_part tmp;
    const rs_part *p = rs_prim(rs, h.part, &tmp);
    if (first && !specular_target_hit(rs, first, h.part)) {
        /* A pane before the target (a window in front of a glass vase) is
         * crossed, as direct light crosses it; anything else hides the
         * target. */
        const rs_object *pm = &rs->objects[p->object];
        if (!pm->thin || p->is_light)
            return;
        vec3f xp = shape_hit_point(p, o, d, h.t), np = shape_normal(p, xp);
        if (f3_dot(np, d) > 0.0f)
            np = f3_neg(np);
        vec3 pass = v3_scale(f3_to_v3(pm->tint),
                             pm->weight[LOBE_REFRACTIVE] *
                                 (1.0 - bsdf_pane_reflectance(-f3_dot(np, d), pm->ior)));
        double sp = share * v3_max(pass);
        if (sp >= BRANCH_MIN)
            follow(t, ray_offset(xp, f3_neg(np)), d, v3_mul(flux, pass), sp, k, glint, first,
                   media, media_count);
        return;
    }
    if (p->is_light)
        return;
    const rs_object *m = &rs->objects[p->object];
    vec3f xf = shape_hit_point(p, o, d, h.t);
    vec3f ngf = shape_normal(p, xf);
    int back = f3_dot(ngf, d) > 0.0f;
    vec3f nf = back ? f3_neg(ngf) : ngf;
    /* Coverage c < 1 (alpha): 1 - c of the flux goes on undeviated at the
     * same count of events (as through a pane, direct light after none),
     * the rest meets the surface. */
    if (__builtin_expect(m->alpha_mode != 0, 0)) {
        float c = rs_coverage_at(rs, h.part, p, m, xf);
        if (c < 1.0f) {
            double sp = share * (1.0 - c);
            if (k >= 1 && sp >= BRANCH_MIN)
                follow(t, ray_offset(xf, f3_neg(nf)), d, v3_scale(flux, 1.0 - c), sp, k, 0, NULL,
                       media, media_count);
            flux = v3_scale(flux, c);
            share *= c;
        }
    }
    /* A material with maps: its weights and roughness here (the smooth
     * lobes below keep the geometric normal). */
    rs_shade sh; /* its mat is filled only when the maps give it */
    sh.ns = nf;
    sh.albedo = m->color;
    sh.m = NULL;
    const rs_shade *known = NULL;
    if (m->maps) {
        rs_shade_at(rs, h.part, p, m, xf, nf, &sh);
        m = rs_shade_material(&sh, m);
        known = &sh;
    }
    vec3 color = f3_to_v3(m->color);
    if (k >= 1 && !glint && m->weight[LOBE_DIFFUSE] > 0.0f)
        deposit_at(t, h.part, k, back, f3_to_v3(xf), f3_to_v3(nf), flux);
    double cmax = v3_max(color);
    if (m->thin) {
        /* A pane passes flux on undeviated and at the same count of
         * events: after none, that is direct light, which the direct
         * light's rays see through the pane already. */
        float cos_p = -f3_dot(nf, d);
        vec3 pass = v3_scale(f3_to_v3(m->tint),
                             m->weight[LOBE_REFRACTIVE] * (1.0 - bsdf_pane_reflectance(cos_p, m->ior)));
        double sp = share * v3_max(pass);
        if (k >= 1 && sp >= BRANCH_MIN)
            follow(t, ray_offset(xf, f3_neg(nf)), d, v3_mul(flux, pass), sp, k, 0, NULL, media,
                   media_count);
    }
    /* The next surface would receive k + 1 events: only while a map level
     * is left for it. */
    if (k + 1 >= t->f->map_levels || k + 1 > LEVEL_MAX)
        return;
    /* Rough lobes send the photon on in one direction drawn from them
     * (zone_rough_scatter), the smooth ones below the rest. */
    if (m->rough)
        rough_on(t, p, h.part, m, known, xf, nf, d, flux, share, k, media, media_count);
    float wm = bsdf_smooth_weight(m, LOBE_METALLIC), wr = bsdf_smooth_weight(m, LOBE_REFLECTING);
    float wt = bsdf_smooth_weight(m, LOBE_REFRACTIVE);
    if (wm <= 0.0f && wr <= 0.0f && wt <= 0.0f)
        return;
    /* The same lobes and weights as zone_radiance, seen from the light's
     * side (Fresnel and Schlick are reciprocal). */
    float cos_o = -f3_dot(nf, d);
    vec3f refl = f3_normalize(f3_sub(d, f3_scale(nf, 2.0f * f3_dot(d, nf))));
    double k_refl = wr, k_tran = 0;
    if (wm > 0.0f)
        k_refl += wm * bsdf_schlick(cos_o, m->ior);
    float eta_i, eta_t;
    int entering = media_indices(rs, media, media_count, p->object, m, &eta_i, &eta_t);
    if (wt > 0.0f && m->thin) {
        k_refl += wt * bsdf_pane_reflectance(cos_o, m->ior);
    } else if (wt > 0.0f) {
        float fr = bsdf_fresnel_dielectric(cos_o, eta_i, eta_t);
        k_refl += wt * fr;
        k_tran = wt * (1.0 - fr);
    }
    if (k_refl > 0 && share * k_refl * cmax >= BRANCH_MIN) {
        int g = k == 0 && !back && media_count == 0 && !t->sun && glint_sphere(rs, h.part);
        follow(t, ray_offset(xf, nf), refl, v3_scale(v3_mul(flux, color), k_refl),
               share * k_refl * cmax, k + 1, g, NULL, media, media_count);
    }
    if (k_tran > 0 && share * k_tran * cmax >= BRANCH_MIN) {
        float eta = eta_i / eta_t;
        vec3f tr = media_refract(d, nf, cos_o, eta);
        int next[MEDIA_MAX];
        int nc = media_cross(media, media_count, p->object, entering, next);
        /* Flux crosses the surface less what it reflects: no eta^2 here.
         * The radiance convention's eta^2 (zone_radiance) is what radiance
         * gains as flux is squeezed into a smaller solid angle; a photon
         * carries flux, so its gain shows as a denser splat instead. */
        follow(t, ray_offset(xf, f3_neg(nf)), tr, v3_scale(v3_mul(flux, color), k_tran),
               share * k_tran * cmax, k + 1, 0, NULL, next, nc);
    }
}

/* Photon i of n from the sun toward a target: a direction within the sun's
 * disc (bases 2, 3) and a point of the target's cross-section, a disc of
 * its bounding sphere's radius across the sun's axis (bases 5, 7), the ray
 * starting beyond every finite primitive.  Flux = radiance x cos to the
 * axis x the disc's area x the sun's solid angle / n. */
static void shoot_sun(tracer *t, const pair *pr, int i)
{
    const rs_distant *sd = &t->rs->distant;
    const specular_target *tg = &t->targets[pr->target];
    uint32_t h = (uint32_t)i + 1;
    const float u[2] = {(float)radical_inverse(h, 2), (float)radical_inverse(h, 3)};
    double u3 = radical_inverse(h, 5), u4 = radical_inverse(h, 7);
    vec3 w = f3_to_v3(distant_sun_direction(sd, u)), axis = f3_to_v3(sd->sun_dir);
    double rho = tg->r * sqrt(u3), phi = 2.0 * PI_D * u4;
    vec3 p = v3_add(tg->c, v3_add(v3_scale(f3_to_v3(sd->sun_t), rho * cos(phi)),
                                  v3_scale(f3_to_v3(sd->sun_b), rho * sin(phi))));
    const direct_ctx *dc = &t->f->direct;
    double back = v3_length(v3_sub(p, dc->far_centre)) + dc->far_radius + tg->r + 1.0;
    double cos_axis = v3_dot(w, axis);
    if (!(cos_axis > 0))
        return;
    double scale = cos_axis * PI_D * tg->r * tg->r * 2.0 * PI_D * sd->sun_one_minus_cos /
                   pr->photons;
    vec3 flux = v3_scale(pr->emission, scale);
    follow(t, v3_to_f3(v3_add(p, v3_scale(w, back))), v3_to_f3(v3_scale(w, -1.0)), flux, 1.0,
           0, 0, tg, NULL, 0);
}

/* Photon i of n of a pair (the sun's: shoot_sun): a point on the light (a triangle uniformly; a
 * sphere over the cap that can see the target) and a direction towards the
 * target (uniform in a sphere's cone, or to a uniform point of a
 * triangle), from the 4-d Halton set (bases 2, 3 for the direction, what
 * shapes a caustic; 5, 7 for the point).  Not Hammersley: its (i/n, base
 * 2) pair is a near-regular grid, which the lens maps onto the fine cells
 * as moire (errors of 6% at 2^19 photons where 2^18 gave 2%).  Flux =
 * radiance x cos at the light x light area x (cone solid angle, or a
 * triangle's area-to-solid-angle factor) / n. */
static void shoot(tracer *t, const pair *pr, int i)
{
    if (pr->light == DIRECT_SUN) {
        shoot_sun(t, pr, i);
        return;
    }
    const rscene *rs = t->rs;
    const specular_target *tg = &t->targets[pr->target];
    rs_part ltmp;
    const rs_part *lp = rs_prim(rs, pr->light, &ltmp);
    const rs_part *tp = tg->part >= 0 ? &rs->parts[tg->part] : NULL;
    int n = pr->photons;
    uint32_t h = (uint32_t)i + 1;
    double u1 = radical_inverse(h, 2), u2 = radical_inverse(h, 3);
    double u3 = radical_inverse(h, 5), u4 = radical_inverse(h, 7);
    vec3 ct = tg->c;
    double rt = tg->r;
    vec3 y, ny;
    double area;
    if (lp->shape == SHAPE_TRIANGLE) {
        double su = sqrt(u3);
        y = v3_add(f3_to_v3(lp->p0), v3_add(v3_scale(f3_to_v3(lp->e1), su * (1 - u4)),
                                            v3_scale(f3_to_v3(lp->e2), su * u4)));
        ny = f3_to_v3(lp->n);
        area = lp->area;
    } else {
        /* Light points whose normal makes cos < (r_l - r_t) / D with the
         * axis to the target's centre cannot see the target: the cap
         * beyond is all that is sampled. */
        vec3 cl = f3_to_v3(lp->p0), w0 = v3_sub(ct, cl), a, b;
        double dist = v3_length(w0), rl = lp->radius;
        w0 = v3_scale(w0, 1.0 / dist);
        double cmin = fmax(-1.0, fmin(1.0, (rl - rt) / dist));
        double z = 1.0 - u3 * (1.0 - cmin), s = sqrt(fmax(0.0, 1.0 - z * z));
        basis(w0, &a, &b);
        ny = v3_add(v3_scale(w0, z), v3_add(v3_scale(a, s * cos(2 * PI_D * u4)),
                                            v3_scale(b, s * sin(2 * PI_D * u4))));
        y = v3_add(cl, v3_scale(ny, rl));
        area = 2.0 * PI_D * rl * rl * (1.0 - cmin);
    }
    vec3 w;
    double g;
    if (!tp || tp->shape == SHAPE_SPHERE) {
        vec3 to = v3_sub(ct, y), a, b;
        double dist = v3_length(to);
        if (dist <= rt)
            return;
        double omc = specular_cone_omc(rt, dist);
        double z = 1.0 - u1 * omc, s = sqrt(fmax(0.0, u1 * omc * (2.0 - u1 * omc)));
        vec3 axis = v3_scale(to, 1.0 / dist);
        basis(axis, &a, &b);
        w = v3_add(v3_scale(axis, z), v3_add(v3_scale(a, s * cos(2 * PI_D * u2)),
                                             v3_scale(b, s * sin(2 * PI_D * u2))));
        g = 2.0 * PI_D * omc;
    } else {
        double su = sqrt(u1);
        vec3 zp = v3_add(f3_to_v3(tp->p0), v3_add(v3_scale(f3_to_v3(tp->e1), su * (1 - u2)),
                                                   v3_scale(f3_to_v3(tp->e2), su * u2)));
        vec3 to = v3_sub(zp, y);
        double d2 = v3_dot(to, to);
        if (!(d2 > 1e-12))
            return;
        w = v3_scale(to, 1.0 / sqrt(d2));
        g = fabs(v3_dot(f3_to_v3(tp->n), w)) * tp->area / d2;
    }
    double cy = v3_dot(ny, w);
    vec3 side = ny;
    if (cy < 0 && lp->shape == SHAPE_TRIANGLE && !lp->culled) {
        cy = -cy; /* a two-sided light emits from its back too */
        side = v3_scale(ny, -1);
    }
    if (!(cy > 0))
        return;
    vec3f wf = v3_to_f3(w);
    /* A switched-off light's photons carry no flux but are traced all the
     * same, with its emission as the flux that chooses the windows: the
     * windows, and so the images of single lights, add up. */
    if (lp->culled && f3_dot(shape_normal(lp, v3_to_f3(y)), f3_neg(wf)) >= 0.0f)
        return;
    vec3f le = light_emitted(rs, pr->light, lp, v3_to_f3(y), f3_neg(wf));
    double scale = cy * g * area / n;
    vec3 flux = v3_scale(f3_to_v3(le), scale);
    follow(t, ray_offset(v3_to_f3(y), v3_to_f3(side)), wf, flux, 1.0, 0, 0, tg, NULL, 0);
}

/* Whether light primitive lp (number prim) sends photons. */
static int sends_photons(const rscene *rs, int prim, const rs_part *lp)
{
    return lp->is_light && (lp->shape == SHAPE_TRIANGLE || lp->shape == SHAPE_SPHERE) &&
           f3_max(rs_emission_mean(rs, prim, &rs->objects[lp->object])) > 0;
}

/* A target's colour and specular weight (a mesh: its brightest slot). */
static double target_catch(const rscene *rs, const specular_target *tg)
{
    double best = 0;
    int first = tg->part >= 0 ? rs->parts[tg->part].object : rs->meshes[tg->mesh].object_base;
    int count = tg->part >= 0 ? 1 : rs->meshes[tg->mesh].m->slot_count;
    for (int s = 0; s < count; s++) {
        const rs_object *m = &rs->objects[first + s];
        double c = f3_max(m->color) *
                   (m->weight[LOBE_REFLECTING] + m->weight[LOBE_METALLIC] + m->weight[LOBE_REFRACTIVE]);
        best = fmax(best, c);
    }
    return best;
}

/* Photons per pair: each light's budget shared by how much of its light
 * each target can catch (solid angle from the light's centre x specular
 * weight x colour), at least MIN_PHOTONS.  A light's budget is q.photons
 * for up to LIGHTS_FULL lights; past that, LIGHTS_FULL budgets are shared
 * among them all, and the floor drops to FLOOR_MANY when the pairs would
 * take more than the total: a mesh light of thousands of triangles must
 * not take thousands of times the photons. */
#define LIGHTS_FULL 8
#define FLOOR_MANY 16
static int make_pairs(const zone_forest *f, const rscene *rs, const specular_target *tg, int targets,
                      pair **out)
{
    int lights = rs->distant.sun ? 1 : 0;
    for (int j = 0; j < rs->light_count; j++) {
        rs_part tmp;
        lights += sends_photons(rs, rs->lights[j].part, rs_prim(rs, rs->lights[j].part, &tmp));
    }
    double total_budget = (double)f->q.photons * (lights < LIGHTS_FULL ? lights : LIGHTS_FULL);
    double light_budget = lights ? total_budget / lights : 0;
    int floor_n = (double)lights * targets * MIN_PHOTONS <= total_budget ? MIN_PHOTONS : FLOOR_MANY;
    int cap = 16, count = 0;
    pair *ps = malloc((size_t)cap * sizeof *ps);
    double *imp = malloc((size_t)(targets + 1) * sizeof *imp);
    if (!ps || !imp) {
        free(ps);
        free(imp);
        return -1;
    }
    /* The lights, then the sun (a light number of its own). */
    for (int j = 0; j <= rs->light_count; j++) {
        int sun = j == rs->light_count;
        if (sun && !rs->distant.sun)
            break;
        int li = sun ? DIRECT_SUN : rs->lights[j].part;
        rs_part tmp;
        const rs_part *lp = sun ? NULL : rs_prim(rs, li, &tmp);
        if (!sun && !sends_photons(rs, li, lp))
            continue;
        vec3 em = sun ? f3_to_v3(rs->distant.sun_radiance)
                      : f3_to_v3(rs_emission_mean(rs, li, &rs->objects[lp->object]));
        vec3 cl = v3(0, 0, 0);
        double rl = 0, total = 0;
        if (!sun)
            part_bounding_sphere(lp, &cl, &rl);
        for (int i = 0; i < targets; i++) {
            imp[i] = 0;
            if (tg[i].part == li)
                continue;
            double c = target_catch(rs, &tg[i]);
            if (c <= 0)
                continue;
            /* What the target catches of the light: the solid angle it
             * fills seen from the light, or its cross-section in the sun. */
            double dist = v3_length(v3_sub(tg[i].c, cl));
            double omega = sun ? PI_D * tg[i].r * tg[i].r
                           : dist <= tg[i].r + rl ? 2.0 * PI_D
                                                  : 2.0 * PI_D * specular_cone_omc(tg[i].r, dist);
            imp[i] = omega * c;
            total += imp[i];
        }
        for (int i = 0; i < targets && total > 0; i++) {
            if (imp[i] <= 0)
                continue;
            if (count == cap) {
                cap *= 2;
                pair *np = realloc(ps, (size_t)cap * sizeof *np);
                if (!np) {
                    free(ps);
                    free(imp);
                    return -1;
                }
                ps = np;
            }
            double share = light_budget * imp[i] / total;
            int n = share < floor_n ? floor_n : (int)(share + 0.5);
            ps[count++] = (pair){li, i, n, em};
        }
    }
    free(imp);
    *out = ps;
    return count;
}

/* Each live node's share of the surface: a corner's share of every element
 * it is a corner of (its dual area). */
static double *node_areas(const surface_nodes *sn, const rscene *rs)
{
    double *a = calloc((size_t)sn->node_count + 1, sizeof *a);
    if (!a)
        return NULL;
    for (int prim = 0; prim < sn->prim_count; prim++) {
        int ne = surface_element_count(sn, prim);
        for (int side = 0; side < sn->prim[prim].sides; side++)
            for (int e = 0; e < ne; e++) {
                vec3 q[4];
                int32_t node[4];
                int corners = surface_element(sn, rs, prim, side, e, q, node);
                double area = 0;
                for (int k = 1; k + 1 < corners; k++)
                    area += 0.5 * v3_length(v3_cross(v3_sub(q[k], q[0]), v3_sub(q[k + 1], q[0])));
                for (int k = 0; k < corners; k++)
                    if (node[k] >= 0)
                        a[node[k]] += area / corners;
            }
    }
    return a;
}

/* Splatting a photon onto the nodes that interpolate its point, then
 * interpolating the nodes again in Phase Two, blurs a caustic twice: a
 * lumped-mass estimate.  A few Jacobi steps towards the consistent one
 * (the field whose interpolation has the deposits' moments: M e = b, with
 * M the elements' mass matrix) take most of that blur back; the light is
 * kept non-negative.  b: the deposited flux per node (one channel), e:
 * in, b / area; out, the sharpened irradiance. */
#define SHARPEN_STEPS 1
static void sharpen(const surface_nodes *sn, const rscene *rs, const double *area,
                    const double *b, double *e, double *me)
{
    size_t n = (size_t)sn->node_count;
    for (int step = 0; step < SHARPEN_STEPS; step++) {
        memset(me, 0, n * sizeof *me);
        for (int prim = 0; prim < sn->prim_count; prim++) {
            int ne = surface_element_count(sn, prim);
            for (int side = 0; side < sn->prim[prim].sides; side++)
                for (int el = 0; el < ne; el++) {
                    vec3 q[4];
                    int32_t node[4];
                    int c = surface_element(sn, rs, prim, side, el, q, node);
                    double a = 0, any = 0;
                    for (int k = 0; k < c; k++)
                        any += node[k] >= 0 && b[node[k]] != 0;
                    if (any == 0)
                        continue;
                    for (int k = 1; k + 1 < c; k++)
                        a += 0.5 * v3_length(v3_cross(v3_sub(q[k], q[0]), v3_sub(q[k + 1], q[0])));
                    for (int i = 0; i < c; i++) {
                        if (node[i] < 0)
                            continue;
                        double sum = 0;
                        for (int j = 0; j < c; j++) {
                            if (node[j] < 0)
                                continue;
                            /* Linear triangles: A/12 (2 on the diagonal);
                             * bilinear quads: A/36 (4, 2 beside, 1 across). */
                            double m = c == 3 ? (i == j ? 2.0 : 1.0) / 12.0
                                              : (i == j ? 4.0 : (i - j + 4) % 2 ? 2.0 : 1.0) / 36.0;
                            sum += m * e[node[j]];
                        }
                        me[node[i]] += a * sum;
                    }
                }
        }
        for (size_t i = 0; i < n; i++)
            if (area[i] > 0 && b[i] != 0) {
                double v = e[i] + (b[i] - me[i]) / area[i];
                e[i] = v > 0 ? v : 0;
            }
    }
}

zt_status caustic_build(zone_forest *f, const zt_renderer *r, zt_error *err)
{
    const rscene *rs = &r->rs;
    if (f->map_levels < 2)
        return ZT_OK;
    specular_target *targets = NULL;
    int ntargets = specular_targets_make(rs, &targets, NULL);
    if (ntargets < 0)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics");
    if (ntargets == 0) {
        free(targets);
        return ZT_OK;
    }
    pair *pairs = NULL;
    int npairs = make_pairs(f, rs, targets, ntargets, &pairs);
    if (npairs < 0) {
        free(targets);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics");
    }
    int njobs = 0;
    for (int k = 0; k < npairs; k++)
        njobs += (pairs[k].photons + CHUNK - 1) / CHUNK;
    job *jobs = calloc((size_t)njobs + 1, sizeof *jobs);
    double *acc = calloc((size_t)f->map_levels * f->sn.node_count * 3 + 3, sizeof *acc);
    double *area = node_areas(&f->sn, rs);
    if (!jobs || !acc || !area) {
        free(targets);
        free(pairs);
        free(jobs);
        free(acc);
        free(area);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics");
    }
    /* Their memory, checked before they are traced, taking one photon
     * stored per photon traced (measured 0.40 on materials.json, 0.91 on
     * cornell_rough.json), and while they are: glass that splits them can
     * store more (1.44 under a glass ball in the sun).  Past the limit the
     * render stops; no light is dropped to fit. */
    uint64_t traced = 0;
    for (int k = 0; k < npairs; k++)
        traced += (uint64_t)pairs[k].photons;
    uint64_t base = r->memory_estimate + memory_zone_nodes(f->sn.node_count, f->map_levels);
    f->photon_estimate = traced * PHOTON_PEAK_BYTES;
    char what[200];
    snprintf(what, sizeof what, "the zone tracer's forest with its caustic photons (%llu traced at "
             "quality %d) and the rest of the render", (unsigned long long)traced,
             r->options.quality);
    zt_status st = memory_check(base + f->photon_estimate, what, &r->options, err);
    if (st != ZT_OK) {
        free(targets);
        free(pairs);
        free(jobs);
        free(acc);
        free(area);
        return st;
    }
    const char *source;
    uint64_t limit = memory_limit(r->options.max_memory, &source);
    uint64_t room = (limit - base) / PHOTON_PEAK_BYTES; /* photons that fit */
    for (int k = 0; k < npairs; k++)
        f->sun_photons |= pairs[k].light == DIRECT_SUN;
    njobs = 0;
    for (int k = 0; k < npairs; k++)
        for (int first = 0; first < pairs[k].photons; first += CHUNK) {
            int left = pairs[k].photons - first;
            jobs[njobs++] = (job){.pair = k, .first = first, .count = left < CHUNK ? left : CHUNK};
        }
    uint64_t rays = 0, stored = 0;
    int over = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(render_thread_count(r->options.threads)) \
    reduction(+ : rays)
    for (int k = 0; k < njobs; k++) {
        int stop;
#pragma omp atomic read
        stop = over;
        if (stop)
            continue;
        tracer t = {f, rs, targets, &jobs[k].out, 0, pairs[jobs[k].pair].light == DIRECT_SUN};
        for (int i = 0; i < jobs[k].count && !stop; i++) {
            shoot(&t, &pairs[jobs[k].pair], jobs[k].first + i);
            if (i % 64 == 63 || i == jobs[k].count - 1) {
                /* The other jobs' finished photons and this one's: no more
                 * than all of them, so the stop does not depend on timing. */
                uint64_t done;
#pragma omp atomic read
                done = stored;
                stop = done + jobs[k].out.photons.count > room;
            }
        }
        if (stop) {
#pragma omp atomic write
            over = 1;
        }
#pragma omp atomic
        stored += jobs[k].out.photons.count;
        /* Kept until every job is done: no room to spare. */
        photon_map *ph = &jobs[k].out.photons;
        zone_photon *fit = ph->count ? realloc(ph->p, ph->count * sizeof *fit) : NULL;
        if (fit) {
            ph->p = fit;
            ph->capacity = ph->count;
        }
        rays += t.rays;
    }
    f->rays += rays;
    if (over) {
        char a[32], b[32];
        st = zt_fail(err, ZT_ERR_MEMORY, "the zone tracer's caustic photons at quality %d outgrew "
                     "the %s of memory left under the limit of %s (%s): glass splits photons, and "
                     "more were stored than the %llu traced that the estimate counts; use a "
                     "lower quality or a higher limit",
                     r->options.quality, memory_format(limit - base, a, sizeof a),
                     memory_format(limit, b, sizeof b), source, (unsigned long long)traced);
    }
    /* Sums in job order, in double precision, then onto the nodes. */
    int failed = over;
    for (int k = 0; k < njobs && !failed; k++) {
        const deposits *o = &jobs[k].out;
        failed = o->failed;
        for (size_t i = 0; i < o->n && !failed; i++) {
            const deposit *d = &o->d[i];
            double a = area[d->node];
            if (!(a > 0))
                continue;
            double *px = acc + ((size_t)d->level * f->sn.node_count + (size_t)d->node) * 3;
            for (int c = 0; c < 3; c++)
                px[c] += d->flux[c] / a;
        }
    }
    /* Per level and channel: b (flux per node) and the sharpened field. */
    size_t nn = (size_t)f->sn.node_count;
    double *b = failed ? NULL : malloc(3 * (nn + 1) * sizeof *b);
    if (!failed && !b)
        failed = 1;
    for (int lv = 0; lv < f->map_levels && !failed; lv++)
        for (int c = 0; c < 3; c++) {
            double *e = b + nn + 1, *me = b + 2 * (nn + 1);
            double *px = acc + (size_t)lv * nn * 3;
            int any = 0;
            for (size_t i = 0; i < nn; i++) {
                e[i] = px[3 * i + c];
                b[i] = e[i] * area[i];
                any |= e[i] != 0;
            }
            if (!any)
                continue;
            sharpen(&f->sn, rs, area, b, e, me);
            for (size_t i = 0; i < nn; i++)
                px[3 * i + c] = e[i];
        }
    free(b);
    if (!failed) {
        size_t n = (size_t)f->map_levels * f->sn.node_count * 3;
        for (size_t i = 0; i < n; i++)
            f->e[i] += (float)acc[i];
        /* The photons as points, in job order, and what the nodes took
         * of them: a camera sample reads the one instead of the other
         * (zone_caustic_read). */
        f->caustic = malloc((n + 3) * sizeof *f->caustic);
        failed = !f->caustic;
        for (size_t i = 0; i < n && !failed; i++)
            f->caustic[i] = (float)acc[i];
        for (int k = 0; k < njobs && !failed; k++) {
            free(jobs[k].out.d); /* room for the photons' trees */
            jobs[k].out.d = NULL;
        }
        if (!failed) {
            /* photon_map_build takes a run of maps: the jobs' are apart. */
            photon_map *parts = malloc((size_t)njobs * sizeof *parts + 1);
            failed = !parts;
            for (int k = 0; k < njobs && !failed; k++)
                parts[k] = jobs[k].out.photons;
            if (!failed) {
                failed = !photon_map_build(&f->photons, parts, njobs, f->map_levels,
                                           rs->part_count + rs->object_count);
                for (int k = 0; k < njobs; k++)
                    jobs[k].out.photons = parts[k];
            }
            free(parts);
        }
        if (!failed && f->photons.count == 0) {
            /* None reached a diffuse surface: nothing to read apart. */
            free(f->caustic);
            f->caustic = NULL;
        }
    }
    for (int k = 0; k < njobs; k++) {
        free(jobs[k].out.d);
        photon_map_free(&jobs[k].out.photons);
    }
    free(acc);
    free(area);
    free(jobs);
    free(pairs);
    free(targets);
    if (over)
        return st;
    return failed ? zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics") : ZT_OK;
}
