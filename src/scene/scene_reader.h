/* The parts of the scene reader, each turning one kind of JSON value into
 * the scene model.  All report through load_fail and return ZT_OK,
 * ZT_ERR_PARSE or ZT_ERR_MEMORY. */
#ifndef ZT_SCENE_SCENE_READER_H
#define ZT_SCENE_SCENE_READER_H

#include "scene/load_context.h"

/* {"character": {...}, "color": [...], "refractiveindex": n} */
zt_status load_material(load_ctx *ctx, jref ref, material *out);

/* The top-level "camera" object. */
zt_status load_camera(load_ctx *ctx, jref ref, zt_camera *out);

/* The kinds of primitive a scene item can name. */
typedef enum shape_kind {
    KIND_SPHERE, KIND_PLANE, KIND_TRIANGLE,
    KIND_LIGHTPOINT, KIND_LIGHTSPHERE, KIND_LIGHTPLANE, KIND_LIGHTTRIANGLE,
    KIND_NONE
} shape_kind;

/* The kind named by key, or KIND_NONE. */
shape_kind shape_kind_of(const char *key);
int shape_kind_is_light(shape_kind kind);

/* Reads the geometry of a primitive body (ref, already known to be an
 * object whose keys are all allowed) into *out. */
zt_status load_shape(load_ctx *ctx, shape_kind kind, jref body, part *out);

/* A "transform" object as p -> a p + t (a row-major). */
zt_status load_transform(load_ctx *ctx, jref ref, double a[9], double t[3]);

/* The body of a "mesh" item (item is the item, for messages about the
 * model file); adds one object. */
zt_status load_mesh_item(load_ctx *ctx, jref item, jref body, int line);

/* The body of a "sky" item and of a "sun" item (item is the item). */
zt_status load_sky(load_ctx *ctx, jref item, jref body);
zt_status load_sun(load_ctx *ctx, jref item, jref body);

/* After the scene list: draws a sky model (which follows the scene's sun)
 * into the sky's map. */
zt_status load_daylight_finish(load_ctx *ctx);

/* The top-level "scene" list: adds every object to ctx->scene. */
zt_status load_scene_list(load_ctx *ctx, jref ref);

#endif
