/* Rough lobes (GGX, material/microfacet.h) in the zone tracer.
 *
 * A smooth lobe passes on the light of one direction, which a ray reads
 * from the forest.  A rough lobe passes on an integral over its spread:
 *
 *   L(wo) = sum over the lobes k of  int f_k(wo, wi) L_{l-1}(wi) |cos| dwi,
 *
 * estimated here over a fixed sequence of directions drawn from the lobes
 * (visible normals), each reading the level below from the forest as the
 * smooth lobe's ray does.  Light of level 0 (lights, the sun, a map) is
 * small and bright: it takes its own, larger set of directions (a ray
 * each, no forest) and as many light samples (the path tracer's
 * next-event choice, from the same kind of sequence), the two weighed by
 * the power heuristic, so that a lobe far narrower than a light and a
 * light far smaller than a lobe both come out right.  The lobes share one
 * density, the weighted mixture that chooses among them, and a direction's
 * value is the sum of every lobe's f cos over it (one-sample MIS over the lobes: a rough glass's reflection
 * and transmission count wherever either sends light).
 *
 * How many directions: a camera sample's share of its pixel's
 * q.rough_pixel (level 0: q.rough_light_pixel), by its weight in the
 * pixel, as the mesh gathers share theirs (gather.c): the pixel's
 * own stretch of Roberts' R2 sequence, sample i of n taking points i,
 * i + n, ...; at least q.rough_sample.  A ray that meets a rough lobe on
 * the way (a reflection seen in a rough mirror, a gather's ray, Phase
 * One's) takes one direction, from a point of the sequence chosen by a
 * hash of where it is: deterministic, and unrelated between neighbours.
 * The image stays deterministic; its error is the quadrature's. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/transmittance.h"
#include "light/light_sample.h"
#include "light/mis.h"
#include "material/bsdf.h"
#include "render/prim.h"
#include "util/r2.h"
#include "util/vec3_convert.h"
#include "zone/phase_one/specular_targets.h"
#include "zone/phase_two/media.h"
#include "zone/zone.h"

/* Additive recurrences for the one-dimensional choices (which lobe,
 * reflect or refract, which light), on irrationals unrelated to R2's. */
#define GOLDEN 0.61803398874989484820
#define SQRT2_1 0.41421356237309504880
#define SQRT3_1 0.73205080756887729353
/* The light samples read R2 this far along: a fixed shift of the lobe's
 * points. */
#define LIGHT_SHIFT 0.5
/* The 4-D R-sequence's number (g^5 = g + 1), whose powers 1/g^k drive the
 * second set of numbers (point_numbers_at). */
#define R4_G 1.16730397826141868426

static float frac_f(double x)
{
    double f = x - floor(x);
    return f < 1.0 ? (float)f : 0.99999994f;
}

/* The numbers a direction takes from point j of the sequence.  Set 0 is a
 * camera sample's own: R2 for the direction, irrationals unrelated to it
 * for the choices.  Set 1 is for a ray from one of its directions that
 * meets a second rough lobe on its way (the far side of a rough glass):
 * the 4-D R-sequence's irrationals, so that the pair of directions spreads
 * over four dimensions, where taking set 0 again would put the second on
 * a fixed offset of the first. */
typedef struct point_numbers {
    float u2[2];         /* the direction */
    float choice, split; /* which lobe; reflect or refract */
    float l2[2];         /* a light sample's point */
    float light, far;    /* which light; the sun or the map */
} point_numbers;

static void point_numbers_at(double j, int set, point_numbers *p)
{
    if (set == 0) {
        double u, v;
        r2_point(j, &u, &v);
        p->u2[0] = (float)u;
        p->u2[1] = (float)v;
        r2_point(j + LIGHT_SHIFT, &u, &v);
        p->l2[0] = (float)u;
        p->l2[1] = (float)v;
        p->choice = frac_f(0.5 + j * GOLDEN);
        p->split = frac_f(0.5 + j * SQRT2_1);
        p->light = frac_f(0.5 + j * SQRT3_1);
        p->far = frac_f(0.5 + j * SQRT2_1 + 0.25);
        return;
    }
    double a1 = 1.0 / R4_G, a2 = a1 * a1, a3 = a2 * a1, a4 = a3 * a1;
    p->u2[0] = frac_f(0.5 + j * a3);
    p->u2[1] = frac_f(0.5 + j * a4);
    p->l2[0] = frac_f(0.5 + (j + LIGHT_SHIFT) * a3);
    p->l2[1] = frac_f(0.5 + (j + LIGHT_SHIFT) * a4);
    p->choice = frac_f(0.5 + j * a1);
    p->split = frac_f(0.5 + j * a2);
    p->light = frac_f(0.75 + j * SQRT3_1);
    p->far = frac_f(0.75 + j * SQRT2_1 + 0.25);
}

