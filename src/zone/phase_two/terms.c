/* Phase Two, step two: the terms of the image, one per zone that sends
 * light toward the eye, and their values on a pixel's samples.
 *
 * The values follow zone_radiance (zone_radiance.c) split by zone: the
 * camera ray's first hit is shaded here, lobe by lobe and level by level,
 * and the light arriving along reflected and refracted rays is asked of
 * zone_radiance one level at a time.  p2_reference shades the same samples
 * with one zone_radiance call each; tests/test_zone.c checks that the terms
 * add up to it, so a change of the physics there that is not mirrored here
 * shows up as a failing test. */
#include <stdlib.h>
#include <string.h>

#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "geom/accel.h"
#include "light/light_sample.h"
#include "material/bsdf.h"
#include "render/prim.h"
#include "util/error.h"
#include "util/vec3_convert.h"
#include "zone/light/sky_gather.h"
#include "zone/phase_two/phase_two.h"

#define SHADE_FLAGS (ZR_EXACT_DIRECT | ZR_NO_EMISSION)


static int push_term(p2_terms *t, int *cap, p2_term term)
{
    if (t->count == *cap) {
        int nc = *cap ? 2 * *cap : 64;
        p2_term *nt = realloc(t->term, (size_t)nc * sizeof *nt);
        if (!nt)
            return 0;
        t->term = nt;
        *cap = nc;
    }
    t->term[t->count++] = term;
    return 1;
}

zt_status p2_terms_build(p2_terms *t, const zone_forest *f, const zt_renderer *r, int lo,
                         int hi, zt_error *err)
{
    const rscene *rs = &r->rs;
    int surfaces = zone_surface_count(rs), cap = 0;
    memset(t, 0, sizeof *t);
    t->sky_term = -1;
    t->surfaces = surfaces;
    t->root_term = malloc(((size_t)rs->part_count + 1) * sizeof *t->root_term);
    t->part_first = calloc((size_t)surfaces + 2, sizeof *t->part_first);
    /* A mesh light's roots are one term for the whole light. */
    unsigned char *emit_seen = calloc((size_t)surfaces + 1, 1);
    if (!t->root_term || !t->part_first || !emit_seen) {
        free(emit_seen);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zone terms");
    }
    for (int i = 0; i <= rs->part_count; i++)
        t->root_term[i] = -1;
    int ok = 1;
    /* The sky: not a zone of the forest; level 0 where the camera sees it. */
    if (lo == 0 && (!f3_is_black(rs->sky) || rs->distant.any)) {
        p2_term term = {P2_SKY, -1, -1, ZONE_EMIT, 0};
        t->sky_term = t->count;
        ok = push_term(t, &cap, term);
    }
    for (int i = 0; i < f->zone_count && ok; i++) {
        const zone *z = &f->zones[i];
        int l = z->level;
        if (l < lo || l > hi)
            continue;
        p2_term term = {0, i, z->source, z->kind, l};
        if (z->kind == ZONE_EMIT) {
            if (z->source < rs->part_count) {
                term.type = P2_ROOT;
                t->root_term[z->source] = t->count;
            } else {
                int s = zone_surface_of(rs, z->source);
                if (emit_seen[s])
                    continue;
                emit_seen[s] = 1;
                term.type = P2_EMIT;
                term.part = s;
            }
        } else if (z->kind == ZONE_DIFFUSE) {
            term.type = l == 1 ? P2_DIRECT : P2_MAP;
            if (l >= 2 && l - 1 >= f->map_levels)
                continue;
        } else {
            term.type = P2_SPECULAR;
        }
        ok = push_term(t, &cap, term);
    }
    free(emit_seen);
    if (!ok)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zone terms");
    /* Terms by surface (index `surfaces`: nothing hit), in term order. */
    for (int k = 0; k < t->count; k++)
        if (t->term[k].type != P2_ROOT)
            t->part_first[(t->term[k].part < 0 ? surfaces : t->term[k].part) + 1]++;
    for (int q = 0; q <= surfaces; q++)
        t->part_first[q + 1] += t->part_first[q];
    t->part_terms = malloc(((size_t)t->part_first[surfaces + 1] + 1) * sizeof *t->part_terms);
    int *fill = malloc(((size_t)surfaces + 1) * sizeof *fill);
    if (!t->part_terms || !fill) {
        free(fill);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zone terms");
    }
    memcpy(fill, t->part_first, ((size_t)surfaces + 1) * sizeof *fill);
    for (int k = 0; k < t->count; k++)
        if (t->term[k].type != P2_ROOT)
            t->part_terms[fill[t->term[k].part < 0 ? surfaces : t->term[k].part]++] = k;
    free(fill);
    return ZT_OK;
}

