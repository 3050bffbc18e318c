#include "zone/light/lambert.h"

/* atan(z) for |z| <= tan(pi/8), by its series to z^17: error under 2e-8
 * there, far below what float maps hold, at a fraction of atan2's cost. */
static double atan_small(double z)
{
    double z2 = z * z;
    double p = 1.0 / 17;
    p = p * z2 - 1.0 / 15;
    p = p * z2 + 1.0 / 13;
    p = p * z2 - 1.0 / 11;
    p = p * z2 + 1.0 / 9;
    p = p * z2 - 1.0 / 7;
    p = p * z2 + 1.0 / 5;
    p = p * z2 - 1.0 / 3;
    p = p * z2 + 1.0;
    return z * p;
}

/* The angle atan2(s, c) for s > 0, in [0, pi]. */
static double angle_of(double s, double c)
{
    const double pi = 3.14159265358979323846;
    if (c < 0) /* obtuse */
        return pi - angle_of(s, -c);
    double t = s <= c ? s / c : c / s; /* in (0, 1] */
    double a = t <= 0.41421356237309503 ? atan_small(t)
                                         : 0.25 * pi + atan_small((t - 1.0) / (t + 1.0));
    return s <= c ? a : 0.5 * pi - a;
}

double lambert_polygon(vec3 x, vec3 n, const vec3 *q, int count)
{
    if (count < 3)
        return 0.0;
    double sum = 0.0;
    vec3 a = v3_normalize(v3_sub(q[count - 1], x));
    for (int i = 0; i < count; i++) {
        vec3 b = v3_normalize(v3_sub(q[i], x));
        vec3 c = v3_cross(a, b);
        double s = v3_length(c);
        if (s > 0.0) {
            /* From the sine and cosine: accurate for nearly parallel
             * vectors, where acos is not. */
            double theta = angle_of(s, v3_dot(a, b));
            sum += theta * v3_dot(n, c) / s;
        }
        a = b;
    }
    return 0.5 * fabs(sum);
}
