#include "material/bsdf.h"

#include "material/microfacet.h"

static int bsdf_sample_rough(const rs_object *m, int lobe, const shading_frame *f, vec3f wo,
                             float u_split, const float u2[2], float eta_i, float eta_t,
                             bsdf_sample *out);
static int sample_coat(const rs_object *m, const shading_frame *f, vec3f wo, float choice,
                       const float u2[2], bsdf_sample *out);


static vec3f reflect(vec3f wo, vec3f n)
{
    return f3_sub(f3_scale(n, 2.0f * f3_dot(wo, n)), wo);
}

float bsdf_pane_reflectance(float cos_i, float ior)
{
    float r = bsdf_fresnel_dielectric(cos_i, 1.0f, ior);
    return 2.0f * r / (1.0f + r);
}

int bsdf_sample_material(const rs_object *m, const shading_frame *f, vec3f wo, float u_lobe,
                         float u_split, const float u2[2], float eta_i,
                         float eta_t, bsdf_sample *out)
{
    vec3f n = f->n;
    /* Lobes are chosen with probability equal to their weights, so the
     * weights cancel from the throughput. */
    int lobe = LOBE_COUNT - 1;
    float acc = 0.0f;
    for (int k = 0; k < LOBE_COUNT; k++) {
        acc += m->weight[k];
        if (u_lobe < acc && m->weight[k] > 0.0f) {
            lobe = k;
            break;
        }
    }
    while (lobe > 0 && m->weight[lobe] <= 0.0f)
        lobe--;
    float cos_o = f3_dot(n, wo);
    out->transmit = 0;
    out->delta = lobe != LOBE_DIFFUSE;
    out->pdf = 0.0f;
    if (lobe != LOBE_DIFFUSE && bsdf_lobe_rough(m, lobe))
        return bsdf_sample_rough(m, lobe, f, wo, u_split, u2, eta_i, eta_t, out);
    switch (lobe) {
    case LOBE_DIFFUSE:
        if (m->coat) {
            /* u_lobe fell in [0, weight): its place there picks coat or
             * base. */
            float u = u_lobe / m->weight[LOBE_DIFFUSE], a = bsdf_coat_albedo(m, cos_o);
            if (u < a)
                return sample_coat(m, f, wo, a, u2, out);
            if (!bsdf_sample_diffuse(m, f, u2, out))
                return 0;
            out->pdf *= 1.0f - a;
            return out->pdf > 0.0f;
        }
        return bsdf_sample_diffuse(m, f, u2, out);
    case LOBE_METALLIC:
        out->wi = reflect(wo, n);
        out->weight = f3_scale(m->color, bsdf_schlick(cos_o, m->ior));
        return 1;
    case LOBE_REFLECTING:
        out->wi = reflect(wo, n);
        out->weight = m->color;
        return 1;
    default: {
        float f = bsdf_fresnel_dielectric(cos_o, eta_i, eta_t);
        /* A pane's vertex is its reflection: passing is not scattering
         * (the path tracer takes it before the vertex). */
        if (m->thin || u_split < f) {
            out->wi = reflect(wo, n);
            out->weight = m->color;
            return 1;
        }
        float eta = eta_i / eta_t;
        float sin2_t = eta * eta * (1.0f - cos_o * cos_o);
        float cos_t = sqrtf(f_max0(1.0f - sin2_t));
        out->wi = f3_normalize(f3_sub(f3_scale(f3_neg(wo), eta),
                                      f3_scale(n, cos_t - eta * cos_o)));
        /* Radiance is compressed entering a denser medium (L/eta^2 is
         * conserved); camera paths carry the factor the other way. */
        out->weight = f3_scale(m->color, eta * eta);
        out->transmit = 1;
        return 1;
    }
    }
}

/* ---- Rough lobes (GGX, material/microfacet.h) ---- */

static vec3f to_local(const shading_frame *f, vec3f v)
{
    return f3(f3_dot(v, f->t), f3_dot(v, f->b), f3_dot(v, f->n));
}

static vec3f from_local(const shading_frame *f, vec3f v)
{
    return f3_add(f3_add(f3_scale(f->t, v.x), f3_scale(f->b, v.y)), f3_scale(f->n, v.z));
}

/* Indices this close make the interface invisible: light crosses it
 * straight (the microfacets have no effect on it). */
static int index_matched(float eta_i, float eta_t)
{
    return fabsf(eta_t - eta_i) <= 1e-3f * eta_i;
}

/* A metallic or reflecting lobe's Fresnel factor at the microfacet (cos_h),
 * times the gain putting back what single scattering loses: with E the
 * white lobe's albedo at cos_o, f (1 + F0 (1 - E) / E) (Turquin 2019),
 * which for F = 1 is f / E, the whole of the light. */