void p2_terms_free(p2_terms *t)
{
    free(t->term);
    free(t->part_first);
    free(t->part_terms);
    free(t->root_term);
    memset(t, 0, sizeof *t);
}

void p2_surface_of(const rscene *rs, const p2_sample *s, p2_surface *sf)
{
    sf->p = rs_prim(rs, s->part, &sf->tmp);
    sf->m = &rs->objects[sf->p->object];
    sf->xf = shape_hit_point(sf->p, s->o, s->d, s->t);
    vec3f ngf = shape_normal(sf->p, sf->xf);
    sf->back = f3_dot(ngf, s->d) > 0.0f;
    sf->nf = sf->back ? f3_neg(ngf) : ngf;
    rs_shade *sh = &sf->sh;
    sh->ns = sf->nf;
    sh->albedo = sf->m->color;
    sh->m = NULL;
    if (rs_needs_shade(rs, s->part, sf->m)) {
        rs_shade_at(rs, s->part, sf->p, sf->m, sf->xf, sf->nf, sh);
        sf->m = rs_shade_material(sh, sf->m);
    }
    sf->x = f3_to_v3(sf->xf);
    sf->n = f3_to_v3(sh->ns);
    sf->color = f3_to_v3(sh->albedo);
}

/* A coated diffuse surface's light of level l at a camera sample, from
 * its base's (diffuse: colour x irradiance x weight / pi): the base keeps
 * 1 - s E(cos_o) of it (bsdf.h), and the coat's reflection of level l - 1
 * is read along the rough lobes' directions (rough.c), a share of the
 * pixel's as large as the coat's share of what the surface returns (a
 * coat over a white base seen head-on is a twentieth of it). */
static vec3 coated(zone_trace *t, const p2_sample *s, const p2_surface *sf, int l, vec3 diffuse)
{
    const rs_object *m = sf->m;
    vec3f ns = v3_to_f3(sf->n);
    float a = bsdf_coat_albedo(m, -f3_dot(ns, s->d));
    if (!(a > 0.0f))
        return diffuse;
    float base = (1.0f - a) * f3_luminance(v3_to_f3(sf->color));
    zone_rough_at at = {m,  s->part, sf->xf, sf->nf, ns, v3(1, 1, 1), s->d, 1.0f, 1.0f,
                        sf->p->object, 1, NULL, 0, a / (a + base)};
    /* What its directions meet is read from the forest, without the exact
     * direct light there: the coat is a small share, and blurs it. */
    return v3_add(v3_scale(diffuse, 1.0 - a),
                  zone_rough_radiance(t, &at, 1u << LOBE_DIFFUSE, l - 1, l - 1, 0));
}

/* Level 1 diffuse light: every light exactly, and the sky. */
static vec3 direct_value(zone_trace *t, const p2_sample *s)
{
    p2_surface sf;
    p2_surface_of(&t->r->rs, s, &sf);
    vec3 e = zone_lights_at(t, s->part, sf.x, sf.n);
    if (t->f->sky)
        e = v3_add(e, zone_sky_irradiance(t, sf.x, sf.n));
    vec3 v = v3_scale(v3_mul(sf.color, e), sf.m->weight[LOBE_DIFFUSE] / 3.14159265358979);
    return sf.m->coat ? coated(t, s, &sf, 1, v) : v;
}

/* Level l >= 2 diffuse light from the surface's nodes E_{l-1}, or on a
 * mesh gathered. */
static vec3 map_value(zone_trace *t, const p2_term *term, const p2_sample *s)
{
    p2_surface sf;
    p2_surface_of(&t->r->rs, s, &sf);
    const rscene *rs = &t->r->rs;
    vec3 e = zone_gathers(rs, s->part)
                 ? zone_mesh_irradiance(t, sf.xf, sf.nf, sf.n, term->level - 1, s->part, sf.back)
                 : zone_map_read(t->f, rs, term->level - 1, s->part, sf.back, sf.x);
    if (t->f->caustic)
        e = v3_add(e, zone_caustic_read(t, term->level - 1, term->level - 1, s->part, sf.back,
                                        sf.x, f3_to_v3(sf.nf)));
    vec3 v = v3_scale(v3_mul(sf.color, e), sf.m->weight[LOBE_DIFFUSE] / 3.14159265358979);
    return sf.m->coat ? coated(t, s, &sf, term->level, v) : v;
}

