/* Rough lobes: the GGX (Trowbridge-Reitz) distribution of microfacet
 * normals with alpha = roughness^2, Smith's height-correlated masking and
 * shadowing, and sampling of the normals visible from wo (Heitz 2018).
 * Vectors here are in the shading frame: +z is the normal on wo's side.
 *
 * One bounce off the microfacets loses the light that would scatter again
 * among them; the energy tables put it back (docs/light-transport.md,
 * "Rough lobes"): a lobe's single-scattering albedo E(cos_o) is tabulated
 * once, and the lobe is scaled so that a white one returns all its light. */
#ifndef ZT_MATERIAL_MICROFACET_H
#define ZT_MATERIAL_MICROFACET_H

#include "util/sincos_turn.h"
#include "util/vec3f.h"

/* Below this alpha a lobe is computed with this alpha: D's peak 1/(pi
 * alpha^2) stays finite in float. */
#define GGX_ALPHA_MIN 1e-4f

static inline float ggx_d(vec3f h, float alpha)
{
    /* a2 / (pi (z^2 (a2 - 1) + 1)^2) for unit h, written with the
     * tangential part so that at alpha^2 below float's resolution of 1 the
     * peak stays 1 / (pi a2) instead of a division by zero. */
    float a2 = alpha * alpha;
    float t = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
    return 1.0f / (3.14159265358979f * a2 * t * t);
}

/* Smith's Lambda for direction w (w.z != 0). */
static inline float ggx_lambda(vec3f w, float alpha)
{
    float z2 = w.z * w.z;
    float tan2 = f_max0(1.0f - z2) / z2;
    return 0.5f * (sqrtf(1.0f + alpha * alpha * tan2) - 1.0f);
}

static inline float ggx_g1(vec3f w, float alpha)
{
    return 1.0f / (1.0f + ggx_lambda(w, alpha));
}

/* Height-correlated masking-shadowing of the pair. */
static inline float ggx_g2(vec3f wo, vec3f wi, float alpha)
{
    return 1.0f / (1.0f + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}

/* A microfacet normal visible from wo (wo.z > 0), with density
 * G1(wo) max(0, wo.h) D(h) / wo.z: stretch to the hemisphere configuration, sample the
 * projected hemisphere seen from there, and unstretch. */
static inline vec3f ggx_sample_vndf(vec3f wo, float alpha, const float u[2])
{
    vec3f vh = f3_normalize(f3(alpha * wo.x, alpha * wo.y, wo.z));
    float len2 = vh.x * vh.x + vh.y * vh.y;
    vec3f t1 = len2 > 0.0f ? f3_scale(f3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(len2))
                           : f3(1.0f, 0.0f, 0.0f);
    vec3f t2 = f3_cross(vh, t1);
    float r = sqrtf(u[0]), s_phi, c_phi;
    sincos_turn(u[1], &s_phi, &c_phi);
    float p1 = r * c_phi, p2 = r * s_phi;
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrtf(f_max0(1.0f - p1 * p1)) + s * p2;
    vec3f nh = f3_add(f3_add(f3_scale(t1, p1), f3_scale(t2, p2)),
                      f3_scale(vh, sqrtf(f_max0(1.0f - p1 * p1 - p2 * p2))));
    return f3_normalize(f3(alpha * nh.x, alpha * nh.y, f_max(nh.z, 1e-6f)));
}

/* Single-scattering albedo of a white rough mirror (F = 1) seen at cos_o,
 * and of a rough dielectric interface (reflection plus transmission, in
 * energy) with eta = index beyond / index on wo's side.  Interpolated in
 * tables made when the program is built (material/gen/ggx_albedo_gen.c);
 * eta is clamped to [1/3, 3] for the lookup. */
float ggx_albedo_mirror(float cos_o, float alpha);
float ggx_albedo_dielectric(float cos_o, float alpha, float eta);
/* The clear coat's (bsdf_coat_fresnel, reflection only) albedo at cos_o,
 * and its average over cosine-weighted directions, 2 int E(mu) mu dmu:
 * what the coat reflects of light arriving evenly from every side. */
float ggx_albedo_coat(float cos_o, float alpha);
float ggx_albedo_coat_average(float alpha);

#endif
