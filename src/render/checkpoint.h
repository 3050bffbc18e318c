/* Checkpoints of a path-traced render: the running sums of every pixel and
 * the number of samples in them, so a render can stop and go on later with
 * the same bits as one that never stopped.  Format: docs/long-renders.md. */
#ifndef ZT_RENDER_CHECKPOINT_H
#define ZT_RENDER_CHECKPOINT_H

#include <stdint.h>

#include "zonetrace/render.h"
#include "scene/scene.h"

/* What the sums depend on: the scene (scene_hash), the camera, the seed, the
 * levels kept and the lights switched off (in any order). */
uint64_t checkpoint_key(const zt_scene *scene, const zt_render_options *o);

/* Writes samples and sums (3 doubles per pixel of a width x height image)
 * to path, replacing it atomically.  ZT_ERR_WRITE names the reason. */
zt_status checkpoint_write(const char *path, uint64_t key, int width, int height,
                           int samples, const double *sums, zt_error *err);

/* Reads a checkpoint written with the same key and size into sums and
 * *samples (at most max_samples).  ZT_ERR_READ when it cannot be read,
 * ZT_ERR_PARSE when it is not a checkpoint, is truncated or corrupt, or is
 * for another render; the message names the file and the reason. */
zt_status checkpoint_read(const char *path, uint64_t key, int width, int height,
                          int max_samples, double *sums, int *samples, zt_error *err);

#endif