/* A point of the sequence for a ray that meets a rough lobe on its way. */
static double hashed_index(vec3f x, vec3f d)
{
    uint32_t b[6];
    const float v[6] = {x.x, x.y, x.z, d.x, d.y, d.z};
    memcpy(b, v, sizeof b);
    uint32_t h = 2166136261u;
    for (int i = 0; i < 6; i++) {
        h ^= b[i];
        h *= 16777619u;
        h ^= h >> 15;
    }
    return (double)(h & 0xffffffu);
}

/* The lobes' f cos summed (colour apart) and their mixture's density of
 * direction wi; 0 when wi lies on the other side of the geometric normal
 * than of the shading normal (light would leak). */
static vec3f lobes_eval(const zone_rough_at *s, const shading_frame *fr, unsigned lobes,
                         float weight_sum, vec3f wi, float *pdf)
{
    *pdf = 0.0f;
    if ((f3_dot(s->ng, wi) > 0.0f) != (f3_dot(fr->n, wi) > 0.0f))
        return f3_splat(0.0f);
    float fcos[LOBE_COUNT], p[LOBE_COUNT], f = 0.0f, metal = 0.0f, sum = 0.0f;
    bsdf_eval_rough(s->m, fr, f3_neg(s->d), wi, s->eta_i, s->eta_t, fcos, p);
    for (int k = 0; k < LOBE_COUNT; k++)
        if (lobes >> k & 1u) {
            if (k == LOBE_METALLIC)
                metal = fcos[k];
            else
                f += fcos[k];
            sum += p[k];
        }
    *pdf = sum / weight_sum;
    if (metal == 0.0f)
        return f3_splat(f);
    vec3f tint = bsdf_metal_tint(s->m, v3_to_f3(s->color), -f3_dot(fr->n, s->d));
    return f3_add(f3_splat(f), f3_scale(tint, metal));
}

/* Level 0 by light samples: the lights (not under ZR_NO_CAUSTIC: photons
 * carry their light by specular surfaces there) and light from far away
 * (the sun's not either at a caustic target, when it sends photons). */
static vec3 light_samples(zone_trace *t, const zone_rough_at *s, const shading_frame *fr,
                          unsigned lobes, float weight_sum, const point_numbers *pn, int flags)
{
    const rscene *rs = &t->r->rs;
    vec3 out = v3(0, 0, 0);
    const float *u2 = pn->l2;
    light_sample ls;
    if (!(flags & ZR_NO_CAUSTIC) && rs->light_count > 0 &&
        light_sample_point(rs, s->x, pn->light, u2, &ls) && !f3_is_black(ls.li)) {
        float pdf;
        vec3f f = lobes_eval(s, fr, lobes, weight_sum, ls.wi, &pdf);
        if (f3_max(f) > 0.0f) {
            int below = f3_dot(s->ng, ls.wi) < 0.0f;
            vec3f from = ray_offset(s->x, below ? f3_neg(s->ng) : s->ng);
            vec3f y = f3_madd(s->x, ls.wi, ls.dist);
            vec3f to_y = f3_sub(y, from);
            float dist_y = f3_length(to_y);
            rs_part tmp;
            const rs_part *lp = rs_prim(rs, ls.part, &tmp);
            vec3f tr = accel_transmittance(rs, from, f3_scale(to_y, 1.0f / dist_y),
                                           shadow_ray_end(from, y, dist_y), lp->background);
            t->rays++;
            float w = ls.delta ? 1.0f / ls.pdf : power_heuristic_over(ls.pdf, pdf);
            out = v3_add(out, f3_to_v3(f3_mul(f3_mul(ls.li, tr), f3_scale(f, w))));
        }
    }
    vec3f wi, li;
    float far_pdf;
    float u_pick = rs->distant.map && rs->distant.sun ? pn->far : 0.0f;
    int got = rs->distant.any && distant_sample(&rs->distant, u_pick, u2, &wi, &far_pdf, &li);
    if (got && (flags & ZR_NO_CAUSTIC) && t->f->sun_photons &&
        specular_target_part(rs, s->part) && distant_in_sun(&rs->distant, wi)) {
        li = f3_sub(li, rs->distant.sun_radiance);
        li = f3(f_max0(li.x), f_max0(li.y), f_max0(li.z));
    }
    if (got && !f3_is_black(li)) {
        float pdf;
        vec3f f = lobes_eval(s, fr, lobes, weight_sum, wi, &pdf);
        if (f3_max(f) > 0.0f) {
            int below = f3_dot(s->ng, wi) < 0.0f;
            vec3f tr = accel_transmittance(rs, ray_offset(s->x, below ? f3_neg(s->ng) : s->ng),
                                           wi, FLT_MAX, 1);
            t->rays++;
            out = v3_add(out, f3_to_v3(f3_mul(f3_mul(li, tr),
                                              f3_scale(f, power_heuristic_over(far_pdf, pdf)))));
        }
    }
    return out;
}

