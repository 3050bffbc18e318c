/* A scene's fingerprint, kept in files made for one scene (forest files,
 * checkpoints) to recognise it. */
#ifndef ZT_SCENE_SCENE_HASH_H
#define ZT_SCENE_SCENE_HASH_H

#include <stdint.h>

#include "scene/scene.h"

/* A hash of the geometry, materials, lights, meshes with their textures,
 * and the sky; not of the camera. */
uint64_t scene_hash(const zt_scene *scene);

#endif
