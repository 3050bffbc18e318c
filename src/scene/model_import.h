/* Model files (OBJ with MTL, PLY, STL, glTF 2, and whatever else Assimp
 * reads) as one mesh of the scene model.  Model files are untrusted: every
 * problem becomes a status and a message, never a crash. */
#ifndef ZT_SCENE_MODEL_IMPORT_H
#define ZT_SCENE_MODEL_IMPORT_H

#include "scene/mesh.h"

/* A camera found in the model file, in the model's space (the file's node
 * transforms applied, the scene's "transform" not yet). */
typedef struct model_camera {
    int present;
    vec3 position, lookat, up;
    double fov;             /* vertical, degrees */
    double aspect;          /* width / height, 0 when the file gives none */
} model_camera;

typedef struct model_import_options {
    int smooth;             /* keep the file's vertex normals (and make
                               smooth ones where it has none); 0: flat,
                               mesh->normal = NULL */
    double *read_seconds;   /* when not NULL, receives the time Assimp took
                               to read and post-process the file (the
                               benchmarks report it apart from the rest) */
} model_import_options;

/* Reads `path` into a new mesh (*out, the caller's: mesh_release), with
 * every node of the file flattened into it (node transforms applied), one
 * slot per material of the file mapped onto the four-weight material
 * (docs/scene-format.md says how), base-colour textures decoded (PNG and
 * JPEG, external files relative to the model's folder, or embedded).
 * Triangles with a zero area, a repeated vertex or a non-finite vertex are
 * skipped and counted (mesh->skipped_degenerate); points and lines are
 * ignored.  camera (may be NULL) receives the file's first camera.
 *
 * Fails with ZT_ERR_READ when the file cannot be opened or read, and with
 * ZT_ERR_PARSE when it is not a model Assimp can read, Assimp reports an
 * error, an index is out of range, a vertex is not finite in a way that
 * cannot be skipped, or no triangle is left.  The message names the model
 * file and the reason, without a scene position (the caller adds it). */
zt_status model_import(const char *path, const model_import_options *options, mesh **out,
                       model_camera *camera, zt_error *err);

/* Whether a file name has an extension Assimp can import (for the command
 * line: "zonetrace render model.glb" renders a model alone). */
int model_import_known_extension(const char *path);

#endif