static float mirror_factor(const rs_object *m, int lobe, float cos_o, float cos_h)
{
    float e = ggx_albedo_mirror(cos_o, m->alpha);
    if (lobe == LOBE_REFLECTING)
        return 1.0f / e;
    float f0 = bsdf_schlick(1.0f, m->ior);
    return bsdf_schlick(cos_h, m->ior) * (1.0f + f0 * (1.0f - e) / e);
}

vec3f bsdf_metal_tint(const rs_object *m, vec3f color, float cos_o)
{
    if (!bsdf_lobe_rough(m, LOBE_METALLIC) || !(cos_o > 0.0f))
        return f3_splat(1.0f);
    float e = ggx_albedo_mirror(cos_o, m->alpha);
    float fk = bsdf_schlick(1.0f, m->ior) * (1.0f - e) / e;
    return f3((1.0f + color.x * fk) / (1.0f + fk), (1.0f + color.y * fk) / (1.0f + fk),
              (1.0f + color.z * fk) / (1.0f + fk));
}

void bsdf_eval_rough(const rs_object *m, const shading_frame *f, vec3f wo, vec3f wi,
                     float eta_i, float eta_t, float fcos[LOBE_COUNT], float pdf[LOBE_COUNT])
{
    for (int k = 0; k < LOBE_COUNT; k++)
        fcos[k] = pdf[k] = 0.0f;
    vec3f o = to_local(f, wo), i = to_local(f, wi);
    if (!(o.z > 0.0f) || i.z == 0.0f)
        return;
    float a = m->alpha, g1 = ggx_g1(o, a), g2 = ggx_g2(o, i, a);
    if (i.z > 0.0f) {
        vec3f h = f3_normalize(f3_add(o, i));
        float c = f3_dot(o, h);
        if (!(c > 0.0f))
            return;
        float d = ggx_d(h, a), base = d / (4.0f * o.z);
        for (int k = LOBE_METALLIC; k <= LOBE_REFLECTING; k++)
            if (bsdf_lobe_rough(m, k)) {
                fcos[k] = m->weight[k] * base * g2 * mirror_factor(m, k, o.z, c);
                pdf[k] = m->weight[k] * base * g1;
            }
        if (m->coat) {
            /* In the diffuse lobe's entries: the coat's (white). */
            float ac = bsdf_coat_alpha(m), bc = ggx_d(h, ac) / (4.0f * o.z);
            float w = m->weight[LOBE_DIFFUSE];
            fcos[LOBE_DIFFUSE] = w * m->specular * bsdf_coat_fresnel(c) * bc * ggx_g2(o, i, ac);
            pdf[LOBE_DIFFUSE] = w * bsdf_coat_albedo(m, o.z) * bc * ggx_g1(o, ac);
        }
        if (bsdf_lobe_rough(m, LOBE_REFRACTIVE) && !index_matched(eta_i, eta_t)) {
            float fr = bsdf_fresnel_dielectric(c, eta_i, eta_t);
            float w = m->weight[LOBE_REFRACTIVE] * fr * base;
            fcos[LOBE_REFRACTIVE] = w * g2 / ggx_albedo_dielectric(o.z, a, eta_t / eta_i);
            pdf[LOBE_REFRACTIVE] = w * g1;
        }
        return;
    }
    if (!bsdf_lobe_rough(m, LOBE_REFRACTIVE) || index_matched(eta_i, eta_t))
        return;
    /* Transmission (Walter et al. 2007): the generalised half vector. */
    float etap = eta_t / eta_i;
    vec3f h = f3_normalize(f3_add(o, f3_scale(i, etap)));
    if (h.z < 0.0f)
        h = f3_neg(h);
    float co = f3_dot(o, h), ci = f3_dot(i, h);
    if (!(co > 0.0f) || !(ci < 0.0f))
        return;
    float fr = bsdf_fresnel_dielectric(co, eta_i, eta_t);
    float denom = ci + co / etap;
    denom *= denom;
    float d = ggx_d(h, a);
    float w = m->weight[LOBE_REFRACTIVE] * (1.0f - fr) * d * -ci / (o.z * denom);
    /* Radiance is compressed entering a denser medium, as in the smooth
     * lobe: camera paths carry (eta_i / eta_t)^2. */
    fcos[LOBE_REFRACTIVE] = w * co * g2 / (etap * etap * ggx_albedo_dielectric(o.z, a, etap));
    pdf[LOBE_REFRACTIVE] = w * co * g1;
}

