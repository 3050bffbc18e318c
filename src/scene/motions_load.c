/* Loading a motions file: reading it, jansson, the position index (the
 * same machinery as scene files, so messages are "file:line:column: ..."),
 * and the checks of each motion and of the camera path.  Also
 * zt_motions_check and the queries of a list. */
#define _POSIX_C_SOURCE 200809L
#include "zonetrace/motion.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "scene/json_positions.h"
#include "scene/load_context.h"
#include "scene/load_values.h"
#include "scene/motions.h"
#include "scene/source_map.h"
#include "util/error.h"
#include "util/read_file.h"

/* A motions file is a few hundred bytes; anything this large is a mistake. */
#define MAX_MOTIONS_BYTES ((size_t)16 << 20)

static const char *const motion_keys[] = {
    "light", "thing", "type", "scale", "delta", "stop", "axis", "period",
    "begin", "end", NULL
};

static const char *const type_names[] = {
    "linear", "orbiting", "oscillating", "brownian"
};

/* The keys each type takes besides "light"/"thing" and "type". */
static const char *const type_keys[4][4] = {
    {"delta", "stop", NULL},
    {"axis", "period", NULL},
    {"begin", "end", "period", NULL},
    {"scale", NULL},
};

/* The keys each type requires. */
static const char *const type_required[4][4] = {
    {"delta", NULL},
    {"axis", "period", NULL},
    {"begin", "end", "period", NULL},
    {"scale", NULL},
};

static int in_list(const char *const *list, const char *key)
{
    for (; *list; list++)
        if (strcmp(*list, key) == 0)
            return 1;
    return 0;
}

/* Line and column of a member's value, for zt_motions_check's messages. */
static void member_place(const load_ctx *ctx, const json_t *obj, const char *key,
                         int *line, int *column)
{
    size_t parsed = json_positions_member(ctx->positions, obj, key);
    size_t original = source_map_original(ctx->map, parsed);
    if (!source_map_locate(ctx->map, original, line, column))
        *line = *column = 0;
}

static zt_status load_target(load_ctx *ctx, jref mref, zt_motion *m)
{
    const json_t *obj = mref.value;
    const json_t *light = json_object_get(obj, "light");
    const json_t *thing = json_object_get(obj, "thing");
    if (!light && !thing)
        return load_fail(ctx, mref, "missing target: a motion needs \"light\" "
                         "or \"thing\" (the index of the object it moves)");
    if (light && thing) {
        /* report at whichever of the two comes second */
        size_t pl = json_positions_key(ctx->positions, obj, "light");
        size_t pt = json_positions_key(ctx->positions, obj, "thing");
        const char *second = pl != SOURCE_OFFSET_UNKNOWN && pt != SOURCE_OFFSET_UNKNOWN
                             && pl > pt ? "light" : "thing";
        return load_fail_key(ctx, obj, second, "a motion moves one object: "
                             "both \"light\" and \"thing\" are given");
    }
    const char *key = light ? "light" : "thing";
    long long index;
    if (load_int(ctx, jref_member(obj, key), 0, INT_MAX, &index))
        return ZT_ERR_PARSE;
    m->target_class = light ? ZT_OBJECT_LIGHT : ZT_OBJECT_THING;
    m->target = (int)index;
    member_place(ctx, obj, key, &m->line, &m->column);
    return ZT_OK;
}

static zt_status load_type(load_ctx *ctx, jref mref, zt_motion *m)
{
    if (!json_object_get(mref.value, "type"))
        return load_fail(ctx, mref, "missing \"type\" in a motion (one of "
                         "\"linear\", \"orbiting\", \"oscillating\", \"brownian\")");
    jref t = jref_member(mref.value, "type");
    if (!json_is_string(t.value))
        return load_fail(ctx, t, "wrong type: the motion type must be a string, not %s",
                         load_type_name(t.value));
    const char *name = json_string_value(t.value);
    for (int i = 0; i < 4; i++)
        if (strcmp(name, type_names[i]) == 0) {
            m->type = (zt_motion_type)i;
            return ZT_OK;
        }
    return load_fail(ctx, t, "unknown motion type \"%.64s\": expected \"linear\", "
                     "\"orbiting\", \"oscillating\" or \"brownian\"", name);
}