/* The rough lobes among `lobes` that m has, and the sum of their weights
 * (the densities' normaliser).  The coat (bsdf.h) is in the diffuse
 * lobe's place, and only when asked for alone (its light is white, the
 * others' tinted): its weight is the diffuse one's times its choice, s
 * E(cos_o). */
static unsigned rough_lobes(const rs_object *m, unsigned lobes, float cos_o, float *weight_sum)
{
    *weight_sum = 0.0f;
    if (lobes == 1u << LOBE_DIFFUSE) {
        if (m->coat)
            *weight_sum = m->weight[LOBE_DIFFUSE] * bsdf_coat_albedo(m, cos_o);
        return *weight_sum > 0.0f ? lobes : 0u;
    }
    for (int k = 0; k < LOBE_COUNT; k++) {
        if (!bsdf_lobe_rough(m, k))
            lobes &= ~(1u << k);
        if (lobes >> k & 1u)
            *weight_sum += m->weight[k];
    }
    return lobes;
}

static void frame_of(const zone_rough_at *s, shading_frame *fr)
{
    fr->n = s->ns;
    f3_basis(fr->n, &fr->t, &fr->b);
}

/* One direction from the lobes, by point j of the sequence: *value is the
 * lobes' f cos over the mixture's density there (colour apart), *pdf that
 * density (0 for the straight line of an index-matched glass, whose value
 * is 1). */
static int scatter(const zone_rough_at *s, const shading_frame *fr, unsigned lobes,
                   float weight_sum, const point_numbers *pn, vec3f *wi, float *pdf, vec3f *value)
{
    bsdf_sample bs;
    if (!bsdf_sample_rough_lobes(s->m, lobes, fr, f3_neg(s->d), pn->choice, pn->split, pn->u2,
                                 s->eta_i, s->eta_t, &bs))
        return 0;
    *wi = bs.wi;
    if (bs.delta) {
        *pdf = 0.0f;
        *value = f3_splat(1.0f);
        return 1;
    }
    vec3f f = lobes_eval(s, fr, lobes, weight_sum, bs.wi, pdf);
    if (!(f3_max(f) > 0.0f) || !(*pdf > 0.0f))
        return 0;
    *value = f3_scale(f, 1.0f / *pdf);
    return 1;
}

int zone_rough_scatter(const zone_rough_at *s, vec3f *wi, vec3f *value)
{
    float weight_sum, pdf;
    unsigned lobes = rough_lobes(s->m, ~0u, 1.0f, &weight_sum);
    if (!(weight_sum > 0.0f))
        return 0;
    shading_frame fr;
    frame_of(s, &fr);
    point_numbers pn;
    point_numbers_at(hashed_index(s->x, s->d), 0, &pn);
    return scatter(s, &fr, lobes, weight_sum, &pn, wi, &pdf, value);
}

/* The lobes' light of levels lo..hi along one direction (point j): f cos
 * over the density times the forest's radiance there; light of level 0
 * weighed against the light samples. */