/* A specular lobe at level l: its share of the level l-1 radiance along
 * the reflected ray (and, for glass, the refracted one). */
static vec3 specular_value(zone_trace *t, const p2_term *term, const p2_sample *s)
{
    p2_surface sf;
    p2_surface_of(&t->r->rs, s, &sf);
    const rs_object *m = sf.m;
    int l = term->level;
    vec3f d = s->d, wo = f3_neg(d), ns = v3_to_f3(sf.n);
    float cos_o = f3_dot(ns, wo);
    vec3f refl = f3_normalize(f3_sub(d, f3_scale(ns, 2.0f * f3_dot(d, ns))));
    vec3f out_o = ray_offset(sf.xf, sf.nf);
    double k_refl = 0, k_tran = 0;
    float eta_i = 1.0f, eta_t = m->ior; /* the camera is in vacuum: entering */
    int lobe = term->kind == ZONE_MIRROR     ? LOBE_REFLECTING
               : term->kind == ZONE_METALLIC ? LOBE_METALLIC
                                             : LOBE_REFRACTIVE;
    if (bsdf_lobe_rough(m, lobe)) {
        zone_rough_at at = {m,     s->part, sf.xf, sf.nf, ns, sf.color, d, eta_i, eta_t,
                            sf.p->object, 1, NULL, 0, 0.0f};
        return zone_rough_radiance(t, &at, 1u << lobe, l - 1, l - 1, ZR_EXACT_DIRECT);
    }
    switch (term->kind) {
    case ZONE_MIRROR:
        k_refl = m->weight[LOBE_REFLECTING];
        break;
    case ZONE_METALLIC:
        k_refl = m->weight[LOBE_METALLIC] * bsdf_schlick(cos_o, m->ior);
        break;
    case ZONE_REFRACT: {
        if (m->thin) {
            /* A pane: its reflection of level l-1, and level l behind it
             * (crossing is no scattering). */
            float fr = bsdf_pane_reflectance(cos_o, m->ior);
            vec3 out = v3(0, 0, 0);
            if (l >= 1) {
                vec3 li = zone_radiance(t, out_o, refl, l - 1, l - 1, ZR_EXACT_DIRECT, NULL, 0);
                out = v3_scale(v3_mul(sf.color, li), m->weight[LOBE_REFRACTIVE] * fr);
            }
            vec3 lb = zone_radiance(t, ray_offset(sf.xf, f3_neg(sf.nf)), d, l, l,
                                    ZR_EXACT_DIRECT, NULL, 0);
            return v3_add(out, v3_scale(v3_mul(f3_to_v3(m->tint), lb),
                                        m->weight[LOBE_REFRACTIVE] * (1.0 - fr)));
        }
        float fr = bsdf_fresnel_dielectric(cos_o, eta_i, eta_t);
        k_refl = m->weight[LOBE_REFRACTIVE] * fr;
        k_tran = m->weight[LOBE_REFRACTIVE] * (1.0 - fr);
        break;
    }
    default:
        return v3(0, 0, 0);
    }
    vec3 out = v3(0, 0, 0);
    if (k_refl > 0) {
        vec3 li = zone_radiance(t, out_o, refl, l - 1, l - 1, ZR_EXACT_DIRECT, NULL, 0);
        out = v3_add(out, v3_scale(v3_mul(sf.color, li), k_refl));
    }
    if (k_tran > 0) {
        float eta = eta_i / eta_t;
        float sin2 = eta * eta * (1.0f - cos_o * cos_o);
        float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin2));
        vec3f tr = f3_normalize(f3_sub(f3_scale(d, eta), f3_scale(ns, cos_t - eta * cos_o)));
        int media = sf.p->object;
        vec3 li = zone_radiance(t, ray_offset(sf.xf, f3_neg(sf.nf)), tr, l - 1, l - 1,
                                ZR_EXACT_DIRECT, &media, 1);
        out = v3_add(out, v3_scale(v3_mul(sf.color, li), k_tran * eta * eta));
    }
    return out;
}

