/* Build tool: writes the tables of material/microfacet_albedo.c to stdout
 * as a C header.  Each entry is the single-scattering albedo of a white GGX
 * lobe seen at cos_o: the mean of its sampling weight G2/G1 over visible
 * normals from a Hammersley set, reflection and transmission weighed by
 * Fresnel (no choice is drawn).  The grids are in microfacet_grid.h. */
#include <stdio.h>

#include "material/fresnel.h"
#include "material/microfacet.h"
#include "material/microfacet_grid.h"

#define TABLE_SAMPLES 1024

static float radical_inverse2(unsigned i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return (float)i * 2.3283064365386963e-10f;
}

static vec3f reflect_about(vec3f wo, vec3f h)
{
    return f3_sub(f3_scale(h, 2.0f * f3_dot(wo, h)), wo);
}

/* eta 0 means the mirror (F = 1, reflection only); COAT the clear layer
 * over a diffuse base (Schlick's F with F0 = 0.04, reflection only). */
#define COAT (-1.0f)
static double albedo(float cos_o, float alpha, float eta)
{
    vec3f wo = f3(sqrtf(f_max0(1.0f - cos_o * cos_o)), 0.0f, cos_o);
    double sum = 0.0;
    for (unsigned i = 0; i < TABLE_SAMPLES; i++) {
        float u[2] = {((float)i + 0.5f) / TABLE_SAMPLES, radical_inverse2(i)};
        vec3f h = ggx_sample_vndf(wo, alpha, u);
        float c = f3_dot(wo, h);
        float f = eta > 0.0f    ? bsdf_fresnel_dielectric(c, 1.0f, eta)
                  : eta == COAT ? bsdf_coat_fresnel(c)
                                : 1.0f;
        float g = 1.0f / ggx_g1(wo, alpha);
        vec3f wr = reflect_about(wo, h);
        if (wr.z > 0.0f)
            sum += f * ggx_g2(wo, wr, alpha) * g;
        vec3f wt;
        if (eta > 0.0f && f < 1.0f && bsdf_refract(wo, h, 1.0f / eta, &wt) && wt.z < 0.0f)
            sum += (1.0f - f) * ggx_g2(wo, wt, alpha) * g;
    }
    return sum / TABLE_SAMPLES;
}

static void row(int ri, float eta)
{
    printf("    {");
    for (int ci = 0; ci < GGX_COS_N; ci++)
        printf("%.6ff%s", albedo(ggx_grid_cos(ci), ggx_grid_alpha(ri), eta),
               ci + 1 < GGX_COS_N ? ", " : "},\n");
}

int main(void)
{
    printf("/* Made by material/gen/ggx_albedo_gen.c when the program is built. */\n");
    printf("static const float ggx_mirror_albedo[GGX_ROUGH_N][GGX_COS_N] = {\n");
    for (int ri = 0; ri < GGX_ROUGH_N; ri++)
        row(ri, 0.0f);
    printf("};\n");
    printf("static const float ggx_coat_albedo[GGX_ROUGH_N][GGX_COS_N] = {\n");
    for (int ri = 0; ri < GGX_ROUGH_N; ri++)
        row(ri, COAT);
    printf("};\n");
    /* The coat's albedo averaged over cosine-weighted directions,
     * 2 int E(mu) mu dmu, by the midpoint rule on a finer grid. */
    printf("static const float ggx_coat_average[GGX_ROUGH_N] = {");
    for (int ri = 0; ri < GGX_ROUGH_N; ri++) {
        double sum = 0.0;
        for (int k = 0; k < 64; k++) {
            float mu = ((float)k + 0.5f) / 64.0f;
            sum += albedo(mu, ggx_grid_alpha(ri), COAT) * mu;
        }
        printf("%.6ff%s", 2.0 * sum / 64.0, ri + 1 < GGX_ROUGH_N ? ", " : "};\n");
    }
    printf("static const float ggx_dielectric_albedo[2][GGX_ETA_N][GGX_ROUGH_N][GGX_COS_N] = {\n");
    for (int side = 0; side < 2; side++) {
        printf("  {\n");
        for (int ei = 0; ei < GGX_ETA_N; ei++) {
            printf("   {\n");
            for (int ri = 0; ri < GGX_ROUGH_N; ri++)
                row(ri, ggx_grid_eta(side, ei));
            printf("   },\n");
        }
        printf("  },\n");
    }
    printf("};\n");
    return 0;
}