static zt_status load_axis(load_ctx *ctx, jref ref, int *axis)
{
    if (!json_is_string(ref.value))
        return load_fail(ctx, ref, "wrong type: expected an axis \"x\", \"y\" or "
                         "\"z\", not %s", load_type_name(ref.value));
    const char *s = json_string_value(ref.value);
    if (strlen(s) == 1) {
        const char *p = strchr("xXyYzZ", s[0]);
        if (p && s[0]) {
            *axis = (int)(p - "xXyYzZ") / 2;
            return ZT_OK;
        }
    }
    return load_fail(ctx, ref, "invalid axis \"%.32s\": expected \"x\", \"y\" or "
                     "\"z\" (either case)", s);
}

static zt_status load_motion(load_ctx *ctx, jref mref, zt_motion *m)
{
    if (!json_is_object(mref.value))
        return load_fail(ctx, mref, "wrong type: a motion must be an object, not %s",
                         load_type_name(mref.value));
    if (load_known_keys(ctx, mref, "a motion", motion_keys))
        return ZT_ERR_PARSE;
    memset(m, 0, sizeof *m);
    m->stop = -1.0;
    if (load_type(ctx, mref, m) || load_target(ctx, mref, m))
        return ZT_ERR_PARSE;

    const char *what = type_names[m->type];
    char what_motion[40];
    snprintf(what_motion, sizeof what_motion, "%s %s motion",
             (m->type == ZT_MOTION_ORBITING || m->type == ZT_MOTION_OSCILLATING) ? "an" : "a",
             what);
    const json_t *obj = mref.value;
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)obj, key, value) {
        if (!strcmp(key, "light") || !strcmp(key, "thing") || !strcmp(key, "type"))
            continue;
        if (!in_list(type_keys[m->type], key))
            return load_fail_key(ctx, obj, key, "\"%s\" does not apply to %s",
                                 key, what_motion);
    }
    for (const char *const *r = type_required[m->type]; *r; r++)
        if (load_require(ctx, mref, *r, what_motion))
            return ZT_ERR_PARSE;

    vec3 v;
    switch (m->type) {
    case ZT_MOTION_LINEAR:
        if (load_triple(ctx, jref_member(obj, "delta"), &v))
            return ZT_ERR_PARSE;
        v3_store(v, m->delta);
        if (json_object_get(obj, "stop") &&
            load_number(ctx, jref_member(obj, "stop"), &m->stop))
            return ZT_ERR_PARSE;
        break;
    case ZT_MOTION_ORBITING:
    case ZT_MOTION_OSCILLATING:
        if (m->type == ZT_MOTION_ORBITING) {
            if (load_axis(ctx, jref_member(obj, "axis"), &m->axis))
                return ZT_ERR_PARSE;
        } else {
            if (load_triple(ctx, jref_member(obj, "begin"), &v))
                return ZT_ERR_PARSE;
            v3_store(v, m->begin);
            if (load_triple(ctx, jref_member(obj, "end"), &v))
                return ZT_ERR_PARSE;
            v3_store(v, m->end);
        }
        if (load_number(ctx, jref_member(obj, "period"), &m->period))
            return ZT_ERR_PARSE;
        if (m->period == 0.0)
            return load_fail(ctx, jref_member(obj, "period"),
                             "period must not be 0 (it is in seconds)");
        break;
    case ZT_MOTION_BROWNIAN:
        if (load_number(ctx, jref_member(obj, "scale"), &m->scale))
            return ZT_ERR_PARSE;
        if (m->scale < 0)
            return load_fail(ctx, jref_member(obj, "scale"),
                             "scale must be 0 or more, not %g", m->scale);
        break;
    }
    return ZT_OK;
}

/* Line and column of an array's element, for the keys of a camera path. */
static void element_place(const load_ctx *ctx, const json_t *array, size_t i, int *line,
                          int *column)
{
    size_t parsed = json_positions_element(ctx->positions, array, i);
    size_t original = source_map_original(ctx->map, parsed);
    if (!source_map_locate(ctx->map, original, line, column))
        *line = *column = 0;
}

