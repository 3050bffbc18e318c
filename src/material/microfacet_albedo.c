/* Lookups in the GGX albedo tables (material/microfacet_grid.h), which the
 * build makes with material/gen/ggx_albedo_gen.c. */
#include "material/microfacet.h"
#include "material/microfacet_grid.h"

#include "ggx_albedo_tables.h"

/* The roughness row below alpha and the fraction toward the next. */
static int rough_row(float alpha, float *fy)
{
    float y = f_clamp01(sqrtf(alpha)) * (GGX_ROUGH_N - 1);
    int yi = (int)y;
    if (yi > GGX_ROUGH_N - 2)
        yi = GGX_ROUGH_N - 2;
    *fy = y - (float)yi;
    return yi;
}

/* Bilinear lookup in one [roughness][cos] slice. */
static float lookup(const float t[GGX_ROUGH_N][GGX_COS_N], float cos_o, float alpha)
{
    float x = f_clamp01(cos_o) * (GGX_COS_N - 1), fy;
    int xi = (int)x, yi = rough_row(alpha, &fy);
    if (xi > GGX_COS_N - 2)
        xi = GGX_COS_N - 2;
    float fx = x - (float)xi;
    float a = t[yi][xi] + fx * (t[yi][xi + 1] - t[yi][xi]);
    float b = t[yi + 1][xi] + fx * (t[yi + 1][xi + 1] - t[yi + 1][xi]);
    return a + fy * (b - a);
}

float ggx_albedo_mirror(float cos_o, float alpha)
{
    return lookup(ggx_mirror_albedo, cos_o, alpha);
}

float ggx_albedo_coat(float cos_o, float alpha)
{
    return lookup(ggx_coat_albedo, cos_o, alpha);
}

float ggx_albedo_coat_average(float alpha)
{
    float fy;
    int yi = rough_row(alpha, &fy);
    return ggx_coat_average[yi] + fy * (ggx_coat_average[yi + 1] - ggx_coat_average[yi]);
}

float ggx_albedo_dielectric(float cos_o, float alpha, float eta)
{
    int side = eta < 1.0f;
    float e = side ? 1.0f / eta : eta;
    float z = (f_max(e, 1.0f) - 1.0f) / (GGX_ETA_MAX - 1.0f) * (GGX_ETA_N - 1);
    if (z > GGX_ETA_N - 1)
        z = GGX_ETA_N - 1;
    int zi = (int)z;
    if (zi > GGX_ETA_N - 2)
        zi = GGX_ETA_N - 2;
    float fz = z - (float)zi;
    float a = lookup(ggx_dielectric_albedo[side][zi], cos_o, alpha);
    float b = lookup(ggx_dielectric_albedo[side][zi + 1], cos_o, alpha);
    return a + fz * (b - a);
}
