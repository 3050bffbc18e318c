/* Roberts' R2 sequence: the additive recurrence on the plastic number g
 * (g^3 = g + 1), whose every prefix is spread evenly over the unit square
 * and which lines up with no direction. */
#ifndef ZT_UTIL_R2_H
#define ZT_UTIL_R2_H

#include <math.h>

/* Point j of the sequence, in [0, 1)^2. */
static inline void r2_point(double j, double *u, double *v)
{
    const double g = 1.32471795724474602596;
    double a = 0.5 + j / g, b = 0.5 + j / (g * g);
    *u = a - floor(a);
    *v = b - floor(b);
}

#endif
