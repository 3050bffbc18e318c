/* The "scene" list: standalone primitives (one object each), thing and
 * light groups (one object with several parts); the sky and the sun are
 * load_daylight.c's. */
#include "scene/scene_reader.h"

#include <string.h>

#include "scene/load_values.h"

/* Keys a primitive body may hold besides its geometry, per class. */
static const char *const thing_settings[] = {"material", "background", "backculled", NULL};
static const char *const light_settings[] = {"emission", "background", "backculled", NULL};

static int is_setting(const char *key, int is_light)
{
    for (const char *const *s = is_light ? light_settings : thing_settings; *s; s++)
        if (strcmp(*s, key) == 0)
            return 1;
    return 0;
}

/* Applies one object-level setting (the last one in the file wins). */
static zt_status apply_setting(load_ctx *ctx, jref value, object *o)
{
    if (strcmp(value.key, "material") == 0)
        return load_material(ctx, value, &o->mat);
    if (strcmp(value.key, "emission") == 0)
        return load_radiance(ctx, value, &o->emission);
    if (strcmp(value.key, "background") == 0)
        return load_bool(ctx, value, &o->background);
    return load_bool(ctx, value, &o->backculled);
}

/* The keys a body of this kind accepts. */
static void body_keys(shape_kind kind, const char **keys)
{
    int n = 0;
    const char *const *settings = shape_kind_is_light(kind) ? light_settings
                                                            : thing_settings;
    while (settings[n]) {
        keys[n] = settings[n];
        n++;
    }
    switch (kind) {
    case KIND_SPHERE:
    case KIND_LIGHTSPHERE:
        keys[n++] = "center";
        keys[n++] = "radius";
        break;
    case KIND_PLANE:
    case KIND_LIGHTPLANE:
        keys[n++] = "normal";
        keys[n++] = "offset";
        break;
    case KIND_TRIANGLE:
    case KIND_LIGHTTRIANGLE:
        keys[n++] = "points";
        break;
    default:
        keys[n++] = "point";
        break;
    }
    keys[n] = NULL;
}

/* Adds an object with the defaults; returns its index or -1. */
static int new_object(load_ctx *ctx, int is_light, int line)
{
    object o;
    memset(&o, 0, sizeof o);
    o.is_light = is_light;
    o.mat = material_default();
    o.line = line;
    return scene_add_object(ctx->scene, &o);
}

static zt_status out_of_memory(load_ctx *ctx)
{
    return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN,
                            "out of memory");
}

/* Reads a primitive body, applies its settings to object `index` of the
 * scene and adds its part to it.  `line` is where the item starts. */
static zt_status add_primitive(load_ctx *ctx, shape_kind kind, jref body,
                               const char *name, int index, int line)
{
    const char *keys[8];
    body_keys(kind, keys);
    if (load_object(ctx, body, name) || load_known_keys(ctx, body, name, keys))
        return ZT_ERR_PARSE;
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)body.value, key, value) {
        if (is_setting(key, shape_kind_is_light(kind)) &&
            apply_setting(ctx, jref_member(body.value, key),
                          &ctx->scene->objects[index]))
            return ZT_ERR_PARSE;
    }
    part p;
    if (load_shape(ctx, kind, body, &p))
        return ZT_ERR_PARSE;
    p.line = line;
    if (scene_add_part(ctx->scene, &p) < 0)
        return out_of_memory(ctx);
    return ZT_OK;
}

/* One element of a group's "parts": a primitive of the group's class, or a
 * one-key setting (the legacy syntax's settings that follow a part). */
static zt_status load_group_part(load_ctx *ctx, jref item, int is_light,
                                 int index, int *parts)
{
    const char *group = is_light ? "light group" : "thing group";
    if (!json_is_object(item.value) || json_object_size(item.value) != 1)
        return load_fail(ctx, item, "wrong type: a part of a %s must be an "
                         "object with one key such as {\"%s\": {...}}",
                         group, is_light ? "lightsphere" : "sphere");
    const char *key = json_object_iter_key(json_object_iter((json_t *)item.value));
    jref body = jref_member(item.value, key);
    if (is_setting(key, is_light))
        return apply_setting(ctx, body, &ctx->scene->objects[index]);
    shape_kind kind = shape_kind_of(key);
    if (strcmp(key, "thing") == 0 || strcmp(key, "light") == 0)
        return load_fail_key(ctx, item.value, key, "nested groups are not allowed");
    if (kind == KIND_NONE)
        return load_fail_key(ctx, item.value, key, "unknown key \"%s\" in %s",
                             key, group);
    if (shape_kind_is_light(kind) != is_light)
        return load_fail_key(ctx, item.value, key, "a %s cannot contain %s parts (%s)",
                             group, is_light ? "thing" : "light", key);
    ++*parts;
    return add_primitive(ctx, kind, body, key, index, load_line(ctx, item));
}

