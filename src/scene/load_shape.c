/* The geometry of primitives, with the checks that keep later stages free
 * of degenerate cases: positive radii, unit plane normals, triangles with
 * area. */
#include "scene/scene_reader.h"

#include <math.h>
#include <string.h>

#include "scene/load_values.h"

/* A triangle is degenerate when twice its area is this small a fraction of
 * its longest edge squared (its height is that fraction of the edge). */
#define TRIANGLE_FLATNESS 1e-10

/* A plane normal shorter than this cannot give a direction. */
#define NORMAL_MIN_LENGTH 1e-12

static const char *const kind_names[] = {
    "sphere", "plane", "triangle",
    "lightpoint", "lightsphere", "lightplane", "lighttriangle"
};

shape_kind shape_kind_of(const char *key)
{
    for (int k = 0; k < KIND_NONE; k++)
        if (strcmp(key, kind_names[k]) == 0)
            return (shape_kind)k;
    return KIND_NONE;
}

int shape_kind_is_light(shape_kind kind)
{
    return kind >= KIND_LIGHTPOINT && kind < KIND_NONE;
}

static zt_status load_sphere(load_ctx *ctx, jref body, const char *what,
                             part *out)
{
    jref radius = jref_member(body.value, "radius");
    if (load_require(ctx, body, "center", what) ||
        load_require(ctx, body, "radius", what) ||
        load_triple(ctx, jref_member(body.value, "center"), &out->p[0]) ||
        load_number(ctx, radius, &out->radius))
        return ZT_ERR_PARSE;
    if (out->radius <= 0)
        return load_fail(ctx, radius, "radius must be positive, not %g",
                         out->radius);
    out->shape = SHAPE_SPHERE;
    return ZT_OK;
}

/* Stores the unit normal and scales the offset with it, so that the plane
 * n.x = offset stays the same set of points. */
static zt_status load_plane(load_ctx *ctx, jref body, const char *what,
                            part *out)
{
    jref normal = jref_member(body.value, "normal");
    vec3 n;
    double offset;
    if (load_require(ctx, body, "normal", what) ||
        load_require(ctx, body, "offset", what) ||
        load_triple(ctx, normal, &n) ||
        load_number(ctx, jref_member(body.value, "offset"), &offset))
        return ZT_ERR_PARSE;
    double len = v3_length(n);
    if (!(len >= NORMAL_MIN_LENGTH))
        return load_fail(ctx, normal, "zero-length plane normal");
    double unit_offset = offset / len;
    if (!isfinite(unit_offset) || fabs(unit_offset) > LOAD_NUMBER_LIMIT)
        return load_fail(ctx, normal, "plane too far from the origin: "
                         "offset / |normal| = %g", unit_offset);
    out->shape = SHAPE_PLANE;
    out->normal = v3_scale(n, 1.0 / len);
    out->offset = unit_offset;
    return ZT_OK;
}

static zt_status load_triangle(load_ctx *ctx, jref body, const char *what,
                               part *out)
{
    jref points = jref_member(body.value, "points");
    if (load_require(ctx, body, "points", what) ||
        load_triples(ctx, points, 3, out->p))
        return ZT_ERR_PARSE;
    vec3 e0 = v3_sub(out->p[1], out->p[0]);
    vec3 e1 = v3_sub(out->p[2], out->p[0]);
    vec3 e2 = v3_sub(out->p[2], out->p[1]);
    double longest2 = fmax(v3_dot(e0, e0), fmax(v3_dot(e1, e1), v3_dot(e2, e2)));
    double area2 = v3_length(v3_cross(e0, e1));
    if (!(area2 > TRIANGLE_FLATNESS * longest2))
        return load_fail(ctx, points, "degenerate triangle: its points are "
                         "(nearly) collinear or equal");
    out->shape = SHAPE_TRIANGLE;
    return ZT_OK;
}

zt_status load_shape(load_ctx *ctx, shape_kind kind, jref body, part *out)
{
    const char *what = kind_names[kind];
    memset(out, 0, sizeof *out);
    switch (kind) {
    case KIND_SPHERE:
    case KIND_LIGHTSPHERE:
        return load_sphere(ctx, body, what, out);
    case KIND_PLANE:
    case KIND_LIGHTPLANE:
        return load_plane(ctx, body, what, out);
    case KIND_TRIANGLE:
    case KIND_LIGHTTRIANGLE:
        return load_triangle(ctx, body, what, out);
    case KIND_LIGHTPOINT:
        out->shape = SHAPE_POINT;
        if (load_require(ctx, body, "point", what) ||
            load_triple(ctx, jref_member(body.value, "point"), &out->p[0]))
            return ZT_ERR_PARSE;
        return ZT_OK;
    case KIND_NONE:
        break;
    }
    return load_fail(ctx, body, "unknown primitive");
}
