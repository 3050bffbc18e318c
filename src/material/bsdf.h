/* The four-part material: a weighted sum of a Lambertian diffuse lobe, a
 * Schlick-Fresnel metal reflector, a mirror and a dielectric, all tinted by
 * the material colour (docs/light-transport.md).  With roughness 0 the
 * last three are smooth (Dirac deltas); above it they are GGX lobes
 * (material/microfacet.h), which have densities like the diffuse one. */
#ifndef ZT_MATERIAL_BSDF_H
#define ZT_MATERIAL_BSDF_H

#include "material/fresnel.h"
#include "material/microfacet.h"
#include "render/render_scene.h"
#include "util/sincos_turn.h"

#define ZT_PI 3.14159265358979f
/* Multiplying by it instead of dividing by ZT_PI saves a division's
 * latency on every vertex (the compiler may not do it by itself). */
#define ZT_INV_PI 0.318309886183791f

/* Where a material is sampled: n the normal facing wo's side, t and b
 * completing an orthonormal frame (either handedness). */
typedef struct shading_frame {
    vec3f t, b, n;
} shading_frame;

typedef struct bsdf_sample {
    vec3f wi;       /* new direction, unit */
    vec3f weight;   /* f * |cos| / pdf: the throughput factor */
    float pdf;      /* density of the choice, lobe weight included (0 for
                       deltas) */
    int delta;      /* chosen lobe is a delta (no MIS) */
    int transmit;   /* crossed the surface (refraction) */
} bsdf_sample;

/* The clear coat over the diffuse lobe (m->coat; docs/light-transport.md):
 *
 *   f_d(wo, wi) = s F(wo.h) D G2 / (4 cos_o cos_i)  +  (1 - s E(cos_o)) c / pi
 *
 * a GGX reflection of the material's alpha (at least GGX_ALPHA_MIN: a
 * coat of roughness 0 is the narrowest lobe, not a delta) with Schlick's
 * F (F0 = 0.04) scaled by s = m->specular, over the base, which gets what
 * the coat does not reflect: E is the coat's albedo at cos_o, so a white
 * base under light arriving evenly returns all of it.  The diffuse lobe,
 * once chosen, picks the coat with probability s E(cos_o) and the base
 * with the rest; the base's sample then weighs c, as without a coat. */
static inline float bsdf_coat_alpha(const rs_object *m)
{
    return m->alpha > GGX_ALPHA_MIN ? m->alpha : GGX_ALPHA_MIN;
}

/* s E(cos_o): the share of evenly arriving light the coat reflects toward
 * wo, which is also its probability of being sampled; 0 without a coat. */
static inline float bsdf_coat_albedo(const rs_object *m, float cos_o)
{
    if (!m->coat || !(cos_o > 0.0f))
        return 0.0f;
    return m->specular * ggx_albedo_coat(cos_o, bsdf_coat_alpha(m));
}

/* f * cos of the diffuse lobe for unit wi, and its sampling density
 * (lobe choice included), where n faces the side the light arrives on.
 * With a coat, the base's (bsdf_eval_base). */
static inline vec3f bsdf_eval_diffuse(const rs_object *m, vec3f n, vec3f wi,
                                      float *pdf)
{
    float c = f3_dot(n, wi);
    if (c <= 0.0f) {
        *pdf = 0.0f;
        return f3_splat(0.0f);
    }
    float w = m->weight[LOBE_DIFFUSE];
    *pdf = w * c * ZT_INV_PI;
    return f3_scale(m->color, *pdf);
}

/* The diffuse lobe's base under its coat (bsdf_coat_albedo) for light from
 * wi leaving at cos_o (the shading normal's cosine with wo): f * cos and
 * the density of the base's sample, both times 1 - s E(cos_o).  Without a
 * coat, bsdf_eval_diffuse. */
static inline vec3f bsdf_eval_base(const rs_object *m, vec3f n, vec3f wi, float cos_o,
                                   float *pdf)
{
    vec3f fc = bsdf_eval_diffuse(m, n, wi, pdf);
    if (m->coat) {
        float keep = 1.0f - bsdf_coat_albedo(m, cos_o);
        *pdf *= keep;
        fc = f3_scale(fc, keep);
    }
    return fc;
}

static inline vec3f bsdf_cosine_hemisphere(const shading_frame *f, const float u[2])
{
    float r = sqrtf(u[0]), sin_phi, cos_phi;
    sincos_turn(u[1], &sin_phi, &cos_phi);
    float z = sqrtf(f_max0(1.0f - u[0]));
    return f3_add(f3_add(f3_scale(f->t, r * cos_phi), f3_scale(f->b, r * sin_phi)),
                  f3_scale(f->n, z));
}

/* The diffuse lobe's part of bsdf_sample_material, once it is chosen; the
 * path tracer calls it directly for materials with no other lobe. */
