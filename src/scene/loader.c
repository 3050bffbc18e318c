/* Loading a scene file: reading it, the legacy rewrite, jansson, the
 * position index, and the top level.  What each value means is read by the
 * load_*.c files; this one only runs the stages and owns their memory. */
#define _POSIX_C_SOURCE 200809L
#include "zonetrace/scene.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "scene/json_positions.h"
#include "scene/legacy_syntax.h"
#include "scene/load_context.h"
#include "scene/load_values.h"
#include "scene/model_import.h"
#include "scene/model_scene.h"
#include "scene/scene_reader.h"
#include "scene/source_map.h"
#include "util/error.h"
#include "util/read_file.h"

/* No scene needs more; a bigger file is taken for a mistake. */
#define MAX_SCENE_BYTES ((size_t)64 << 20)


static zt_status load_top_level(load_ctx *ctx, const json_t *root)
{
    static const char *const keys[] = {"scene", "camera", NULL};
    jref top = jref_root(root);
    if (!json_is_object(root))
        return load_fail(ctx, top, "wrong type: the top level must be an object "
                         "with \"scene\" and \"camera\", not %s",
                         load_type_name(root));
    if (load_known_keys(ctx, top, "the top level", keys))
        return ZT_ERR_PARSE;
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)root, key, value) {
        zt_status s;
        if (strcmp(key, "scene") == 0) {
            s = load_scene_list(ctx, jref_member(root, key));
        } else {
            s = load_camera(ctx, jref_member(root, key), &ctx->scene->camera);
            ctx->scene->has_camera = s == ZT_OK;
        }
        if (s)
            return s;
    }
    if (!json_object_get(root, "scene"))
        return load_fail(ctx, top, "missing \"scene\" at the top level");
    if (!json_object_get(root, "camera"))
        return load_fail(ctx, top, "missing \"camera\" at the top level");
    return load_daylight_finish(ctx);
}

/* The stages after the rewrite.  *scene is built in place. */
static zt_status load_parsed(const char *name, const char *dir, const char *original,
                             size_t length, const legacy_text *strict,
                             zt_scene *scene, zt_error *err)
{
    source_map map;
    if (!source_map_init(&map, original, length, strict))
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    load_ctx ctx = {name, dir, &map, NULL, err, scene, {0}};
    json_error_t jerr;
    json_t *root = json_loadb(strict->text, strict->length,
                              JSON_REJECT_DUPLICATES | JSON_DECODE_ANY, &jerr);
    zt_status status;
    if (!root) {
        int oom = json_error_code(&jerr) == json_error_out_of_memory;
        status = load_fail_offset(&ctx, oom ? ZT_ERR_MEMORY : ZT_ERR_PARSE,
                                  json_syntax_error_offset(strict->text, strict->length, &jerr),
                                  "syntax error: %s", jerr.text);
    } else {
        json_positions *positions = json_positions_build(strict->text,
                                                         strict->length, root);
        if (!positions) {
            status = zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
        } else {
            ctx.positions = positions;
            status = load_top_level(&ctx, root);
            json_positions_free(positions);
        }
        json_decref(root);
    }
    source_map_free(&map);
    return status;
}

/* Embedded NUL bytes are refused before anything else: jansson would stop
 * at them with a less helpful message, and C strings cannot hold them. */
static zt_status check_nul(const char *name, const char *text, size_t length,
                           zt_error *err)
{
    const char *nul = memchr(text, '\0', length);
    if (!nul)
        return ZT_OK;
    source_map map;
    int line, column;
    if (!source_map_init(&map, text, length, NULL))
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    source_map_locate(&map, (size_t)(nul - text), &line, &column);
    source_map_free(&map);
    return zt_fail(err, ZT_ERR_PARSE, "%s:%d:%d: NUL byte in the file "
                   "(it is not a text file?)", name, line, column);
}

/* Loads text; model files are looked for relative to dir. */
static zt_status load_text(const char *text, size_t length, const char *name,
                           const char *dir, zt_scene **out, zt_error *err)
{
    zt_error_clear(err);
    if (!out || (!text && length))
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_scene_load_string: no text or no result pointer");
    *out = NULL;
    if (!name)
        name = "<string>";
    if (!text)
        text = "";
    if (length > MAX_SCENE_BYTES)
        return zt_fail(err, ZT_ERR_READ, "%s: too large: %zu bytes (the limit "
                       "is 64 MiB)", name, length);
    zt_status status = check_nul(name, text, length, err);
    if (status)
        return status;

    legacy_text strict;
    size_t deep_at = 0;
    legacy_status ls = legacy_rewrite(text, length, &strict, &deep_at);
    zt_scene *scene = NULL;
    if (ls == LEGACY_NO_MEMORY) {
        status = zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    } else if (ls == LEGACY_TOO_DEEP) {
        source_map map;
        int line = 0, column = 0;
        if (source_map_init(&map, text, length, NULL))
            source_map_locate(&map, deep_at, &line, &column);
        source_map_free(&map);
        status = zt_fail(err, ZT_ERR_PARSE, "%s:%d:%d: nesting too deep (more "
                         "than %d levels of brackets)", name, line, column,
                         LEGACY_MAX_DEPTH);
    } else if (!(scene = scene_create())) {
        status = zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    } else {
        status = load_parsed(name, dir, text, length, &strict, scene, err);
    }
    legacy_free(&strict);
    if (status) {
        zt_scene_release(scene);
        return status;
    }
    *out = scene;
    return ZT_OK;
}

zt_status zt_scene_load_string(const char *text, size_t length,
                               const char *name, zt_scene **out,
                               zt_error *err)
{
    return load_text(text, length, name, "", out, err);
}

zt_status zt_scene_load_file(const char *path, zt_scene **out, zt_error *err)
{
    zt_error_clear(err);
    if (!path || !out)
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_scene_load_file: no path or no result pointer");
    *out = NULL;
    /* A model file alone is a scene too. */
    const char *ext = strrchr(path, '.');
    if (model_import_known_extension(path) && !(ext && strcasecmp(ext, ".json") == 0))
        return scene_from_model(path, out, err);
    char *text = NULL;
    size_t length = 0;
    zt_status status = read_text_file(path, "scene file", MAX_SCENE_BYTES, &text, &length, err);
    if (!status) {
        /* Model files are relative to the scene file's folder. */
        char *dir = strdup(path);
        if (!dir) {
            free(text);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
        }
        char *slash = strrchr(dir, '/');
        if (slash)
            slash[1] = '\0';
        else
            dir[0] = '\0';
        status = load_text(text, length, path, dir, out, err);
        free(dir);
    }
    free(text);
    return status;
}
