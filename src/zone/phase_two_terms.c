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
#include "material/bsdf.h"
#include "util/error.h"
#include "util/vec3_convert.h"
#include "zone/phase_two.h"

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

static const int lobe_kind[LOBE_COUNT] = {ZONE_DIFFUSE, ZONE_METALLIC, ZONE_MIRROR,
                                          ZONE_REFRACT};

zt_status p2_terms_build(p2_terms *t, const zone_forest *f, const zt_renderer *r, int lo,
                         int hi, zt_error *err)
{
    const rscene *rs = &r->rs;
    int parts = rs->part_count, cap = 0;
    memset(t, 0, sizeof *t);
    t->sky_term = -1;
    /* The representative zone of each (surface, kind, level). */
    size_t nrep = (size_t)parts * ZONE_KINDS * (size_t)(hi + 1);
    int *rep = malloc((nrep ? nrep : 1) * sizeof *rep);
    t->root_term = malloc(((size_t)parts + 1) * sizeof *t->root_term);
    t->part_first = calloc((size_t)parts + 2, sizeof *t->part_first);
    if (!rep || !t->root_term || !t->part_first) {
        free(rep);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zone terms");
    }
    for (size_t i = 0; i < nrep; i++)
        rep[i] = -1;
    for (int i = 0; i <= parts; i++)
        t->root_term[i] = -1;
#define REP(q, k, l) rep[((size_t)(q) * ZONE_KINDS + (size_t)(k)) * (size_t)(hi + 1) + (size_t)(l)]
    int ok = 1;
    for (int i = 0; i < f->zone_count && ok; i++) {
        const zone *z = &f->zones[i];
        int l = z->level;
        if (l < lo || l > hi)
            continue;
        p2_term term = {0, i, z->source, -1, z->kind, l};
        if (z->kind == ZONE_EMIT) {
            term.type = P2_ROOT;
            t->root_term[z->source] = t->count;
        } else if (z->kind == ZONE_DIFFUSE && l == 1) {
            /* Direct light is exact per light part: no merging. */
            term.type = P2_DIRECT;
            term.light = z->root_light;
        } else {
            if (REP(z->source, z->kind, l) >= 0)
                continue; /* merged into the representative */
            REP(z->source, z->kind, l) = i;
            if (z->kind == ZONE_DIFFUSE) {
                if (l - 1 >= f->map_levels)
                    continue;
                term.type = P2_MAP;
            } else {
                term.type = P2_SPECULAR;
            }
        }
        ok = push_term(t, &cap, term);
    }
    /* The sky: not a zone of the forest.  Level 0 where the camera sees it;
     * and, if it shines, a pseudo-zone for every (surface, lobe, level) that
     * no zone represents (direct light at level 1 is the lights' only). */
    if (ok && !f3_is_black(rs->sky)) {
        if (lo == 0) {
            p2_term term = {P2_SKY, -1, -1, -1, ZONE_EMIT, 0};
            t->sky_term = t->count;
            ok = push_term(t, &cap, term);
        }
        for (int l = lo > 1 ? lo : 1; l <= hi && ok; l++)
            for (int q = 0; q < parts && ok; q++) {
                const rs_object *m = &rs->objects[rs->parts[q].object];
                if (m->is_light)
                    continue;
                for (int k = 0; k < LOBE_COUNT && ok; k++) {
                    int kind = lobe_kind[k];
                    if (m->weight[k] <= 0.0f || REP(q, kind, l) >= 0)
                        continue;
                    p2_term term = {P2_SPECULAR, -1, q, -1, kind, l};
                    if (kind == ZONE_DIFFUSE) {
                        if (l == 1)
                            term.type = P2_SKY_DIRECT;
                        else if (l - 1 < f->map_levels)
                            term.type = P2_MAP;
                        else
                            continue;
                    }
                    ok = push_term(t, &cap, term);
                }
            }
    }
#undef REP
    free(rep);
    if (!ok)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zone terms");
    /* Terms by surface part (index parts: nothing hit), in term order. */
    for (int k = 0; k < t->count; k++)
        if (t->term[k].type != P2_ROOT)
            t->part_first[(t->term[k].part < 0 ? parts : t->term[k].part) + 1]++;
    for (int q = 0; q <= parts; q++)
        t->part_first[q + 1] += t->part_first[q];
    t->part_terms = malloc(((size_t)t->part_first[parts + 1] + 1) * sizeof *t->part_terms);
    int *fill = malloc(((size_t)parts + 1) * sizeof *fill);
    if (!t->part_terms || !fill) {
        free(fill);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zone terms");
    }
    memcpy(fill, t->part_first, ((size_t)parts + 1) * sizeof *fill);
    for (int k = 0; k < t->count; k++)
        if (t->term[k].type != P2_ROOT)
            t->part_terms[fill[t->term[k].part < 0 ? parts : t->term[k].part]++] = k;
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

/* The first hit of a camera sample, as zone_radiance sees it. */
typedef struct surface {
    const rs_part *p;
    const rs_object *m;
    vec3f xf, nf;
    vec3 x, n, color;
    int back;
} surface;

static void surface_of(const rscene *rs, const p2_sample *s, surface *sf)
{
    sf->p = &rs->parts[s->part];
    sf->m = &rs->objects[sf->p->object];
    sf->xf = f3_madd(s->o, s->d, s->t);
    vec3f ngf = shape_normal(sf->p, sf->xf);
    sf->back = f3_dot(ngf, s->d) > 0.0f;
    sf->nf = sf->back ? f3_neg(ngf) : ngf;
    sf->x = f3_to_v3(sf->xf);
    sf->n = f3_to_v3(sf->nf);
    sf->color = f3_to_v3(sf->m->color);
}

/* Level 1 diffuse light from one light part. */
static vec3 direct_value(zone_trace *t, const p2_term *term, const p2_sample *s)
{
    const rscene *rs = &t->r->rs;
    surface sf;
    surface_of(rs, s, &sf);
    vec3f em = rs->objects[rs->parts[term->light].object].emission;
    double g = direct_irradiance(&t->f->direct, term->light, sf.x, sf.n, s->part);
    vec3 e = v3_scale(f3_to_v3(em), g);
    return v3_scale(v3_mul(sf.color, e), sf.m->weight[LOBE_DIFFUSE] / 3.14159265358979);
}

/* Level l >= 2 diffuse light from the surface's map E_{l-1}. */
static vec3 map_value(zone_trace *t, const p2_term *term, const p2_sample *s)
{
    surface sf;
    surface_of(&t->r->rs, s, &sf);
    vec3 e = term->type == P2_SKY_DIRECT
                 ? forest_sky_irradiance(t, sf.x, sf.n)
                 : map_lookup_wide(&t->f->maps[s->part], term->level - 1, sf.back, sf.x, 0.0);
    return v3_scale(v3_mul(sf.color, e), sf.m->weight[LOBE_DIFFUSE] / 3.14159265358979);
}

/* A specular lobe at level l: its share of the level l-1 radiance along
 * the reflected ray (and, for glass, the refracted one). */
static vec3 specular_value(zone_trace *t, const p2_term *term, const p2_sample *s)
{
    surface sf;
    surface_of(&t->r->rs, s, &sf);
    const rs_object *m = sf.m;
    int l = term->level;
    vec3f d = s->d, wo = f3_neg(d);
    float cos_o = f3_dot(sf.nf, wo);
    vec3f refl = f3_normalize(f3_sub(d, f3_scale(sf.nf, 2.0f * f3_dot(d, sf.nf))));
    vec3f out_o = ray_offset(sf.xf, sf.nf);
    double k_refl = 0, k_tran = 0;
    float eta_i = 1.0f, eta_t = m->ior; /* the camera is in vacuum: entering */
    switch (term->kind) {
    case ZONE_MIRROR:
        k_refl = m->weight[LOBE_REFLECTING];
        break;
    case ZONE_METALLIC:
        k_refl = m->weight[LOBE_METALLIC] * bsdf_schlick(cos_o, m->ior);
        break;
    case ZONE_REFRACT: {
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
        vec3f tr = f3_normalize(f3_sub(f3_scale(d, eta), f3_scale(sf.nf, cos_t - eta * cos_o)));
        int media = sf.p->object;
        vec3 li = zone_radiance(t, ray_offset(sf.xf, f3_neg(sf.nf)), tr, l - 1, l - 1,
                                ZR_EXACT_DIRECT, &media, 1);
        out = v3_add(out, v3_scale(v3_mul(sf.color, li), k_tran * eta * eta));
    }
    return out;
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
        vec3 sky = f3_to_v3(t->r->rs.sky);
        for (int i = 0; i < px->n; i++)
            if (px->s[i].part < 0)
                add(acc, px->s[i].w, sky);
        return;
    }
    default:
        break;
    }
    for (int i = 0; i < px->n; i++) {
        const p2_sample *s = &px->s[i];
        if (s->part != term->part)
            continue;
        vec3 v = term->type == P2_DIRECT ? direct_value(t, term, s)
                 : term->type == P2_MAP || term->type == P2_SKY_DIRECT ? map_value(t, term, s)
                                         : specular_value(t, term, s);
        add(acc, s->w, v);
    }
}

void p2_reference(const p2_ctx *c, zone_trace *t, const p2_pixel *px, double acc[3])
{
    const rscene *rs = &t->r->rs;
    if (c->lo == 0)
        for (int i = 0; i < px->nlights; i++)
            if (!f3_is_black(rs->objects[rs->parts[px->lights[i]].object].emission))
                add(acc, 1.0, root_value(c, t, i, px));
    for (int i = 0; i < px->n; i++)
        add(acc, px->s[i].w,
            zone_radiance(t, px->s[i].o, px->s[i].d, c->lo, c->hi, SHADE_FLAGS, NULL, 0));
}
