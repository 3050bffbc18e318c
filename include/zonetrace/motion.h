/* zonetrace: motions.
 *
 * A motions file (the original programs' "-m/--motions" file, see
 * docs/viewer.md) makes lights and things move over time, and may give the
 * camera a path through timed keys:
 *
 *     { "motions": [
 *         { "light": 0, "type": "orbiting", "axis": "Z", "period": 20 },
 *         { "thing": 2, "type": "brownian", "scale": 1 },
 *         { "camera": "path", "keys": [
 *             { "time": 0, "position": [0, 1, -8], "lookat": [0, 1, 0] },
 *             { "time": 4, "position": [6, 2, -6], "lookat": [0, 0, 0], "fov": 30 } ] }
 *     ] }
 *
 * Motions are evaluated in closed form: the scene at time t depends only on
 * the scene at time 0, t and a seed, never on how often it was evaluated,
 * so the viewer (at any frame rate) and the offline animation agree.
 * Motions files are untrusted: problems are reported as ZT_ERR_READ or
 * ZT_ERR_PARSE with "file:line:column: what is wrong", like scene files.
 */
#ifndef ZONETRACE_MOTION_H
#define ZONETRACE_MOTION_H

#include <stddef.h>
#include <stdint.h>
#include "zonetrace/error.h"
#include "zonetrace/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum zt_motion_type {
    ZT_MOTION_LINEAR = 0,      /* delta * t, at most `stop` units far */
    ZT_MOTION_ORBITING = 1,    /* rotation about a world axis */
    ZT_MOTION_OSCILLATING = 2, /* to and fro along end - begin */
    ZT_MOTION_BROWNIAN = 3     /* a seeded random walk */
} zt_motion_type;

/* One motion as read from the file. */
typedef struct zt_motion {
    zt_motion_type type;
    zt_object_class target_class; /* "light" or "thing" */
    int target;                   /* index among the lights or the things */
    double delta[3];              /* linear: velocity, units per second */
    double stop;                  /* linear: maximum distance; < 0 unlimited */
    int axis;                     /* orbiting: 0 = X, 1 = Y, 2 = Z */
    double period;                /* orbiting, oscillating: seconds, != 0 */
    double begin[3], end[3];      /* oscillating */
    double scale;                 /* brownian: speed, units per second */
    int line, column;             /* where the motion's target is written */
} zt_motion;

/* One key of a camera path, as read from the file. */
typedef struct zt_camera_key {
    double time;          /* seconds; the keys' times increase strictly */
    double position[3];
    double lookat[3];     /* != position */
    double up[3];         /* as written (default 0, 1, 0); not parallel to
                             lookat - position */
    double fov;           /* vertical, degrees, 0 < fov < 180 (default 40) */
    int line, column;     /* where the key's "{" is written */
} zt_camera_key;

typedef struct zt_motions zt_motions;

/* Loads a motions file.  *out is a new list owned by the caller. */
zt_status zt_motions_load_file(const char *path, zt_motions **out,
                               zt_error *err);

/* The same from memory; name is used in messages only. */
zt_status zt_motions_load_string(const char *text, size_t length,
                                 const char *name, zt_motions **out,
                                 zt_error *err);

/* Frees a list.  NULL is allowed. */
void zt_motions_release(zt_motions *motions);

/* The number of motions of lights and things and motion i (0 <= i <
 * count) in file order.  A camera path is not one of them. */
int zt_motions_count(const zt_motions *motions);
const zt_motion *zt_motions_get(const zt_motions *motions, int i);

/* Whether any motion moves a light or a thing.  When none does, the scene
 * stands still and only the camera may move: one renderer (and the zone
 * tracer's forest) serves every time. */
int zt_motions_moves_objects(const zt_motions *motions);

/* The keys of the file's camera path in time order, their number in *count
 * (at least 2); NULL and 0 when the file has no camera path. */
const zt_camera_key *zt_motions_camera_path(const zt_motions *motions, int *count);

/* The camera at time t_seconds (>= 0): with a camera path, the path's
 * camera at that time, aimed (as zt_camera_look_at makes it) on the pixel
 * grid of scene_at_time0's camera, which it replaces whatever its form;
 * without one, scene_at_time0's camera.  At a key's time the camera is
 * exactly the one a scene file with that key's position, lookat, up and
 * fov gives.  Fails with ZT_ERR_ARGUMENT for a bad time, and with
 * ZT_ERR_PARSE and "file:line:column: ..." at the earlier key when the
 * camera between two keys is degenerate at that time (the interpolated
 * position meets the look-at point, or up turns parallel to the view). */
zt_status zt_motions_camera(const zt_motions *motions, const zt_scene *scene_at_time0,
                            double t_seconds, zt_camera *out, zt_error *err);

/* Checks every target index against the scene's lights and things.  Fails
 * with ZT_ERR_PARSE and "file:line:column: ..." at the first motion whose
 * object does not exist. */
zt_status zt_motions_check(const zt_motions *motions, const zt_scene *scene,
                           zt_error *err);

/* Sets the objects of scene_out to those of scene_at_time0 moved to their
 * positions at time t_seconds (>= 0).  scene_out must be a clone of
 * scene_at_time0 (zt_scene_clone) or an earlier result of this call for
 * it.  With a camera path its camera is set to zt_motions_camera's;
 * without one it is left as it is.  Motions are applied in file order,
 * each to the result of the ones before it.  The result depends only on
 * the arguments (seed drives the brownian motions).  Fails with
 * ZT_ERR_ARGUMENT for a bad time (brownian motions: beyond 10^6 s), scenes
 * that do not match, or a target that does not exist (call
 * zt_motions_check first for a located message), and as zt_motions_camera
 * does for a degenerate camera.
 * Thread-safe for one motions list used by several threads. */
zt_status zt_motions_apply(const zt_motions *motions,
                           const zt_scene *scene_at_time0, double t_seconds,
                           uint64_t seed, zt_scene *scene_out, zt_error *err);

#ifdef __cplusplus
}
#endif
#endif
