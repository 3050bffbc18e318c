#include "zone/lambert.h"

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
            /* atan2 keeps the angle accurate for nearly parallel vectors. */
            double theta = atan2(s, v3_dot(a, b));
            sum += theta * v3_dot(n, c) / s;
        }
        a = b;
    }
    return 0.5 * fabs(sum);
}