/* {"thing": {"material": ..., "parts": [...]}} or the light equivalent;
 * the legacy array form arrives here already rewritten. */
static zt_status load_group(load_ctx *ctx, jref body, int is_light, int line)
{
    static const char *const thing_keys[] = {
        "material", "background", "backculled", "parts", NULL
    };
    static const char *const light_keys[] = {
        "emission", "background", "backculled", "parts", NULL
    };
    const char *group = is_light ? "light group" : "thing group";
    if (load_object(ctx, body, group) ||
        load_known_keys(ctx, body, group, is_light ? light_keys : thing_keys))
        return ZT_ERR_PARSE;
    int index = new_object(ctx, is_light, line);
    if (index < 0)
        return out_of_memory(ctx);
    int parts = 0;
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)body.value, key, value) {
        jref member = jref_member(body.value, key);
        if (strcmp(key, "parts") != 0) {
            zt_status s = apply_setting(ctx, member, &ctx->scene->objects[index]);
            if (s)
                return s;
            continue;
        }
        if (!json_is_array(value))
            return load_fail(ctx, member, "wrong type: the parts of a %s must "
                             "be a list, not %s", group, load_type_name(value));
        for (size_t i = 0; i < json_array_size(value); i++) {
            zt_status s = load_group_part(ctx, jref_element(value, i), is_light,
                                          index, &parts);
            if (s)
                return s;
        }
    }
    if (parts == 0)
        return load_fail(ctx, body, "empty group: a %s needs at least one part",
                         group);
    return ZT_OK;
}

static zt_status load_item(load_ctx *ctx, jref item)
{
    if (!json_is_object(item.value))
        return load_fail(ctx, item, "wrong type: a scene item must be an "
                         "object such as {\"sphere\": {...}}, not %s",
                         load_type_name(item.value));
    if (json_object_size(item.value) == 0)
        return load_fail(ctx, item, "empty scene item: expected one key such "
                         "as \"sphere\"");
    void *it = json_object_iter((json_t *)item.value);
    const char *key = json_object_iter_key(it);
    it = json_object_iter_next((json_t *)item.value, it);
    if (it) {
        const char *extra = json_object_iter_key(it);
        return load_fail_key(ctx, item.value, extra, "unexpected second key "
                             "\"%s\": a scene item holds exactly one object",
                             extra);
    }
    jref body = jref_member(item.value, key);
    int line = load_line(ctx, item);
    if (strcmp(key, "sky") == 0)
        return load_sky(ctx, item, body);
    if (strcmp(key, "sun") == 0)
        return load_sun(ctx, item, body);
    if (strcmp(key, "thing") == 0 || strcmp(key, "light") == 0)
        return load_group(ctx, body, key[0] == 'l', line);
    if (strcmp(key, "mesh") == 0)
        return load_mesh_item(ctx, item, body, line);
    if (strcmp(key, "camera") == 0)
        return load_fail_key(ctx, item.value, key, "misplaced camera: it "
                             "belongs at the top level, beside \"scene\"");
    shape_kind kind = shape_kind_of(key);
    if (kind == KIND_NONE)
        return load_fail_key(ctx, item.value, key, "unknown scene item \"%s\"", key);
    int index = new_object(ctx, shape_kind_is_light(kind), line);
    if (index < 0)
        return out_of_memory(ctx);
    return add_primitive(ctx, kind, body, key, index, line);
}

zt_status load_scene_list(load_ctx *ctx, jref ref)
{
    if (!json_is_array(ref.value))
        return load_fail(ctx, ref, "wrong type: \"scene\" must be a list, not %s",
                         load_type_name(ref.value));
    for (size_t i = 0; i < json_array_size(ref.value); i++) {
        zt_status s = load_item(ctx, jref_element(ref.value, i));
        if (s)
            return s;
    }
    return ZT_OK;
}