int bsdf_sample_rough_lobes(const rs_object *m, unsigned lobes, const shading_frame *f, vec3f wo,
                            float u_lobe, float u_split, const float u2[2], float eta_i,
                            float eta_t, bsdf_sample *out)
{
    if (lobes == 1u << LOBE_DIFFUSE)
        return m->coat && sample_coat(m, f, wo, 1.0f, u2, out);
    float total = 0.0f;
    for (int k = 0; k < LOBE_COUNT; k++)
        if ((lobes >> k & 1u) && bsdf_lobe_rough(m, k))
            total += m->weight[k];
    if (!(total > 0.0f))
        return 0;
    int lobe = -1;
    float acc = 0.0f;
    for (int k = 0; k < LOBE_COUNT; k++)
        if ((lobes >> k & 1u) && bsdf_lobe_rough(m, k)) {
            lobe = k;
            acc += m->weight[k];
            if (u_lobe * total < acc)
                break;
        }
    return bsdf_sample_rough(m, lobe, f, wo, u_split, u2, eta_i, eta_t, out);
}

static int bsdf_sample_rough(const rs_object *m, int lobe, const shading_frame *f, vec3f wo,
                             float u_split, const float u2[2], float eta_i, float eta_t,
                             bsdf_sample *out)
{
    vec3f o = to_local(f, wo);
    if (!(o.z > 0.0f))
        return 0;
    float a = m->alpha;
    out->delta = 0;
    out->transmit = 0;
    if (lobe == LOBE_REFRACTIVE && index_matched(eta_i, eta_t)) {
        out->wi = f3_neg(wo);
        out->weight = m->color;
        out->delta = 1;
        out->transmit = 1;
        out->pdf = 0.0f;
        return 1;
    }
    vec3f h = ggx_sample_vndf(o, a, u2);
    float c = f3_dot(o, h);
    if (!(c > 0.0f))
        return 0;
    float g1 = ggx_g1(o, a), d = ggx_d(h, a);
    float gain, choice = 1.0f;
    vec3f i;
    if (lobe != LOBE_REFRACTIVE) {
        gain = mirror_factor(m, lobe, o.z, c);
        i = f3_sub(f3_scale(h, 2.0f * c), o);
    } else {
        float fr = bsdf_fresnel_dielectric(c, eta_i, eta_t);
        gain = 1.0f / ggx_albedo_dielectric(o.z, a, eta_t / eta_i);
        if (u_split < fr) {
            i = f3_sub(f3_scale(h, 2.0f * c), o);
            choice = fr;
        } else {
            float etap = eta_t / eta_i;
            if (!bsdf_refract(o, h, 1.0f / etap, &i) || !(i.z < 0.0f))
                return 0;
            choice = 1.0f - fr;
            float ci = f3_dot(i, h), denom = ci + c / etap;
            denom *= denom;
            out->wi = f3_normalize(from_local(f, i));
            out->weight = f3_scale(m->color, ggx_g2(o, i, a) / g1 * gain / (etap * etap));
            out->pdf = m->weight[lobe] * g1 * c * d / o.z * choice * -ci / denom;
            out->transmit = 1;
            return out->pdf > 0.0f;
        }
    }
    if (!(i.z > 0.0f))
        return 0;
    out->wi = f3_normalize(from_local(f, i));
    out->weight = f3_scale(m->color, ggx_g2(o, i, a) / g1 * gain);
    if (lobe == LOBE_METALLIC)
        out->weight = f3_mul(out->weight, bsdf_metal_tint(m, m->color, o.z));
    out->pdf = m->weight[lobe] * g1 * d / (4.0f * o.z) * choice;
    return out->pdf > 0.0f;
}

/* The coat's direction (bsdf.h), chosen with probability `choice` once
 * the diffuse lobe is: visible normals of its alpha; the weight is white. */
static int sample_coat(const rs_object *m, const shading_frame *f, vec3f wo, float choice,
                       const float u2[2], bsdf_sample *out)
{
    vec3f o = to_local(f, wo);
    if (!(o.z > 0.0f) || !(choice > 0.0f))
        return 0;
    float a = bsdf_coat_alpha(m);
    vec3f h = ggx_sample_vndf(o, a, u2);
    float c = f3_dot(o, h);
    if (!(c > 0.0f))
        return 0;
    vec3f i = f3_sub(f3_scale(h, 2.0f * c), o);
    if (!(i.z > 0.0f))
        return 0;
    float g1 = ggx_g1(o, a);
    out->wi = f3_normalize(from_local(f, i));
    out->weight = f3_splat(m->specular * bsdf_coat_fresnel(c) * ggx_g2(o, i, a) / (g1 * choice));
    out->pdf = m->weight[LOBE_DIFFUSE] * choice * g1 * ggx_d(h, a) / (4.0f * o.z);
    out->delta = 0;
    out->transmit = 0;
    return out->pdf > 0.0f;
}
