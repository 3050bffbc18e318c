/* Typed readers for scene values (see load_values.h). */
#include "scene/load_values.h"

#include <math.h>
#include <string.h>

const char *load_type_name(const json_t *value)
{
    switch (json_typeof(value)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER: return "an integer";
    case JSON_REAL: return "a number";
    case JSON_TRUE: return "true";
    case JSON_FALSE: return "false";
    case JSON_NULL: return "null";
    }
    return "a value";
}

zt_status load_object(load_ctx *ctx, jref ref, const char *what)
{
    if (!json_is_object(ref.value))
        return load_fail(ctx, ref, "wrong type: %s must be an object, not %s",
                         what, load_type_name(ref.value));
    return ZT_OK;
}

zt_status load_known_keys(load_ctx *ctx, jref obj, const char *what,
                          const char *const *allowed)
{
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)obj.value, key, value) {
        int known = 0;
        for (const char *const *a = allowed; *a && !known; a++)
            known = strcmp(*a, key) == 0;
        if (!known)
            return load_fail_key(ctx, obj.value, key,
                                 "unknown key \"%s\" in %s", key, what);
    }
    return ZT_OK;
}

zt_status load_require(load_ctx *ctx, jref obj, const char *key,
                       const char *what)
{
    if (!json_object_get(obj.value, key))
        return load_fail(ctx, obj, "missing \"%s\" in %s", key, what);
    return ZT_OK;
}

zt_status load_number(load_ctx *ctx, jref ref, double *out)
{
    if (!json_is_number(ref.value))
        return load_fail(ctx, ref, "wrong type: expected a number, not %s",
                         load_type_name(ref.value));
    double x = json_number_value(ref.value);
    if (!isfinite(x))
        return load_fail(ctx, ref, "number is not finite");
    if (fabs(x) > LOAD_NUMBER_LIMIT)
        return load_fail(ctx, ref, "number too large: %g (the limit is 1e12)", x);
    *out = x;
    return ZT_OK;
}

zt_status load_bool(load_ctx *ctx, jref ref, int *out)
{
    if (!json_is_boolean(ref.value))
        return load_fail(ctx, ref, "wrong type: expected true or false, not %s",
                         load_type_name(ref.value));
    *out = json_is_true(ref.value);
    return ZT_OK;
}

zt_status load_triple(load_ctx *ctx, jref ref, vec3 *out)
{
    if (!json_is_array(ref.value))
        return load_fail(ctx, ref, "wrong type: expected [x, y, z], not %s",
                         load_type_name(ref.value));
    size_t n = json_array_size(ref.value);
    if (n != 3)
        return load_fail(ctx, ref, "wrong length: expected 3 numbers, found %zu", n);
    double v[3];
    for (size_t i = 0; i < 3; i++)
        if (load_number(ctx, jref_element(ref.value, i), &v[i]))
            return ZT_ERR_PARSE;
    *out = v3(v[0], v[1], v[2]);
    return ZT_OK;
}

zt_status load_albedo(load_ctx *ctx, jref ref, vec3 *out)
{
    if (load_triple(ctx, ref, out))
        return ZT_ERR_PARSE;
    double v[3] = {out->x, out->y, out->z};
    for (size_t i = 0; i < 3; i++)
        if (v[i] < 0 || v[i] > 1)
            return load_fail(ctx, jref_element(ref.value, i),
                             "colour out of range: %g is not in [0, 1]", v[i]);
    return ZT_OK;
}

zt_status load_radiance(load_ctx *ctx, jref ref, vec3 *out)
{
    if (load_triple(ctx, ref, out))
        return ZT_ERR_PARSE;
    double v[3] = {out->x, out->y, out->z};
    for (size_t i = 0; i < 3; i++)
        if (v[i] < 0)
            return load_fail(ctx, jref_element(ref.value, i),
                             "negative radiance: %g", v[i]);
    return ZT_OK;
}

zt_status load_triples(load_ctx *ctx, jref ref, int count, vec3 *out)
{
    if (!json_is_array(ref.value))
        return load_fail(ctx, ref, "wrong type: expected a list of %d [x, y, z], not %s",
                         count, load_type_name(ref.value));
    size_t n = json_array_size(ref.value);
    if (n != (size_t)count)
        return load_fail(ctx, ref, "wrong length: expected %d points, found %zu",
                         count, n);
    for (int i = 0; i < count; i++)
        if (load_triple(ctx, jref_element(ref.value, (size_t)i), &out[i]))
            return ZT_ERR_PARSE;
    return ZT_OK;
}

zt_status load_int(load_ctx *ctx, jref ref, long long lo, long long hi,
                   long long *out)
{
    if (!json_is_integer(ref.value))
        return load_fail(ctx, ref, "wrong type: expected an integer, not %s",
                         load_type_name(ref.value));
    long long x = json_integer_value(ref.value);
    if (x < lo || x > hi)
        return load_fail(ctx, ref, "out of range: %lld is not in %lld..%lld",
                         x, lo, hi);
    *out = x;
    return ZT_OK;
}
