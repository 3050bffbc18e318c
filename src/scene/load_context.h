/* State shared by the parts of the scene loader, and the one way they
 * report a problem: "NAME:LINE:COLUMN: what is wrong" at a value's place. */
#ifndef ZT_SCENE_LOAD_CONTEXT_H
#define ZT_SCENE_LOAD_CONTEXT_H

#include <jansson.h>

#include "scene/json_positions.h"
#include "scene/scene.h"
#include "scene/source_map.h"

/* A value and where it sits: a member of an object (key != NULL), an
 * element of an array, or the document's root (parent == NULL). */
typedef struct jref {
    const json_t *value;          /* NULL for a missing member */
    const json_t *parent;
    const char *key;
    size_t index;
} jref;

/* A sky model waits for the end of the scene list, where the sun it
 * follows is known (load_daylight_finish). */
typedef struct sky_model_request {
    int pending;
    double turbidity;
    int has_sun;                  /* its own sun position, in sun */
    vec3 sun;
    jref where;                   /* the "model" value, for messages */
} sky_model_request;

typedef struct load_ctx {
    const char *name;             /* file name for messages */
    const char *dir;              /* the folder model files are relative to
                                     ("" for the current one) */
    const source_map *map;
    const json_positions *positions;
    zt_error *err;
    zt_scene *scene;              /* being built */
    sky_model_request sky_model;
} load_ctx;

jref jref_root(const json_t *root);
jref jref_member(const json_t *obj, const char *key);
jref jref_element(const json_t *array, size_t index);

/* Records a ZT_ERR_PARSE at the start of ref's value (or, for a missing
 * member, at its object) and returns ZT_ERR_PARSE. */
zt_status load_fail(load_ctx *ctx, jref ref, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* The same with another status (a model file that cannot be read). */
zt_status load_fail_status(load_ctx *ctx, zt_status status, jref ref, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* The same at the key of a member (for unknown keys). */
zt_status load_fail_key(load_ctx *ctx, const json_t *obj, const char *key,
                        const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* The same at an offset of the parsed text. */
zt_status load_fail_offset(load_ctx *ctx, zt_status status, size_t parsed,
                           const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* The line of ref's value in the file, or 0. */
int load_line(const load_ctx *ctx, jref ref);

/* A file named in the scene (a model, a map): as written when absolute,
 * else in the scene's folder. */
void load_file_path(const load_ctx *ctx, const char *file, char *out, size_t size);

#endif
