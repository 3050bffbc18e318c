#include "zone/caustic.h"

#include <omp.h>
#include <stdlib.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "light/light_sample.h"
#include "material/bsdf.h"
#include "util/error.h"
#include "util/vec3_convert.h"
#include "zone/media.h"
#include "zone/glint.h"

#define PI_D 3.14159265358979323846
#define CHUNK 1024        /* photons per work item */
#define MIN_PHOTONS 256   /* per (light, target): a small target still gets a few */
#define DETAIL_SUB 4      /* fine cells per texel side where a caustic is
                             concentrated: texels above DETAIL_FRACTION of
                             the level's brightest caustic texel that got
                             DETAIL_PHOTONS per fine cell (fewer make a fine
                             grid blotchy); at most DETAIL_MAX texels in the
                             window around them, else the texels hold it */
#define DETAIL_FRACTION 0.02
#define DETAIL_PHOTONS 16
#define DETAIL_MAX 4096
#define BRANCH_MIN 1e-3   /* a branch whose share of its photon's flux falls
                             below this is dropped: glass splits every ray in
                             two, and deep levels would otherwise follow 2^k
                             branches per photon (what is dropped is lost) */
#define LEVEL_MAX 250     /* deposits keep their level in a byte */

int caustic_target(const rscene *rs, int i)
{
    const rs_part *p = &rs->parts[i];
    if (p->is_light || (p->shape != SHAPE_TRIANGLE && p->shape != SHAPE_SPHERE))
        return 0;
    const rs_object *m = &rs->objects[p->object];
    return m->weight[LOBE_REFLECTING] > 0.0f || m->weight[LOBE_METALLIC] > 0.0f ||
           m->weight[LOBE_REFRACTIVE] > 0.0f;
}

/* Flux arriving in texel (i, j) of a part's map, at one level and side,
 * in fine cell (su, sv) of that texel. */
typedef struct deposit {
    int part, i, j;
    unsigned char level, side, su, sv;
    float flux[3];
    float dec;          /* what the windows are chosen by (make_pairs) */
} deposit;

typedef struct deposits {
    deposit *d;
    size_t n, cap;
    int failed;
} deposits;

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
    deposits *out;
    uint64_t rays;
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

/* 1 - cos of the half-angle of a sphere of radius r seen from distance
 * d > r, without cancellation for small cones. */
static double cone_omc(double r, double d)
{
    double s2 = (r / d) * (r / d);
    return s2 < 1e-3 ? 0.5 * s2 + 0.125 * s2 * s2 : 1.0 - sqrt(fmax(0.0, 1.0 - s2));
}

