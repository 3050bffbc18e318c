/* Unpolarised Fresnel reflectance from index n1 into n2 (1 under total
 * internal reflection), in double precision, for tests that compute the
 * expected light themselves rather than call the renderer's own formula.
 * Header-only. */
#ifndef ZT_TEST_FRESNEL_H
#define ZT_TEST_FRESNEL_H

#include <math.h>

static inline double fresnel(double cos_i, double n1, double n2)
{
    double sin2_t = (n1 / n2) * (n1 / n2) * (1 - cos_i * cos_i);
    if (sin2_t >= 1)
        return 1;
    double cos_t = sqrt(1 - sin2_t);
    double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

#endif