/* The share of a pixel's 16 x 16 cell centres whose rays see light part
 * `light` first: where too many occluders stand before it to clip. */
static double sampled_coverage(const p2_ctx *c, zone_trace *t, int light, const p2_pixel *px)
{
    enum { N = 16 };
    int count = 0;
    for (int k = 0; k < N * N; k++) {
        vec3f o, d;
        cam_ray(&c->c, (float)px->x + (k % N + 0.5f) / N, (float)px->y + (k / N + 0.5f) / N, &o,
                &d);
        hit h = accel_intersect(&t->r->rs, o, d);
        t->rays++;
        count += h.part == light;
    }
    return (double)count / (N * N);
}

/* Level 0 of a light part in a pixel: its exact coverage x emission. */
static vec3 root_value(const p2_ctx *c, zone_trace *t, int i, const p2_pixel *px)
{
    const rscene *rs = &t->r->rs;
    int light = px->lights[i];
    vec3f e = rs->objects[rs->parts[light].object].emission;
    if (px->light_cover[i] >= 0)
        return v3_scale(f3_to_v3(e), px->light_cover[i]);
    vec3 corner[4];
    const float cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
    for (int i = 0; i < 4; i++) {
        vec3f o, d;
        cam_ray(&c->c, (float)px->x + cx[i], (float)px->y + cy[i], &o, &d);
        corner[i] = v3(o.x, o.y, o.z);
    }
    vec3 eye = f3_to_v3(c->c.viewpoint);
    double cov = direct_pixel_coverage(&t->f->direct, light, eye, corner);
    if (cov < 0)
        cov = sampled_coverage(c, t, light, px);
    return v3_scale(f3_to_v3(e), cov);
}

static void add(double acc[3], double w, vec3 v)
{
    acc[0] += w * v.x;
    acc[1] += w * v.y;
    acc[2] += w * v.z;
}

void p2_apply(const p2_ctx *c, zone_trace *t, int k, const p2_pixel *px, double acc[3])
{
    const p2_term *term = &c->terms.term[k];
    switch (term->type) {
    case P2_ROOT:
        for (int i = 0; i < px->nlights; i++)
            if (px->lights[i] == term->part) {
                add(acc, 1.0, root_value(c, t, i, px));
                break;
            }
        return;
    case P2_SKY: {
        const rscene *rs = &t->r->rs;
        for (int i = 0; i < px->n; i++)
            if (px->s[i].part < 0)
                add(acc, px->s[i].w, f3_to_v3(zone_background(rs, px->s[i].d)));
        return;
    }
    default:
        break;
    }
    for (int i = 0; i < px->n; i++) {
        const p2_sample *s = &px->s[i];
        if (s->surface != term->part)
            continue;
        t->light_split = s->light_split;
        t->gather = s->gather;
        t->sample_share = s->w;
        vec3 v;
        switch (term->type) {
        case P2_EMIT: {
            rs_part tmp;
            const rs_part *p = rs_prim(&t->r->rs, s->part, &tmp);
            v = f3_to_v3(light_emitted(&t->r->rs, s->part, p, f3_madd(s->o, s->d, s->t), s->d));
            break;
        }
        case P2_DIRECT: v = direct_value(t, s); break;
        case P2_MAP: v = map_value(t, term, s); break;
        default: v = specular_value(t, term, s); break;
        }
        add(acc, s->w, v);
    }
    t->light_split = 0;
    t->gather = (zone_gather_slot){0};
    t->sample_share = 0.0;
}

void p2_reference(const p2_ctx *c, zone_trace *t, const p2_pixel *px, double acc[3])
{
    const rscene *rs = &t->r->rs;
    if (c->lo == 0)
        for (int i = 0; i < px->nlights; i++)
            if (!f3_is_black(rs->objects[rs->parts[px->lights[i]].object].emission))
                add(acc, 1.0, root_value(c, t, i, px));
    for (int i = 0; i < px->n; i++) {
        t->light_split = px->s[i].light_split;
        t->gather = px->s[i].gather;
        t->sample_share = px->s[i].w;
        add(acc, px->s[i].w,
            zone_radiance(t, px->s[i].o, px->s[i].d, c->lo, c->hi, SHADE_FLAGS | ZR_WHOLE_HIT,
                          NULL, 0));
    }
    t->light_split = 0;
    t->gather = (zone_gather_slot){0};
    t->sample_share = 0.0;
}
