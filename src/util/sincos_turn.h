/* sin and cos of a fraction of a full turn, 2 pi u for u in [0, 1), for
 * the sampling routines.  Inline polynomials instead of libm's sincosf:
 * the call spilled every float register of the path tracer's loop.
 * Absolute error below 1e-7 (tests/test_sampling_math.c checks it). */
#ifndef ZT_UTIL_SINCOS_TURN_H
#define ZT_UTIL_SINCOS_TURN_H

static inline void sincos_turn(float u, float *s, float *c)
{
    /* The nearest quarter turn q and the rest a in [-pi/4, pi/4]. */
    float x = 4.0f * u;
    int q = (int)(x + 0.5f);
    float a = (x - (float)q) * 1.57079632679490f;
    float a2 = a * a;
    /* Taylor series to a^9 and a^8: truncation below 2.5e-8 on the range. */
    float sa = a * (1.0f + a2 * (-1.0f / 6 + a2 * (1.0f / 120 + a2 * (-1.0f / 5040 +
                                                                  a2 * (1.0f / 362880)))));
    float ca = 1.0f + a2 * (-0.5f + a2 * (1.0f / 24 + a2 * (-1.0f / 720 + a2 * (1.0f / 40320))));
    /* Rotate by q quarter turns. */
    float sq = (q & 1) ? ca : sa, cq = (q & 1) ? sa : ca;
    *s = (q & 2) ? -sq : sq;
    *c = ((q + 1) & 2) ? -cq : cq;
}

#endif