static zt_status load_camera_key(load_ctx *ctx, jref kref, const zt_camera_key *prev,
                                 zt_camera_key *k)
{
    static const char *const keys[] = {"time", "position", "lookat", "up", "fov", NULL};
    const json_t *obj = kref.value;
    if (!json_is_object(obj))
        return load_fail(ctx, kref, "wrong type: a camera key must be an object, not %s",
                         load_type_name(obj));
    if (load_known_keys(ctx, kref, "a camera key", keys) ||
        load_require(ctx, kref, "time", "a camera key") ||
        load_require(ctx, kref, "position", "a camera key") ||
        load_require(ctx, kref, "lookat", "a camera key"))
        return ZT_ERR_PARSE;
    jref time = jref_member(obj, "time"), lookat = jref_member(obj, "lookat");
    jref up_ref = jref_member(obj, "up"), fov_ref = jref_member(obj, "fov");
    vec3 pos, at, up = v3(0, 1, 0);
    double fov = 40; /* the defaults of a scene file's aimed camera */
    if (load_number(ctx, time, &k->time) ||
        load_triple(ctx, jref_member(obj, "position"), &pos) ||
        load_triple(ctx, lookat, &at) ||
        (up_ref.value && load_triple(ctx, up_ref, &up)) ||
        (fov_ref.value && load_number(ctx, fov_ref, &fov)))
        return ZT_ERR_PARSE;
    if (prev && !(k->time > prev->time))
        return load_fail(ctx, time, "time %g is not after the previous key's (%g): the keys "
                         "of a camera path go in strictly increasing time", k->time,
                         prev->time);
    if (!(fov > 0 && fov < 180))
        return load_fail(ctx, fov_ref, "fov out of range: %g (the vertical field of view, "
                         "in degrees, between 0 and 180)", fov);
    if (pos.x == at.x && pos.y == at.y && pos.z == at.z)
        return load_fail(ctx, lookat, "lookat equals position: the camera must look "
                         "somewhere else");
    if (up.x == 0 && up.y == 0 && up.z == 0)
        return load_fail(ctx, up_ref, "up must not be zero");
    v3_store(pos, k->position);
    v3_store(at, k->lookat);
    v3_store(up, k->up);
    k->fov = fov;
    zt_camera cam;
    zt_error cerr;
    zt_error_clear(&cerr);
    /* What is left to fail: up parallel to the view. */
    if (zt_camera_look_at(&cam, k->position, k->lookat, k->up, fov, 1, 1, &cerr) != ZT_OK) {
        if (up_ref.value)
            return load_fail(ctx, up_ref, "up is parallel to the view direction (from "
                             "position to lookat)");
        return load_fail(ctx, kref, "the default up (0, 1, 0) is parallel to the view "
                         "direction (from position to lookat): give \"up\"");
    }
    return ZT_OK;
}

/* {"camera": "path", "keys": [...]}: the camera path, at most one. */
static zt_status load_camera_path(load_ctx *ctx, jref cref, zt_motions *ms)
{
    static const char *const keys[] = {"camera", "keys", NULL};
    const json_t *obj = cref.value;
    if (load_known_keys(ctx, cref, "a camera path", keys))
        return ZT_ERR_PARSE;
    jref kind = jref_member(obj, "camera");
    if (!json_is_string(kind.value))
        return load_fail(ctx, kind, "wrong type: \"camera\" must be \"path\", not %s",
                         load_type_name(kind.value));
    if (strcmp(json_string_value(kind.value), "path") != 0)
        return load_fail(ctx, kind, "unknown camera motion \"%.64s\": expected \"path\"",
                         json_string_value(kind.value));
    if (ms->path.count)
        return load_fail_key(ctx, obj, "camera", "a second camera path: a motions file has "
                             "at most one (the first has its first key on line %d)",
                             ms->path.keys[0].line);
    if (load_require(ctx, cref, "keys", "a camera path"))
        return ZT_ERR_PARSE;
    jref list = jref_member(obj, "keys");
    if (!json_is_array(list.value))
        return load_fail(ctx, list, "wrong type: \"keys\" must be a list of camera keys, "
                         "not %s", load_type_name(list.value));
    size_t n = json_array_size(list.value);
    if (n < 2)
        return load_fail(ctx, list, "a camera path needs at least two keys, found %zu", n);
    if (n > 100000)
        return load_fail(ctx, list, "too many camera keys (%zu; the limit is 100000)", n);
    camera_path path = {calloc(n, sizeof(zt_camera_key)), 0, NULL, NULL};
    if (!path.keys)
        return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN, "out of memory");
    for (size_t i = 0; i < n; i++) {
        zt_camera_key *k = &path.keys[i];
        if (load_camera_key(ctx, jref_element(list.value, i), i ? k - 1 : NULL, k)) {
            camera_path_free(&path);
            return ZT_ERR_PARSE;
        }
        element_place(ctx, list.value, i, &k->line, &k->column);
        path.count++;
    }
    if (!camera_path_prepare(&path)) {
        camera_path_free(&path);
        return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN, "out of memory");
    }
    ms->path = path;
    return ZT_OK;
}