static vec3 lobe_ray(zone_trace *t, const zone_rough_at *s, const shading_frame *fr,
                     unsigned lobes, float weight_sum, const point_numbers *pn, int lo, int hi,
                     int flags)
{
    vec3f wi, f;
    float pdf;
    if (!scatter(s, fr, lobes, weight_sum, pn, &wi, &pdf, &f))
        return v3(0, 0, 0);
    int through = f3_dot(s->ng, wi) < 0.0f;
    vec3f o = ray_offset(s->x, through ? f3_neg(s->ng) : s->ng);
    int next[MEDIA_MAX];
    const int *media = s->media;
    int media_count = s->media_count;
    if (through) {
        media_count = media_cross(s->media, s->media_count, s->object, s->entering, next);
        media = next;
    }
    t->mis_pdf = lo == 0 ? pdf : 0.0f;
    t->mis_from = s->x;
    return v3_mul(zone_radiance(t, o, wi, lo, hi, flags, media, media_count), f3_to_v3(f));
}

/* A camera sample's count of a pixel's `per_pixel` points: by its weight
 * in the pixel, at least `least`. */
static int sample_count(int per_pixel, double share, int least)
{
    int k = (int)(per_pixel * share + 0.5);
    return k > least ? k : least;
}

/* The same for level 0's light samples and directions, which aim at the
 * lights: where a sample's share is worth fewer than `least` points, it
 * takes `least` of them with probability p = per_pixel x share / least,
 * weighted 1/p (*gain), or none.  The choice is stratified along the
 * pixel's samples (sample i takes them where i p + phase passes an
 * integer), so the pixel takes about its own count.  A mesh's 8 x 8
 * detail samples would otherwise take `least` each: for a coat (a tenth of
 * a surface's light), 2.5 times the pixel's count.  On the engine room
 * (512 x 512, one saved forest) Phase Two A/B wall 0.94 for 0.771% ->
 * 0.779% per pixel; the directions that read the forest (levels 1 and up)
 * keep `least` a sample: chosen the same way they took the error to 0.93%. */
static int light_sample_count(int per_pixel, double share, int least,
                              const zone_gather_slot *slot, double *gain)
{
    double want = per_pixel * share;
    *gain = 1.0;
    if (want + 0.5 >= least)
        return sample_count(per_pixel, share, least);
    double p = want / least;
    double c = slot->sample * p + frac_f(0.5 + slot->pixel * GOLDEN);
    if (floor(c + p) == floor(c))
        return 0;
    *gain = 1.0 / p;
    return least;
}

/* Where a sample's points lie in the sequence, and in which set of
 * numbers: a camera sample's pixel has its own stretch, which its samples
 * take interleaved (sample i of n the points i, i + n, i + 2n, ...), so
 * that the pixel as a whole integrates over evenly spread points; a ray
 * from one of those directions takes that direction's point in the second
 * set (t->rough_nested); any other ray starts where a hash of the point
 * says. */
typedef struct seq {
    double first, step;
    int set;
} seq;

static seq sequence(const zone_trace *t, const zone_gather_slot *slot, int camera, int per_pixel,
                    const zone_rough_at *s)
{
    if (camera)
        return (seq){(double)slot->pixel * per_pixel + slot->sample + 1, slot->samples, 0};
    if (t->rough_nested)
        return (seq){t->rough_j, 1.0, 1};
    return (seq){hashed_index(s->x, s->d), 1.0, 0};
}

