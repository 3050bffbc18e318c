/* GGX (Trowbridge-Reitz) written out in double precision for tests that
 * compute the expected light themselves rather than call the renderer's
 * microfacet.h: the distribution of normals at cosine cos_h to the
 * surface normal, and Smith's Lambda of a direction at cosine cos_w, for
 * alpha a.  Header-only. */
#ifndef ZT_TEST_GGX_REFERENCE_H
#define ZT_TEST_GGX_REFERENCE_H

#include <math.h>

static inline double ggx_ref_d(double cos_h, double a)
{
    double t = cos_h * cos_h * (a * a - 1) + 1;
    return a * a / (3.14159265358979323846 * t * t);
}

static inline double ggx_ref_lambda(double cos_w, double a)
{
    double z2 = cos_w * cos_w;
    return 0.5 * (sqrt(1 + a * a * (1 - z2) / z2) - 1);
}

#endif
