/* Moving and turning the camera: viewpoint and screen move together, and
 * turns rotate the screen's corners about the viewpoint (Rodrigues). */
#include <math.h>

#include "viewer.h"

static void sub(const double a[3], const double b[3], double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = a[k] - b[k];
}

static void normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0)
        for (int k = 0; k < 3; k++)
            v[k] /= l;
}

static void cross(const double a[3], const double b[3], double out[3])
{
    double r[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    for (int k = 0; k < 3; k++)
        out[k] = r[k];
}

void vcam_axes(const zt_camera *c, double right[3], double up[3],
               double back[3], double forward[3])
{
    sub(c->screen[1], c->screen[0], right);
    sub(c->screen[0], c->screen[2], up);
    normalize(right);
    normalize(up);
    cross(right, up, back);
    normalize(back);
    /* the centre of the parallelogram TL, TR, BL */
    double centre[3];
    for (int k = 0; k < 3; k++)
        centre[k] = 0.5 * (c->screen[1][k] + c->screen[2][k]);
    sub(centre, c->viewpoint, forward);
    normalize(forward);
}

void vcam_translate(zt_camera *c, const double d[3])
{
    for (int k = 0; k < 3; k++) {
        c->viewpoint[k] += d[k];
        for (int i = 0; i < 4; i++)
            c->screen[i][k] += d[k];
    }
}

void vcam_rotate(zt_camera *c, const double axis[3], double angle)
{
    double cs = cos(angle), sn = sin(angle);
    for (int i = 0; i < 4; i++) {
        double v[3], kxv[3];
        sub(c->screen[i], c->viewpoint, v);
        cross(axis, v, kxv);
        double kv = axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2];
        for (int k = 0; k < 3; k++)
            c->screen[i][k] = c->viewpoint[k] + v[k] * cs + kxv[k] * sn +
                              axis[k] * kv * (1.0 - cs);
    }
}