static zt_status load_top(load_ctx *ctx, const json_t *root, zt_motions *ms)
{
    static const char *const keys[] = {"motions", NULL};
    jref top = jref_root(root);
    if (!json_is_object(root))
        return load_fail(ctx, top, "wrong type: the top level must be an object "
                         "with \"motions\", not %s", load_type_name(root));
    if (load_known_keys(ctx, top, "the top level of a motions file", keys))
        return ZT_ERR_PARSE;
    if (load_require(ctx, top, "motions", "the top level"))
        return ZT_ERR_PARSE;
    jref list = jref_member(root, "motions");
    if (!json_is_array(list.value))
        return load_fail(ctx, list, "wrong type: \"motions\" must be a list of "
                         "motions, not %s", load_type_name(list.value));
    size_t n = json_array_size(list.value);
    if (n > 100000)
        return load_fail(ctx, list, "too many motions (%zu; the limit is 100000)", n);
    if (n) {
        ms->items = calloc(n, sizeof *ms->items);
        ms->walks = calloc(n, sizeof *ms->walks);
        if (!ms->items || !ms->walks)
            return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN,
                                    "out of memory");
    }
    for (size_t i = 0; i < n; i++) {
        jref m = jref_element(list.value, i);
        if (json_is_object(m.value) && json_object_get(m.value, "camera")) {
            zt_status s = load_camera_path(ctx, m, ms);
            if (s)
                return s;
            continue;
        }
        zt_status s = load_motion(ctx, m, &ms->items[ms->count]);
        if (s)
            return s;
        ms->count++;
    }
    return ZT_OK;
}


static zt_motions *motions_new(const char *name)
{
    zt_motions *ms = calloc(1, sizeof *ms);
    if (!ms)
        return NULL;
    ms->name = strdup(name);
    if (!ms->name || pthread_mutex_init(&ms->lock, NULL) != 0) {
        free(ms->name);
        free(ms);
        return NULL;
    }
    return ms;
}

void zt_motions_release(zt_motions *ms)
{
    if (!ms)
        return;
    pthread_mutex_destroy(&ms->lock);
    camera_path_free(&ms->path);
    free(ms->items);
    free(ms->walks);
    free(ms->name);
    free(ms);
}

