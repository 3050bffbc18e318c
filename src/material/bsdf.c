#include "material/bsdf.h"


static vec3f reflect(vec3f wo, vec3f n)
{
    return f3_sub(f3_scale(n, 2.0f * f3_dot(wo, n)), wo);
}

float bsdf_schlick(float cos_i, float ior)
{
    float r0 = (1.0f - ior) / (1.0f + ior);
    r0 *= r0;
    float m = 1.0f - f_clamp01(cos_i);
    float m2 = m * m;
    return r0 + (1.0f - r0) * m2 * m2 * m;
}

float bsdf_fresnel_dielectric(float cos_i, float eta_i, float eta_t)
{
    cos_i = f_clamp01(cos_i);
    float eta = eta_i / eta_t;
    float sin2_t = eta * eta * (1.0f - cos_i * cos_i);
    if (sin2_t >= 1.0f)
        return 1.0f;
    float cos_t = sqrtf(1.0f - sin2_t);
    float rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    float rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    return 0.5f * (rs * rs + rp * rp);
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
    switch (lobe) {
    case LOBE_DIFFUSE:
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
