/* The grids of the GGX albedo tables: cos_o from 0 to 1 (the first entry
 * just above 0, which is never seen), roughness = sqrt(alpha) from 0 to 1,
 * and the dielectric's eta from 1 to GGX_ETA_MAX and its inverses. */
#ifndef ZT_MATERIAL_MICROFACET_GRID_H
#define ZT_MATERIAL_MICROFACET_GRID_H

#include "material/microfacet.h"

#define GGX_COS_N 32
#define GGX_ROUGH_N 32
#define GGX_ETA_N 32
#define GGX_ETA_MAX 3.0f

static inline float ggx_grid_cos(int i)
{
    return i == 0 ? 1e-3f : (float)i / (GGX_COS_N - 1);
}

static inline float ggx_grid_alpha(int i)
{
    float r = (float)i / (GGX_ROUGH_N - 1);
    return f_max(r * r, GGX_ALPHA_MIN);
}

/* side 0: eta >= 1 (into a denser medium), side 1: its inverse. */
static inline float ggx_grid_eta(int side, int i)
{
    float e = 1.0f + (GGX_ETA_MAX - 1.0f) * (float)i / (GGX_ETA_N - 1);
    return side ? 1.0f / e : e;
}

#endif
