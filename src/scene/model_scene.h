/* A scene made from a model file alone (zonetrace render model.glb). */
#ifndef ZT_SCENE_MODEL_SCENE_H
#define ZT_SCENE_MODEL_SCENE_H

#include "scene/mesh.h"

/* Reads the model at path (model_import) into a new scene: the model as
 * one thing with the file's materials, a white sky (radiance 1), and the
 * file's first camera, or a camera that frames the model's bounding box
 * from the front-right and above (+y up), 640 x 480.  Errors as
 * model_import's. */
zt_status scene_from_model(const char *path, zt_scene **out, zt_error *err);

#endif
