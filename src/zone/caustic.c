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
#include "zone/glint.h"

#define PI_D 3.14159265358979323846
#define MEDIA_MAX 8
#define CHUNK 1024        /* photons per work item */
#define MIN_PHOTONS 256   /* per (light, target): a small target still gets a few */

int caustic_target(const rscene *rs, int i)
{
    const rs_part *p = &rs->parts[i];
    if (p->is_light || (p->shape != SHAPE_TRIANGLE && p->shape != SHAPE_SPHERE))
        return 0;
    const rs_object *m = &rs->objects[p->object];
    return m->weight[LOBE_REFLECTING] > 0.0f || m->weight[LOBE_METALLIC] > 0.0f ||
           m->weight[LOBE_REFRACTIVE] > 0.0f;
}

/* Irradiance added to one texel: texel `at` of part's texel array (float
 * index / 3). */
typedef struct deposit {
    int part;
    size_t at;
    float e[3];
} deposit;

typedef struct deposits {
    deposit *d;
    size_t n, cap;
    int failed;
} deposits;

/* One (light, target) pair and its photon count. */
typedef struct pair {
    int light, target, photons;
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

static void push(deposits *o, int part, size_t at, vec3 e)
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
    o->d[o->n++] = (deposit){part, at, {(float)e.x, (float)e.y, (float)e.z}};
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
 * events: its texel's irradiance grows by flux / texel area.  Splatting
 * into the texel that holds x blurs a caustic by a texel: the maps'
 * resolution, as for every other light in them. */
static void deposit_at(tracer *t, int part, int level, int side, vec3 x, vec3 flux)
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
    double area = texel_area(m, i, j);
    if (!(area > 0))
        return;
    size_t at = (((size_t)level * l->sides + side) * l->nv + j) * l->nu + i;
    push(t->out, part, at, v3_scale(flux, 1.0 / area));
}

/* Follows flux along (o, d) after k specular events.  `first`: the part
 * the ray must hit first (-1: any).  `glint`: the path so far is one
 * reflection off the outside of a glint sphere, which glint.c accounts for
 * when it lands on a texel. */
static void follow(tracer *t, vec3f o, vec3f d, vec3 flux, int k, int glint, int first,
                   const int *media, int media_count)
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
        deposit_at(t, h.part, k, back, f3_to_v3(xf), flux);
    /* The next surface would receive k + 1 events: only while a map level
     * is left for it. */
    if (k + 1 >= t->f->map_levels)
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
    if (k_refl > 0) {
        int g = k == 0 && !back && media_count == 0 && glint_sphere(rs, h.part);
        follow(t, ray_offset(xf, nf), refl, v3_scale(v3_mul(flux, color), k_refl), k + 1, g, -1,
               media, media_count);
    }
    if (k_tran > 0) {
        float eta = eta_i / eta_t;
        float sin2 = eta * eta * (1.0f - cos_o * cos_o);
        float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin2));
        vec3f tr = f3_normalize(f3_sub(f3_scale(d, eta), f3_scale(nf, cos_t - eta * cos_o)));
        int next[MEDIA_MAX];
        int nc = media_count;
        for (int i = 0; i < nc && i < MEDIA_MAX; i++)
            next[i] = media[i];
        if (entering) {
            if (nc < MEDIA_MAX)
                next[nc++] = p->object;
        } else {
            nc--;
        }
        /* Flux crosses the surface less what it reflects: no eta^2 here.
         * The radiance convention's eta^2 (zone_radiance) is what radiance
         * gains as flux is squeezed into a smaller solid angle; a photon
         * carries flux, so its gain shows as a denser splat instead. */
        follow(t, ray_offset(xf, f3_neg(nf)), tr, v3_scale(v3_mul(flux, color), k_tran), k + 1,
               0, -1, next, nc);
    }
}

