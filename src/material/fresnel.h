/* Fresnel reflectance of smooth interfaces, and refraction. */
#ifndef ZT_MATERIAL_FRESNEL_H
#define ZT_MATERIAL_FRESNEL_H

#include "util/vec3f.h"

/* Schlick's Fresnel with R0 from the index, as the original programs
 * meant "metallic" (indices below 1 give metal-like R0). */
static inline float bsdf_schlick(float cos_i, float ior)
{
    float r0 = (1.0f - ior) / (1.0f + ior);
    r0 *= r0;
    float m = 1.0f - f_clamp01(cos_i);
    float m2 = m * m;
    return r0 + (1.0f - r0) * m2 * m2 * m;
}

/* The clear layer over a diffuse base (a material's "specular", glTF's
 * dielectric layer over non-metals): Schlick's Fresnel with F0 = 0.04 (an
 * index of 1.5) and F90 = 1, which the layer's factor then scales. */
#define BSDF_COAT_F0 0.04f
static inline float bsdf_coat_fresnel(float cos_i)
{
    float m = 1.0f - f_clamp01(cos_i);
    float m2 = m * m;
    return BSDF_COAT_F0 + (1.0f - BSDF_COAT_F0) * m2 * m2 * m;
}

/* Unpolarised Fresnel reflectance of a smooth dielectric, going from index
 * eta_i into eta_t; 1 under total internal reflection. */
static inline float bsdf_fresnel_dielectric(float cos_i, float eta_i, float eta_t)
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

/* wo refracted about normal h (wo.h > 0) with eta = eta_i / eta_t into
 * *wt; 0 under total internal reflection. */
static inline int bsdf_refract(vec3f wo, vec3f h, float eta, vec3f *wt)
{
    float c = f3_dot(wo, h);
    float sin2_t = eta * eta * f_max0(1.0f - c * c);
    if (sin2_t >= 1.0f)
        return 0;
    float cos_t = sqrtf(1.0f - sin2_t);
    *wt = f3_sub(f3_scale(h, eta * c - cos_t), f3_scale(wo, eta));
    return 1;
}

#endif
