/* A camera aimed at a point, as the four screen corners the renderers use. */
#include "zonetrace/scene.h"

#include <math.h>

#include "util/error.h"
#include "util/vec3.h"

/* The screen sits this fraction of the distance to the look-at point in
 * front of the eye: it is also the near plane (nothing nearer is seen). */
#define NEAR_FRACTION 1e-3

zt_status zt_camera_look_at(zt_camera *out, const double position[3], const double lookat[3],
                            const double up[3], double fov_degrees, int width, int height,
                            zt_error *err)
{
    vec3 eye = v3_from(position), at = v3_from(lookat), upv = v3_from(up);
    vec3 f = v3_sub(at, eye);
    double dist = v3_length(f);
    if (!(dist > 0) || !isfinite(dist))
        return zt_fail(err, ZT_ERR_ARGUMENT, "the camera's position and look-at point coincide");
    if (!(fov_degrees > 0 && fov_degrees < 180))
        return zt_fail(err, ZT_ERR_ARGUMENT, "fov %g is out of range (0 to 180 degrees, "
                       "exclusive)", fov_degrees);
    f = v3_scale(f, 1.0 / dist);
    vec3 r = v3_cross(f, upv);
    double lr = v3_length(r);
    if (!(lr > 1e-9 * v3_length(upv)))
        return zt_fail(err, ZT_ERR_ARGUMENT, "the camera's up direction is zero or parallel "
                       "to its view direction");
    r = v3_scale(r, 1.0 / lr);
    vec3 u = v3_cross(r, f);
    zt_status st = zt_camera_set_resolution(out, width, height, err);
    if (st != ZT_OK)
        return st;
    double near = NEAR_FRACTION * dist;
    double half_h = near * tan(fov_degrees * 3.14159265358979323846 / 360.0);
    double half_w = half_h * width / height;
    vec3 c = v3_add(eye, v3_scale(f, near));
    vec3 dx = v3_scale(r, half_w), dy = v3_scale(u, half_h);
    v3_store(eye, out->viewpoint);
    v3_store(v3_add(v3_sub(c, dx), dy), out->screen[0]);
    v3_store(v3_add(v3_add(c, dx), dy), out->screen[1]);
    v3_store(v3_sub(v3_sub(c, dx), dy), out->screen[2]);
    v3_store(v3_sub(v3_add(c, dx), dy), out->screen[3]);
    return ZT_OK;
}
