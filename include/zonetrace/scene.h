/* zonetrace: scenes.
 *
 * A scene is loaded from the JSON format of the original Retra/Silence
 * programs (docs/scene-format.md), including their non-JSON "thing"/"light"
 * group syntax.  Scene files are untrusted: every problem is reported as a
 * ZT_ERR_READ or ZT_ERR_PARSE with "file:line:column: what is wrong".
 */
#ifndef ZONETRACE_SCENE_H
#define ZONETRACE_SCENE_H

#include <stddef.h>
#include "zonetrace/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct zt_scene zt_scene;

/* Pinhole camera: rays start on the screen (which acts as a near plane) and
 * leave it away from the viewpoint.  screen holds the corners top-left,
 * top-right, bottom-left, bottom-right; the screen is taken as the
 * parallelogram spanned by the first three. */
typedef struct zt_camera {
    double viewpoint[3];
    double screen[4][3];
    int width;
    int height;
} zt_camera;

/* Loads a scene file.  On success *out is a new scene owned by the caller.
 * Fails with ZT_ERR_READ (cannot open/read, a directory, too large) or
 * ZT_ERR_PARSE (syntax or content), with the position in err. */
zt_status zt_scene_load_file(const char *path, zt_scene **out, zt_error *err);

/* The same from memory; name is used in messages only. */
zt_status zt_scene_load_string(const char *text, size_t length,
                               const char *name, zt_scene **out,
                               zt_error *err);

/* Frees a scene.  NULL is allowed. */
void zt_scene_release(zt_scene *scene);

/* A deep copy, or NULL when out of memory. */
zt_scene *zt_scene_clone(const zt_scene *scene);

typedef struct zt_scene_info {
    int lights;       /* light objects (groups count once) */
    int things;       /* passive objects (groups count once) */
    int light_parts;  /* emitting primitives (mesh triangles included) */
    int thing_parts;  /* passive primitives (mesh triangles included) */
    int spheres, planes, triangles, points; /* primitives of each kind,
                                               meshes' triangles apart */
    int meshes;       /* objects made from model files */
    long long mesh_triangles; /* their triangles */
    long long skipped_triangles; /* degenerate ones the import left out */
    long long replaced_normals; /* vertex normals of a model that were not
                                   finite or zero, replaced from the faces */
    int rough_materials; /* model files' materials with a rough (GGX) metallic
                            or refractive lobe */
    int rough_lobes;  /* scene materials with a roughness above 0 and a
                         metallic, reflecting or refractive lobe (GGX) */
    int missing_textures; /* textures a model names but that are missing or
                             cannot be decoded (left out: base colour only) */
    char texture_problem[160]; /* the first of them and why */
    int map_fallbacks; /* models' normal, roughness, metal and emissive maps
                          left out (missing or cannot be decoded): the
                          factors alone, the interpolated normal */
    char map_problem[160]; /* the first of them and why */
    char unused[256]; /* what the models' materials have that is not used,
                         counted by kind ("2 occlusion textures, 1 sheen
                         layers"); empty when nothing */
    int alpha_masks;  /* materials with alphaMode MASK (holes where the
                         coverage is below the cutoff) */
    int alpha_blends; /* materials with partial coverage (BLEND, or a
                         scene material's "coverage") */
    int alpha_fallbacks; /* models' alpha cutoffs not in [0, 1], clamped */
    char alpha_problem[160]; /* the first of them and what was taken */
    long long emissive_pieces; /* triangles the import added by cutting
                                  emissive ones where their texture varies
                                  (docs/scene-format.md) */
    int has_sky;      /* non-zero when a sky colour is given */
    int panes;        /* materials (of things and of models' slots) whose
                         refractive lobe is a thin pane */
} zt_scene_info;

void zt_scene_get_info(const zt_scene *scene, zt_scene_info *out);

/* The scene's camera (a copy) and a way to replace it. */
zt_camera zt_scene_get_camera(const zt_scene *scene);
void zt_scene_set_camera(zt_scene *scene, const zt_camera *camera);

/* A camera at position looking at lookat, with up (any vector not parallel
 * to the view) pointing up in the image, a vertical field of view of
 * fov_degrees (0 < fov < 180) and square pixels on a width x height grid.
 * The screen (which is also the near plane) lies at a thousandth of the
 * distance to lookat.  ZT_ERR_ARGUMENT for a degenerate camera. */
zt_status zt_camera_look_at(zt_camera *out, const double position[3], const double lookat[3],
                            const double up[3], double fov_degrees, int width, int height,
                            zt_error *err);

/* Keeps the camera's screen but changes its pixel grid (--size). */
zt_status zt_camera_set_resolution(zt_camera *camera, int width, int height,
                                   zt_error *err);

/* Objects are addressed as the motions file does: light i or thing i,
 * counted separately in file order from 0. */
typedef enum zt_object_class { ZT_OBJECT_LIGHT, ZT_OBJECT_THING } zt_object_class;

/* Number of objects of a class. */
int zt_scene_object_count(const zt_scene *scene, zt_object_class cls);

/* Moves every part of an object by delta.  ZT_ERR_ARGUMENT for a bad index. */
zt_status zt_scene_translate_object(zt_scene *scene, zt_object_class cls,
                                    int index, const double delta[3],
                                    zt_error *err);

/* Rotates every part of an object by angle radians about world axis
 * 0 = X, 1 = Y, 2 = Z through the origin (right-hand rule). */
zt_status zt_scene_rotate_object(zt_scene *scene, zt_object_class cls,
                                 int index, int axis, double angle,
                                 zt_error *err);

/* A point that represents the object's position (the mean of its parts'
 * centres; for planes the point of the plane nearest the origin). */
zt_status zt_scene_object_position(const zt_scene *scene, zt_object_class cls,
                                   int index, double out[3], zt_error *err);

#ifdef __cplusplus
}
#endif
#endif