zt_status zt_motions_load_string(const char *text, size_t length,
                                 const char *name, zt_motions **out,
                                 zt_error *err)
{
    zt_error_clear(err);
    if (!out || (!text && length))
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_motions_load_string: no text or no result pointer");
    *out = NULL;
    if (!name)
        name = "<string>";
    if (!text)
        text = "";
    if (length > MAX_MOTIONS_BYTES)
        return zt_fail(err, ZT_ERR_READ, "%s: too large: %zu bytes (the limit "
                       "is 16 MiB)", name, length);

    /* A copy with a UTF-8 byte-order mark blanked (jansson refuses it);
     * blanking keeps every offset. */
    char *copy = malloc(length + 1);
    if (!copy)
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    memcpy(copy, text, length);
    copy[length] = '\0';
    if (length >= 3 && memcmp(copy, "\xEF\xBB\xBF", 3) == 0)
        memset(copy, ' ', 3);

    source_map map;
    if (!source_map_init(&map, copy, length, NULL)) {
        free(copy);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    }
    load_ctx ctx = {name, "", &map, NULL, err, NULL, {0}};
    zt_status status;
    zt_motions *ms = NULL;
    const char *nul = memchr(copy, '\0', length);
    if (nul) {
        status = load_fail_offset(&ctx, ZT_ERR_PARSE, (size_t)(nul - copy),
                                  "NUL byte in the file (it is not a text file?)");
    } else if (!(ms = motions_new(name))) {
        status = zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    } else {
        json_error_t jerr;
        json_t *root = json_loadb(copy, length,
                                  JSON_REJECT_DUPLICATES | JSON_DECODE_ANY, &jerr);
        if (!root) {
            int oom = json_error_code(&jerr) == json_error_out_of_memory;
            status = load_fail_offset(&ctx, oom ? ZT_ERR_MEMORY : ZT_ERR_PARSE,
                                      json_syntax_error_offset(copy, length, &jerr),
                                      "syntax error: %s", jerr.text);
        } else {
            json_positions *positions = json_positions_build(copy, length, root);
            if (!positions) {
                status = zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
            } else {
                ctx.positions = positions;
                status = load_top(&ctx, root, ms);
                json_positions_free(positions);
            }
            json_decref(root);
        }
    }
    source_map_free(&map);
    free(copy);
    if (status) {
        zt_motions_release(ms);
        return status;
    }
    *out = ms;
    return ZT_OK;
}

zt_status zt_motions_load_file(const char *path, zt_motions **out, zt_error *err)
{
    zt_error_clear(err);
    if (!path || !out)
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_motions_load_file: no path or no result pointer");
    *out = NULL;
    char *text = NULL;
    size_t n = 0;
    zt_status status = read_text_file(path, "motions file", MAX_MOTIONS_BYTES, &text, &n, err);
    if (!status)
        status = zt_motions_load_string(text, n, path, out, err);
    free(text);
    return status;
}

int zt_motions_count(const zt_motions *ms)
{
    return ms ? ms->count : 0;
}

const zt_motion *zt_motions_get(const zt_motions *ms, int i)
{
    if (!ms || i < 0 || i >= ms->count)
        return NULL;
    return &ms->items[i];
}

int zt_motions_moves_objects(const zt_motions *ms)
{
    return ms && ms->count > 0;
}

const zt_camera_key *zt_motions_camera_path(const zt_motions *ms, int *count)
{
    int n = ms ? ms->path.count : 0;
    if (count)
        *count = n;
    return n ? ms->path.keys : NULL;
}

zt_status zt_motions_check(const zt_motions *ms, const zt_scene *scene,
                           zt_error *err)
{
    zt_error_clear(err);
    if (!ms || !scene)
        return zt_fail(err, ZT_ERR_ARGUMENT, "zt_motions_check: no motions or no scene");
    for (int i = 0; i < ms->count; i++) {
        const zt_motion *m = &ms->items[i];
        int have = zt_scene_object_count(scene, m->target_class);
        if (m->target < have)
            continue;
        const char *cls = m->target_class == ZT_OBJECT_LIGHT ? "light" : "thing";
        char has[96];
        if (have == 0)
            snprintf(has, sizeof has, "the scene has no %ss", cls);
        else if (have == 1)
            snprintf(has, sizeof has, "the scene has one %s (%s 0)", cls, cls);
        else
            snprintf(has, sizeof has, "the scene has %d %ss (0 to %d)", have, cls, have - 1);
        if (m->line > 0)
            return zt_fail(err, ZT_ERR_PARSE, "%s:%d:%d: no %s %d: %s", ms->name,
                           m->line, m->column, cls, m->target, has);
        return zt_fail(err, ZT_ERR_PARSE, "%s: motion %d: no %s %d: %s", ms->name,
                       i + 1, cls, m->target, has);
    }
    return ZT_OK;
}
