/* Multiple importance sampling: Veach's power heuristic (exponent 2), used
 * by the path tracer and by the zone tracer's rough lobes. */
#ifndef ZT_LIGHT_MIS_H
#define ZT_LIGHT_MIS_H

static inline float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* power_heuristic(a, b) / a for a > 0: one division instead of two. */
static inline float power_heuristic_over(float a, float b)
{
    return a / (a * a + b * b);
}

#endif