static inline int bsdf_sample_diffuse(const rs_object *m, const shading_frame *f,
                                      const float u2[2], bsdf_sample *out)
{
    out->wi = bsdf_cosine_hemisphere(f, u2);
    out->pdf = m->weight[LOBE_DIFFUSE] * f3_dot(f->n, out->wi) * ZT_INV_PI;
    out->weight = m->color;
    out->delta = 0;
    out->transmit = 0;
    return out->pdf > 0.0f;
}

/* A thin pane (a material with "thin": its refractive lobe is a sheet of
 * glass): the light it reflects at cosine cos_i, both faces and their
 * inter-reflections counted, R = 2 r / (1 + r) for one face's r.  What it
 * does not reflect crosses it undeviated. */
float bsdf_pane_reflectance(float cos_i, float ior);

/* The part of light that crosses a pane-carrying material undeviated at
 * cosine cos_i: refractive weight x (1 - R) x tint. */
static inline vec3f bsdf_pane_transmittance(const rs_object *m, float cos_i)
{
    return f3_scale(m->tint, m->weight[LOBE_REFRACTIVE] *
                                 (1.0f - bsdf_pane_reflectance(cos_i, m->ior)));
}

/* What crosses a hit of coverage c on m undeviated at cosine cos_i, by
 * colour: the uncovered share 1 - c, and of the covered share what a pane
 * passes (nothing unless m is one).  For objects that rs_passes. */
static inline vec3f bsdf_pass_through(const rs_object *m, float c, float cos_i)
{
    vec3f t = f3_splat(1.0f - c);
    if (m->thin)
        t = f3_add(t, f3_scale(bsdf_pane_transmittance(m, cos_i), c));
    return t;
}

/* Whether lobe k of m is a GGX lobe. */
static inline int bsdf_lobe_rough(const rs_object *m, int k)
{
    return m->alpha > 0.0f && k != LOBE_DIFFUSE && m->weight[k] > 0.0f &&
           !(k == LOBE_REFRACTIVE && m->thin);
}

/* Lobe k's weight if it is smooth, else 0: what the deterministic
 * reflected and refracted rays carry beside the rough lobes. */
static inline float bsdf_smooth_weight(const rs_object *m, int k)
{
    return bsdf_lobe_rough(m, k) ? 0.0f : m->weight[k];
}

/* m's rough lobes for light arriving from wi and leaving toward wo (next-
 * event estimation): for each such lobe k, fcos[k] = weight x f x |cos_i|
 * (the colour apart) and pdf[k] = weight x the density of the lobe choosing
 * wi; other entries 0.  wi may be on either side of f->n (rough
 * transmission); eta_i, eta_t as for bsdf_sample_material. */
void bsdf_eval_rough(const rs_object *m, const shading_frame *f, vec3f wo, vec3f wi,
                     float eta_i, float eta_t, float fcos[LOBE_COUNT], float pdf[LOBE_COUNT]);

/* What the rough metallic lobe's fcos (bsdf_eval_rough) is to be
 * multiplied by, per channel, besides its colour: mirror_factor puts back
 * the light single scattering loses as a white lobe would (Turquin 2019,
 * 1 + F0 (1 - E) / E, F0 = the Fresnel's f0), where a coloured metal's F0
 * is its colour times f0 in each channel, and a second scattering inside
 * the roughness takes its colour twice: (1 + c f0 k) / (1 + f0 k), with
 * k = (1 - E) / E at cos_o (the shading normal's cosine with wo).  1
 * for white, and where the metallic lobe is smooth. */
vec3f bsdf_metal_tint(const rs_object *m, vec3f color, float cos_o);

/* Samples a direction from m's rough lobes among `lobes` (a mask of 1 << k),
 * one of them chosen by u_lobe in proportion to its weight; the rest as
 * for bsdf_sample_material.  Only out->wi, ->transmit and ->delta are of
 * use: bsdf_eval_rough gives every lobe's value and density there. */
int bsdf_sample_rough_lobes(const rs_object *m, unsigned lobes, const shading_frame *f, vec3f wo,
                            float u_lobe, float u_split, const float u2[2], float eta_i,
                            float eta_t, bsdf_sample *out);

/* Samples the material at a point with frame f (f->n facing the side of
 * wo, the direction towards the previous vertex).  u_lobe picks the lobe,
 * u_split reflection or transmission of the dielectric, u2 the diffuse
 * direction.  eta_i/eta_t are the indices on wo's side and on the far
 * side.  Returns 0 when the sample carries no light. */
int bsdf_sample_material(const rs_object *m, const shading_frame *f, vec3f wo, float u_lobe,
                         float u_split, const float u2[2], float eta_i,
                         float eta_t, bsdf_sample *out);

#endif