vec3 zone_rough_radiance(zone_trace *t, const zone_rough_at *s, unsigned lobes, int lo, int hi,
                         int flags)
{
    const rs_object *m = s->m;
    const rscene *rs = &t->r->rs;
    float weight_sum;
    lobes = rough_lobes(m, lobes, -f3_dot(s->ns, s->d), &weight_sum);
    if (!(weight_sum > 0.0f) || hi < 0 || lo > hi)
        return v3(0, 0, 0);
    if (lo < 0)
        lo = 0;
    shading_frame fr;
    frame_of(s, &fr);

    /* The directions: the camera sample's share of its pixel's, or one
     * from a point of the sequence a hash of where it is picks. */
    zone_gather_slot slot = t->gather;
    double own_share = t->sample_share;
    /* (A coat takes its share of them: terms.c.) */
    double share = own_share * (s->budget > 0.0f ? s->budget : 1.0f);
    const zone_quality *q = &t->f->q;
    int camera = share > 0.0 && slot.samples > 0;
    int k_max = camera ? sample_count(q->rough_pixel, share, q->rough_sample) : 1;
    int exact_direct = flags & ZR_EXACT_DIRECT;
    int cflags = ZR_BLURRED;
    if (flags & ZR_NO_CAUSTIC)
        cflags |= ZR_NO_CAUSTIC | (specular_target_part(rs, s->part) ? ZR_CAUSTIC_LIGHT : 0);
    /* Rays from here on are not the camera sample's: what they meet takes
     * one direction each of the sample's stretch, and exact direct light
     * at their ends is a point's own (no shared split). */
    int save_split = t->light_split;
    t->light_split = 0;
    /* This lobe's sequence: a nested lobe's point is taken (rays beyond it
     * hash their own). */
    seq sq0 = sequence(t, &slot, camera, q->rough_light_pixel, s);
    seq sq = sequence(t, &slot, camera, q->rough_pixel, s);
    int save_nested = t->rough_nested;
    double save_j = t->rough_j;
    t->rough_nested = 0;
    vec3 sum = v3(0, 0, 0);
    t->sample_share = 0.0;
    /* Level 0: its own, larger set of directions and light samples: they
     * read no forest (a ray each), and a light's highlight in a glossy lobe
     * is small and bright. */
    if (lo == 0) {
        double gain0 = 1.0;
        int k0 = camera ? light_sample_count(q->rough_light_pixel, share, q->rough_sample, &slot,
                                             &gain0)
                        : 1;
        vec3 l0 = v3(0, 0, 0);
        for (int k = 0; k < k0; k++) {
            point_numbers pn;
            point_numbers_at(sq0.first + sq0.step * k, sq0.set, &pn);
            l0 = v3_add(l0, light_samples(t, s, &fr, lobes, weight_sum, &pn, flags));
            l0 = v3_add(l0, lobe_ray(t, s, &fr, lobes, weight_sum, &pn, 0, 0, exact_direct | cflags));
        }
        if (k0 > 0)
            sum = v3_add(sum, v3_scale(l0, gain0 * k_max / k0));
        lo = 1;
    }
    /* What the lobe's rays meet: a mesh gathers a share of the camera
     * sample's directions (gather.c), a rough lobe takes one. */
    for (int k = 0; k < k_max && lo <= hi; k++) {
        double j = sq.first + sq.step * k;
        if (camera) {
            t->gather = (zone_gather_slot){
                .pixel = slot.pixel, .index = (uint16_t)k, .count = (uint16_t)k_max};
            t->rough_nested = 1;
            t->rough_j = j;
        }
        point_numbers pn;
        point_numbers_at(j, sq.set, &pn);
        sum = v3_add(sum, lobe_ray(t, s, &fr, lobes, weight_sum, &pn, lo, hi,
                                   exact_direct | cflags));
    }
    t->gather = slot;
    t->rough_nested = save_nested;
    t->rough_j = save_j;
    t->sample_share = own_share;
    t->mis_pdf = 0.0f;
    t->light_split = save_split;
    return v3_scale(v3_mul(s->color, sum), 1.0 / k_max);
}

/* An irrational unrelated to the sequence's (the plastic number's
 * reciprocal): the coat's roulette on a ray's way. */
#define PLASTIC_1 0.75487766624669276005

vec3 zone_coat_on_the_way(zone_trace *t, const zone_rough_at *s, int lo, int hi, int flags)
{
    float a = bsdf_coat_albedo(s->m, -f3_dot(s->ns, s->d));
    if (!(a > 0.0f) || hi < 0 || lo > hi)
        return v3(0, 0, 0);
    double u = hashed_index(s->x, s->d) * PLASTIC_1 + 0.25;
    if (u - floor(u) >= a)
        return v3(0, 0, 0);
    zone_rough_at white = *s;
    white.color = v3(1, 1, 1);
    /* No photons leave by coats: the light they reflect of the lights is
     * read here, in Phase One's gathers too. */
    return v3_scale(zone_rough_radiance(t, &white, 1u << LOBE_DIFFUSE, lo, hi,
                                        flags & ~ZR_NO_CAUSTIC),
                    1.0 / a);
}