/* A sphere around a triangle or sphere part. */
static void bounding_sphere(const rs_part *p, vec3 *c, double *r)
{
    if (p->shape == SHAPE_SPHERE) {
        *c = f3_to_v3(p->p0);
        *r = p->radius;
        return;
    }
    vec3 a = f3_to_v3(p->p0), b = v3_add(a, f3_to_v3(p->e1)), d = v3_add(a, f3_to_v3(p->e2));
    *c = v3_scale(v3_add(v3_add(a, b), d), 1.0 / 3.0);
    *r = fmax(v3_length(v3_sub(a, *c)), fmax(v3_length(v3_sub(b, *c)), v3_length(v3_sub(d, *c))));
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

/* Area of texel (i, j) that lies on the surface (a planar texel's cover). */
static double texel_area(const part_map *m, int i, int j)
{
    const map_layout *l = &m->layout;
    if (l->shape == SHAPE_SPHERE) {
        double t0 = PI_D * j / l->nv, t1 = PI_D * (j + 1) / l->nv;
        return l->radius * l->radius * (cos(t0) - cos(t1)) * 2.0 * PI_D / l->nu;
    }
    double s = axis_edge(&l->au, i + 1) - axis_edge(&l->au, i);
    double t = axis_edge(&l->av, j + 1) - axis_edge(&l->av, j);
    return v3_length(v3_cross(l->du, l->dv)) * s * t * m->cover[(size_t)j * l->nu + i];
}

/* Flux arriving at x on a mapped part, side `side`, after `level` specular
 * events: its texel's irradiance grows by flux / texel area (and, where
 * the caustic is concentrated, a fine cell's by flux / cell area).
 * Splatting into cells blurs a caustic by a cell. */
static void deposit_at(tracer *t, int part, int level, int side, vec3 x, vec3 flux, vec3 dflux)
{
    const part_map *m = &t->f->maps[part];
    const map_layout *l = &m->layout;
    if (!m->texels || level >= t->f->map_levels)
        return;
    if (side >= l->sides)
        side = l->sides - 1;
    double u, v;
    map_coords(l, x, &u, &v);
    int i = (int)floor(u + 0.5), j = (int)floor(v + 0.5);
    if (l->shape == SHAPE_SPHERE)
        i = ((i % l->nu) + l->nu) % l->nu;
    else
        i = i < 0 ? 0 : i >= l->nu ? l->nu - 1 : i;
    j = j < 0 ? 0 : j >= l->nv ? l->nv - 1 : j;
    int su = 0, sv = 0;
    if (l->shape != SHAPE_SPHERE) {
        su = (int)floor((u + 0.5 - i) * DETAIL_SUB);
        sv = (int)floor((v + 0.5 - j) * DETAIL_SUB);
        su = su < 0 ? 0 : su >= DETAIL_SUB ? DETAIL_SUB - 1 : su;
        sv = sv < 0 ? 0 : sv >= DETAIL_SUB ? DETAIL_SUB - 1 : sv;
    }
    push(t->out, (deposit){part, i, j, (unsigned char)level, (unsigned char)side,
                           (unsigned char)su, (unsigned char)sv,
                           {(float)flux.x, (float)flux.y, (float)flux.z},
                           (float)v3_max(dflux)});
}

/* Follows flux along (o, d) after k specular events.  `first`: the part
 * the ray must hit first (-1: any).  `glint`: the path so far is one
 * reflection off the outside of a glint sphere, which glint.c accounts for
 * when it lands on a texel. */
static void follow(tracer *t, vec3f o, vec3f d, vec3 flux, vec3 dflux, double share, int k,
                   int glint, int first, const int *media, int media_count)
{
    const rscene *rs = t->rs;
    hit h = accel_intersect(rs, o, d);
    t->rays++;
    if (h.part < 0 || (first >= 0 && h.part != first))
        return;
    const rs_part *p = &rs->parts[h.part];
    if (p->is_light)
        return;
    const rs_object *m = &rs->objects[p->object];
    vec3f xf = f3_madd(o, d, h.t);
    vec3f ngf = shape_normal(p, xf);
    int back = f3_dot(ngf, d) > 0.0f;
    vec3f nf = back ? f3_neg(ngf) : ngf;
    vec3 color = f3_to_v3(m->color);
    if (k >= 1 && !glint && m->weight[LOBE_DIFFUSE] > 0.0f)
        deposit_at(t, h.part, k, back, f3_to_v3(xf), flux, dflux);
    /* The next surface would receive k + 1 events: only while a map level
     * is left for it. */
    if (k + 1 >= t->f->map_levels || k + 1 > LEVEL_MAX)
        return;
    float wm = m->weight[LOBE_METALLIC], wr = m->weight[LOBE_REFLECTING];
    float wt = m->weight[LOBE_REFRACTIVE];
    if (wm <= 0.0f && wr <= 0.0f && wt <= 0.0f)
        return;
    /* The same lobes and weights as zone_radiance, seen from the light's
     * side (Fresnel and Schlick are reciprocal). */
    float cos_o = -f3_dot(nf, d);
    vec3f refl = f3_normalize(f3_sub(d, f3_scale(nf, 2.0f * f3_dot(d, nf))));
    double k_refl = wr, k_tran = 0;
    if (wm > 0.0f)
        k_refl += wm * bsdf_schlick(cos_o, m->ior);
    int entering = media_count == 0 || media[media_count - 1] != p->object;
    float eta_i = media_count ? rs->objects[media[media_count - 1]].ior : 1.0f;
    float eta_t = entering ? m->ior : (media_count > 1 ? rs->objects[media[media_count - 2]].ior : 1.0f);
    if (wt > 0.0f) {
        float fr = bsdf_fresnel_dielectric(cos_o, eta_i, eta_t);
        k_refl += wt * fr;
        k_tran = wt * (1.0 - fr);
    }
    double cmax = v3_max(color);
    if (k_refl > 0 && share * k_refl * cmax >= BRANCH_MIN) {
        int g = k == 0 && !back && media_count == 0 && glint_sphere(rs, h.part);
        follow(t, ray_offset(xf, nf), refl, v3_scale(v3_mul(flux, color), k_refl),
               v3_scale(v3_mul(dflux, color), k_refl), share * k_refl * cmax, k + 1, g, -1, media,
               media_count);
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
               v3_scale(v3_mul(dflux, color), k_tran), share * k_tran * cmax, k + 1, 0, -1, next,
               nc);
    }
}

