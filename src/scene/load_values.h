/* Typed readers for the values of a scene file.  Each checks the type and
 * range of one value and reports a failure at that value; all return ZT_OK
 * or ZT_ERR_PARSE (with the message in ctx->err). */
#ifndef ZT_SCENE_LOAD_VALUES_H
#define ZT_SCENE_LOAD_VALUES_H

#include "scene/load_context.h"

/* Numbers beyond this are taken for mistakes (and would overflow squares). */
#define LOAD_NUMBER_LIMIT 1e12

/* "a number", "a string", ... for messages. */
const char *load_type_name(const json_t *value);

/* Fails unless ref is an object; `what` names it in the message. */
zt_status load_object(load_ctx *ctx, jref ref, const char *what);

/* Fails at the first key of object (ref) that is not in the NULL-terminated
 * list `allowed`, naming the key and `what`. */
zt_status load_known_keys(load_ctx *ctx, jref obj, const char *what,
                          const char *const *allowed);

/* Fails at object (ref) when member key is missing. */
zt_status load_require(load_ctx *ctx, jref obj, const char *key,
                       const char *what);

/* A finite number with |x| <= LOAD_NUMBER_LIMIT. */
zt_status load_number(load_ctx *ctx, jref ref, double *out);

/* true or false. */
zt_status load_bool(load_ctx *ctx, jref ref, int *out);

/* An array of exactly three numbers. */
zt_status load_triple(load_ctx *ctx, jref ref, vec3 *out);

/* A triple with each component in [0,1] (an albedo). */
zt_status load_albedo(load_ctx *ctx, jref ref, vec3 *out);

/* A triple with no negative component (a radiance or intensity). */
zt_status load_radiance(load_ctx *ctx, jref ref, vec3 *out);

/* An array of exactly `count` triples. */
zt_status load_triples(load_ctx *ctx, jref ref, int count, vec3 *out);

/* An integer in [lo, hi]. */
zt_status load_int(load_ctx *ctx, jref ref, long long lo, long long hi,
                   long long *out);

#endif
