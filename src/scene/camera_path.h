/* A motions file's camera path (docs/viewer.md): keys of position, look-at
 * point, up and fov at given times, and the camera between them.
 *
 * The position and the look-at point each follow a centripetal Catmull-Rom
 * curve through the keys (alpha = 0.5, evaluated by Barry and Goldman's
 * pyramid).  The curve's own parameter runs at its own pace, so time is
 * mapped onto it by a monotone cubic through (key time, key parameter);
 * the up vector's components and the fov follow the same kind of monotone
 * cubic over time.  Its slopes are 0 at the first and the last key, where
 * the camera comes to rest (it holds still outside the keys), so the whole
 * motion is C1 in time. */
#ifndef ZT_SCENE_CAMERA_PATH_H
#define ZT_SCENE_CAMERA_PATH_H

#include "zonetrace/motion.h"

/* What is interpolated over time: the curve parameters of the position and
 * of the look-at point, the unit up's three components, the fov. */
enum { PATH_POSITION, PATH_LOOKAT, PATH_UP, PATH_FOV = PATH_UP + 3, PATH_CHANNELS };

typedef struct camera_path {
    zt_camera_key *keys; /* count >= 2 when there is a path, times increasing */
    int count;
    double (*value)[PATH_CHANNELS]; /* per key */
    double (*slope)[PATH_CHANNELS]; /* per key: d value / d time */
} camera_path;

/* Computes value and slope from the keys.  Returns 0 when out of memory. */
int camera_path_prepare(camera_path *p);

/* Frees the arrays (keys included) and zeroes p. */
void camera_path_free(camera_path *p);

/* The camera at time t (any number): before the first key the first key,
 * after the last the last, at a key's time exactly that key's values (up as
 * written), between keys the interpolation (up of unit length, or zero when
 * the interpolated direction vanishes). */
void camera_path_at(const camera_path *p, double t, double position[3], double lookat[3],
                    double up[3], double *fov);

/* The last key at or before t: -1 before the first key, count - 1 from the
 * last one on. */
int camera_path_segment(const camera_path *p, double t);

#endif
