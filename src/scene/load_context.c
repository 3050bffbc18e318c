/* Positions of values and the loader's error messages. */
#include "scene/load_context.h"

#include <stdarg.h>
#include <stdio.h>

#include "util/error.h"

jref jref_root(const json_t *root)
{
    jref r = {root, NULL, NULL, 0};
    return r;
}

jref jref_member(const json_t *obj, const char *key)
{
    jref r = {json_object_get(obj, key), obj, key, 0};
    return r;
}

jref jref_element(const json_t *array, size_t index)
{
    jref r = {json_array_get(array, index), array, NULL, index};
    return r;
}

/* Offset of ref in the parsed text.  A missing member has no place: callers
 * report those at the object that lacks it. */
static size_t ref_offset(const load_ctx *ctx, jref ref)
{
    const json_positions *pos = ctx->positions;
    if (!ref.parent)
        return json_positions_root(pos);
    if (ref.key)
        return ref.value ? json_positions_member(pos, ref.parent, ref.key)
                         : SOURCE_OFFSET_UNKNOWN;
    return json_positions_element(pos, ref.parent, ref.index);
}

static zt_status vfail(load_ctx *ctx, zt_status status, size_t parsed,
                       const char *fmt, va_list ap)
{
    char what[ZT_ERROR_MESSAGE_MAX];
    vsnprintf(what, sizeof what, fmt, ap);
    int line, column;
    size_t original = source_map_original(ctx->map, parsed);
    if (source_map_locate(ctx->map, original, &line, &column))
        return zt_fail(ctx->err, status, "%s:%d:%d: %s", ctx->name, line,
                       column, what);
    return zt_fail(ctx->err, status, "%s: %s", ctx->name, what);
}

zt_status load_fail_offset(load_ctx *ctx, zt_status status, size_t parsed,
                           const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    zt_status s = vfail(ctx, status, parsed, fmt, ap);
    va_end(ap);
    return s;
}

zt_status load_fail(load_ctx *ctx, jref ref, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    zt_status s = vfail(ctx, ZT_ERR_PARSE, ref_offset(ctx, ref), fmt, ap);
    va_end(ap);
    return s;
}

zt_status load_fail_status(load_ctx *ctx, zt_status status, jref ref, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    zt_status s = vfail(ctx, status, ref_offset(ctx, ref), fmt, ap);
    va_end(ap);
    return s;
}

zt_status load_fail_key(load_ctx *ctx, const json_t *obj, const char *key,
                        const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    zt_status s = vfail(ctx, ZT_ERR_PARSE,
                        json_positions_key(ctx->positions, obj, key), fmt, ap);
    va_end(ap);
    return s;
}

int load_line(const load_ctx *ctx, jref ref)
{
    int line, column;
    size_t original = source_map_original(ctx->map, ref_offset(ctx, ref));
    return source_map_locate(ctx->map, original, &line, &column) ? line : 0;
}

void load_file_path(const load_ctx *ctx, const char *file, char *out, size_t size)
{
    if (file[0] == '/' || !ctx->dir || !ctx->dir[0])
        snprintf(out, size, "%s", file);
    else
        snprintf(out, size, "%s%s", ctx->dir, file);
}