/* Photon i of n of a pair: a point on the light (a triangle uniformly; a
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
    const rscene *rs = t->rs;
    const rs_part *lp = &rs->parts[pr->light], *tp = &rs->parts[pr->target];
    int n = pr->photons;
    uint32_t h = (uint32_t)i + 1;
    double u1 = radical_inverse(h, 2), u2 = radical_inverse(h, 3);
    double u3 = radical_inverse(h, 5), u4 = radical_inverse(h, 7);
    vec3 ct;
    double rt;
    bounding_sphere(tp, &ct, &rt);
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
    if (tp->shape == SHAPE_SPHERE) {
        vec3 to = v3_sub(ct, y), a, b;
        double dist = v3_length(to);
        if (dist <= rt)
            return;
        double omc = cone_omc(rt, dist);
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
    vec3f le = light_emitted(rs, lp, v3_to_f3(y), f3_neg(wf));
    double scale = cy * g * area / n;
    vec3 flux = v3_scale(f3_to_v3(le), scale), dflux = v3_scale(pr->emission, scale);
    follow(t, ray_offset(v3_to_f3(y), v3_to_f3(side)), wf, flux, dflux, 1.0, 0, 0, pr->target,
           NULL, 0);
}

/* Whether light part li sends photons. */
static int sends_photons(const zt_scene *sc, const rs_part *lp)
{
    return lp->is_light && (lp->shape == SHAPE_TRIANGLE || lp->shape == SHAPE_SPHERE) &&
           v3_max(sc->objects[lp->object].emission) > 0;
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
static int make_pairs(const zone_forest *f, const zt_scene *sc, const rscene *rs, pair **out)
{
    int lights = 0;
    for (int li = 0; li < rs->part_count; li++)
        lights += sends_photons(sc, &rs->parts[li]);
    int targets = 0;
    for (int i = 0; i < rs->part_count; i++)
        targets += caustic_target(rs, i);
    double total_budget = (double)f->q.photons * (lights < LIGHTS_FULL ? lights : LIGHTS_FULL);
    double light_budget = lights ? total_budget / lights : 0;
    int floor_n = (double)lights * targets * MIN_PHOTONS <= total_budget ? MIN_PHOTONS : FLOOR_MANY;
    int cap = 16, count = 0;
    pair *ps = malloc((size_t)cap * sizeof *ps);
    double *imp = malloc((size_t)(rs->part_count + 1) * sizeof *imp);
    if (!ps || !imp) {
        free(ps);
        free(imp);
        return -1;
    }
    for (int li = 0; li < rs->part_count; li++) {
        const rs_part *lp = &rs->parts[li];
        vec3 em = sc->objects[lp->object].emission;
        if (!sends_photons(sc, lp))
            continue;
        vec3 cl, ct;
        double rl, rt, total = 0;
        bounding_sphere(lp, &cl, &rl);
        for (int i = 0; i < rs->part_count; i++) {
            imp[i] = 0;
            if (i == li || !caustic_target(rs, i))
                continue;
            const rs_object *m = &rs->objects[rs->parts[i].object];
            double c = f3_max(m->color);
            if (c <= 0)
                continue;
            bounding_sphere(&rs->parts[i], &ct, &rt);
            double dist = v3_length(v3_sub(ct, cl));
            double omega = dist <= rt + rl ? 2.0 * PI_D : 2.0 * PI_D * cone_omc(rt, dist);
            imp[i] = omega * c *
                     (m->weight[LOBE_REFLECTING] + m->weight[LOBE_METALLIC] + m->weight[LOBE_REFRACTIVE]);
            total += imp[i];
        }
        for (int i = 0; i < rs->part_count && total > 0; i++) {
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

/* Whether a texel's caustic is bright enough and got photons enough for
 * fine cells. */
static int fine_enough(double e, unsigned count, double top)
{
    return e >= DETAIL_FRACTION * top &&
           count >= DETAIL_PHOTONS * DETAIL_SUB * DETAIL_SUB;
}

static size_t map_floats(const part_map *m)
{
    return (size_t)m->levels * m->layout.sides * m->layout.nu * m->layout.nv * 3;
}

static size_t texel_index(const part_map *m, int level, int side, int i, int j)
{
    const map_layout *l = &m->layout;
    return (((size_t)level * l->sides + side) * l->nv + j) * l->nu + i;
}

/* Area of fine cell (su, sv) of planar texel (i, j) that lies on the
 * surface. */
static double cell_area(const part_map *m, int i, int j, int su, int sv)
{
    const map_layout *l = &m->layout;
    double s0 = axis_edge(&l->au, i), s1 = axis_edge(&l->au, i + 1);
    double t0 = axis_edge(&l->av, j), t1 = axis_edge(&l->av, j + 1);
    double a0 = s0 + (s1 - s0) * su / DETAIL_SUB, a1 = s0 + (s1 - s0) * (su + 1) / DETAIL_SUB;
    double b0 = t0 + (t1 - t0) * sv / DETAIL_SUB, b1 = t0 + (t1 - t0) * (sv + 1) / DETAIL_SUB;
    double whole = v3_length(v3_cross(l->du, l->dv)) * (a1 - a0) * (b1 - b0);
    if (m->cover[(size_t)j * l->nu + i] >= 1.0f)
        return whole;
    vec3 q[2 * MAP_CLIPS + 8];
    int n = map_rect_polygon(l, a0, a1, b0, b1, q, 2 * MAP_CLIPS + 8);
    vec3 sum = v3(0, 0, 0);
    for (int k = 1; k + 1 < n; k++)
        sum = v3_add(sum, v3_cross(v3_sub(q[k], q[0]), v3_sub(q[k + 1], q[0])));
    return n >= 3 ? 0.5 * v3_length(sum) : 0.0;
}

/* Where a level's caustic on planar part p is concentrated, a window of
 * fine cells takes it, made from the same deposits in the same order; the
 * level's coarse caustic is kept apart too (caustic_finish).  acc: the
 * caustic's texels; count: photons per texel.  Returns 0 when out of
 * memory. */
static int make_details(zone_forest *f, int p, const double *acc, const double *dacc,
                        const unsigned *count, const job *jobs, int njobs)
{
    part_map *m = &f->maps[p];
    const map_layout *l = &m->layout;
    size_t cells = (size_t)l->nu * l->nv;
    int first = m->details;
    for (int level = 1; level < f->map_levels; level++)
        for (int side = 0; side < l->sides; side++) {
            size_t base = texel_index(m, level, side, 0, 0);
            const double *a = acc + 3 * base, *da = dacc + base;
            const unsigned *cn = count + base;
            double top = 0;
            for (size_t k = 0; k < cells; k++)
                top = fmax(top, da[k]);
            if (!(top > 0))
                continue;
            /* The texels fine enough, and one around them: the coarse
             * caustic read bilinearly beside a bright texel would carry
             * half of it a texel too far. */
            unsigned char *ok = calloc(cells, 1);
            if (!ok)
                return 0;
            for (int j = 0; j < l->nv; j++)
                for (int i = 0; i < l->nu; i++) {
                    size_t k = (size_t)j * l->nu + i;
                    if (!fine_enough(da[k], cn[k], top))
                        continue;
                    for (int dj = -1; dj <= 1; dj++)
                        for (int di = -1; di <= 1; di++)
                            if (i + di >= 0 && i + di < l->nu && j + dj >= 0 && j + dj < l->nv)
                                ok[(size_t)(j + dj) * l->nu + i + di] = 1;
                }
            int i0 = l->nu, i1 = -1, j0 = l->nv, j1 = -1;
            for (int j = 0; j < l->nv; j++)
                for (int i = 0; i < l->nu; i++) {
                    if (!ok[(size_t)j * l->nu + i])
                        continue;
                    i0 = i < i0 ? i : i0, i1 = i > i1 ? i : i1;
                    j0 = j < j0 ? j : j0, j1 = j > j1 ? j : j1;
                }
            int ni = i1 - i0 + 1, nj = j1 - j0 + 1;
            if (i1 < 0 || ni * nj > DETAIL_MAX) {
                free(ok);
                continue;
            }
            map_detail *nd = realloc(m->detail, (size_t)(m->details + 1) * sizeof *nd);
            if (!nd) {
                free(ok);
                return 0;
            }
            m->detail = nd;
            map_detail *d = &m->detail[m->details++];
            *d = (map_detail){level, side, i0, j0, ni, nj, DETAIL_SUB,
                              NULL, NULL, NULL, NULL, NULL};
            d->use = malloc((size_t)ni * nj);
            d->e = calloc((size_t)ni * nj * DETAIL_SUB * DETAIL_SUB * 3, sizeof(float));
            d->coarse = malloc(cells * 3 * sizeof(float));
            if (!d->use || !d->e || !d->coarse) {
                free(ok);
                return 0;
            }
            for (size_t k = 0; k < cells * 3; k++)
                d->coarse[k] = (float)a[k];
            for (int j = 0; j < nj; j++)
                for (int i = 0; i < ni; i++) {
                    size_t k = (size_t)(j0 + j) * l->nu + i0 + i;
                    d->use[(size_t)j * ni + i] = ok[k];
                }
            free(ok);
        }
    for (int k = first; k < m->details; k++) {
        map_detail *d = &m->detail[k];
        int fu = d->ni * d->sub;
        size_t n = (size_t)fu * d->nj * d->sub * 3;
        double *fine = calloc(n, sizeof(double));
        if (!fine)
            return 0;
        for (int q = 0; q < njobs; q++)
            for (size_t x = 0; x < jobs[q].out.n; x++) {
                const deposit *dp = &jobs[q].out.d[x];
                if (dp->part != p || dp->level != d->level || dp->side != d->side ||
                    dp->i < d->i0 || dp->i >= d->i0 + d->ni || dp->j < d->j0 ||
                    dp->j >= d->j0 + d->nj)
                    continue;
                double area = cell_area(m, dp->i, dp->j, dp->su, dp->sv);
                if (!(area > 0))
                    continue;
                size_t at = 3 * ((size_t)((dp->j - d->j0) * d->sub + dp->sv) * fu +
                                 (size_t)((dp->i - d->i0) * d->sub + dp->su));
                for (int c = 0; c < 3; c++)
                    fine[at + c] += dp->flux[c] / area;
            }
        for (size_t x = 0; x < n; x++)
            d->e[x] = (float)fine[x];
        free(fine);
    }
    return 1;
}

int caustic_finish(zone_forest *f)
{
    for (int p = 0; p < f->map_count; p++) {
        part_map *m = &f->maps[p];
        if (!m->details)
            continue;
        size_t cells = (size_t)m->layout.nu * m->layout.nv;
        /* Refinement windows (refine.c, no coarse array) are not in the
         * texels. */
        for (int k = 0; k < m->details; k++) {
            const map_detail *d = &m->detail[k];
            if (!d->coarse)
                continue;
            float *px = map_texel(m, d->level, d->side, 0, 0);
            for (size_t i = 0; i < cells * 3; i++)
                px[i] -= d->coarse[i];
        }
        for (int k = 0; k < m->details; k++)
            if (m->detail[k].coarse && !map_build_mips(m, m->detail[k].level))
                return 0;
        m->detail_live = 1;
    }
    return 1;
}

zt_status caustic_build(zone_forest *f, const zt_renderer *r, zt_error *err)
{
    const rscene *rs = &r->rs;
    if (f->map_levels < 2)
        return ZT_OK;
    pair *pairs = NULL;
    int npairs = make_pairs(f, r->scene, rs, &pairs);
    if (npairs < 0)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics");
    int njobs = 0;
    for (int k = 0; k < npairs; k++)
        njobs += (pairs[k].photons + CHUNK - 1) / CHUNK;
    job *jobs = calloc((size_t)njobs + 1, sizeof *jobs);
    double **acc = calloc((size_t)f->map_count + 1, sizeof *acc);
    double **dacc = calloc((size_t)f->map_count + 1, sizeof *dacc);
    unsigned **count = calloc((size_t)f->map_count + 1, sizeof *count);
    if (!jobs || !acc || !dacc || !count) {
        free(pairs);
        free(jobs);
        free(acc);
        free(dacc);
        free(count);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics");
    }
    njobs = 0;
    for (int k = 0; k < npairs; k++)
        for (int first = 0; first < pairs[k].photons; first += CHUNK) {
            int left = pairs[k].photons - first;
            jobs[njobs++] = (job){k, first, left < CHUNK ? left : CHUNK, {NULL, 0, 0, 0}};
        }
    uint64_t rays = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(render_thread_count(r->options.threads)) \
    reduction(+ : rays)
    for (int k = 0; k < njobs; k++) {
        tracer t = {f, rs, &jobs[k].out, 0};
        for (int i = 0; i < jobs[k].count; i++)
            shoot(&t, &pairs[jobs[k].pair], jobs[k].first + i);
        rays += t.rays;
    }
    f->rays += rays;
    /* Sums in job order, in double precision, then into the texels. */
    int failed = 0;
    for (int k = 0; k < njobs && !failed; k++) {
        const deposits *o = &jobs[k].out;
        failed = o->failed;
        for (size_t i = 0; i < o->n && !failed; i++) {
            const deposit *d = &o->d[i];
            const part_map *m = &f->maps[d->part];
            if (!acc[d->part]) {
                acc[d->part] = calloc(map_floats(m), sizeof(double));
                dacc[d->part] = calloc(map_floats(m) / 3, sizeof(double));
                count[d->part] = calloc(map_floats(m) / 3, sizeof(unsigned));
                if (!acc[d->part] || !dacc[d->part] || !count[d->part]) {
                    failed = 1;
                    break;
                }
            }
            double area = texel_area(m, d->i, d->j);
            if (!(area > 0))
                continue;
            size_t at = texel_index(m, d->level, d->side, d->i, d->j);
            count[d->part][at]++;
            dacc[d->part][at] += d->dec / area;
            for (int c = 0; c < 3; c++)
                acc[d->part][3 * at + c] += d->flux[c] / area;
        }
    }
    for (int p = 0; p < f->map_count && !failed; p++)
        if (acc[p] && f->maps[p].layout.shape != SHAPE_SPHERE)
            failed = !make_details(f, p, acc[p], dacc[p], count[p], jobs, njobs);
    for (int p = 0; p < f->map_count; p++) {
        if (acc[p] && !failed) {
            const part_map *m = &f->maps[p];
            size_t n = map_floats(m);
            for (size_t i = 0; i < n; i++)
                m->texels[i] += (float)acc[p][i];
        }
        free(acc[p]);
        free(dacc[p]);
        free(count[p]);
    }
    free(dacc);
    free(count);
    for (int k = 0; k < njobs; k++)
        free(jobs[k].out.d);
    free(acc);
    free(jobs);
    free(pairs);
    return failed ? zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics") : ZT_OK;
}