/* Photon i of n of a pair: a point on the light (a triangle uniformly; a
 * sphere over the cap that can see the target) and a direction towards the
 * target (uniform in a sphere's cone, or to a uniform point of a
 * triangle), from a 4-d Hammersley set whose best-spread pair of
 * coordinates picks the direction (what shapes a caustic).  Flux =
 * radiance x cos at the light x light area x (cone solid angle, or a
 * triangle's area-to-solid-angle factor) / n. */
static void shoot(tracer *t, const pair *pr, int i)
{
    const rscene *rs = t->rs;
    const rs_part *lp = &rs->parts[pr->light], *tp = &rs->parts[pr->target];
    int n = pr->photons;
    double u1 = (i + 0.5) / n, u2 = radical_inverse((uint32_t)i, 2);
    double u3 = radical_inverse((uint32_t)i, 3), u4 = radical_inverse((uint32_t)i, 5);
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
    vec3f le = light_emitted(rs, lp, v3_to_f3(y), f3_neg(wf));
    if (f3_is_black(le))
        return;
    vec3 flux = v3_scale(f3_to_v3(le), cy * g * area / n);
    follow(t, ray_offset(v3_to_f3(y), v3_to_f3(side)), wf, flux, 0, 0, pr->target, NULL, 0);
}

/* Photons per pair: the light's budget shared by how much of its light
 * each target can catch (solid angle from the light's centre x specular
 * weight x colour), at least MIN_PHOTONS. */
static int make_pairs(const zone_forest *f, const rscene *rs, pair **out)
{
    int cap = 16, count = 0;
    pair *ps = malloc((size_t)cap * sizeof *ps);
    double *imp = malloc((size_t)(rs->part_count + 1) * sizeof *imp);
    if (!ps || !imp) {
        free(ps);
        free(imp);
        return -1;
    }
    for (int j = 0; j < rs->light_count; j++) {
        int li = rs->lights[j].part;
        const rs_part *lp = &rs->parts[li];
        if ((lp->shape != SHAPE_TRIANGLE && lp->shape != SHAPE_SPHERE) ||
            f3_is_black(rs->objects[lp->object].emission))
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
            double share = (double)f->q.photons * imp[i] / total;
            int n = share < MIN_PHOTONS ? MIN_PHOTONS : (int)(share + 0.5);
            ps[count++] = (pair){li, i, n};
        }
    }
    free(imp);
    *out = ps;
    return count;
}

zt_status caustic_build(zone_forest *f, const zt_renderer *r, zt_error *err)
{
    const rscene *rs = &r->rs;
    if (f->map_levels < 2)
        return ZT_OK;
    pair *pairs = NULL;
    int npairs = make_pairs(f, rs, &pairs);
    if (npairs < 0)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics");
    int njobs = 0;
    for (int k = 0; k < npairs; k++)
        njobs += (pairs[k].photons + CHUNK - 1) / CHUNK;
    job *jobs = calloc((size_t)njobs + 1, sizeof *jobs);
    double **acc = calloc((size_t)f->map_count + 1, sizeof *acc);
    if (!jobs || !acc) {
        free(pairs);
        free(jobs);
        free(acc);
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
                size_t n = (size_t)m->levels * m->layout.sides * m->layout.nu * m->layout.nv * 3;
                acc[d->part] = calloc(n, sizeof(double));
                if (!acc[d->part]) {
                    failed = 1;
                    break;
                }
            }
            for (int c = 0; c < 3; c++)
                acc[d->part][d->at * 3 + c] += d->e[c];
        }
    }
    for (int p = 0; p < f->map_count; p++) {
        if (acc[p] && !failed) {
            const part_map *m = &f->maps[p];
            size_t n = (size_t)m->levels * m->layout.sides * m->layout.nu * m->layout.nv * 3;
            for (size_t i = 0; i < n; i++)
                m->texels[i] += (float)acc[p][i];
        }
        free(acc[p]);
    }
    for (int k = 0; k < njobs; k++)
        free(jobs[k].out.d);
    free(acc);
    free(jobs);
    free(pairs);
    return failed ? zt_fail(err, ZT_ERR_MEMORY, "out of memory for caustics") : ZT_OK;
}
