/* The "mesh" item: a model file read with Assimp (model_import.c), placed
 * by a transform, with the file's materials or one given in the scene. */
#include "scene/scene_reader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/load_values.h"
#include "scene/mesh.h"
#include "scene/model_import.h"

#define PI 3.14159265358979323846

/* 3x3 row-major product c = a b. */
static void mat3_mul(const double a[9], const double b[9], double c[9])
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
    memcpy(c, r, sizeof r);
}

/* Rotation by `degrees` about unit axis u, right-handed (Rodrigues). */
static void mat3_rotation(vec3 u, double degrees, double r[9])
{
    double a = degrees * PI / 180.0, c = cos(a), s = sin(a), k = 1.0 - c;
    r[0] = c + u.x * u.x * k;       r[1] = u.x * u.y * k - u.z * s; r[2] = u.x * u.z * k + u.y * s;
    r[3] = u.y * u.x * k + u.z * s; r[4] = c + u.y * u.y * k;       r[5] = u.y * u.z * k - u.x * s;
    r[6] = u.z * u.x * k - u.y * s; r[7] = u.z * u.y * k + u.x * s; r[8] = c + u.z * u.z * k;
}

/* {"scale": s or [sx, sy, sz], "rotate": [[ax, ay, az, degrees], ...],
 * "translate": [x, y, z]}: p -> a p + t, scale first, then each rotation in
 * order, then the translation. */
zt_status load_transform(load_ctx *ctx, jref ref, double a[9], double t[3])
{
    static const char *const keys[] = {"scale", "rotate", "translate", NULL};
    const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(a, identity, sizeof identity);
    t[0] = t[1] = t[2] = 0;
    if (load_object(ctx, ref, "transform") || load_known_keys(ctx, ref, "transform", keys))
        return ZT_ERR_PARSE;
    jref scale = jref_member(ref.value, "scale");
    if (scale.value) {
        vec3 s;
        if (json_is_array(scale.value)) {
            if (load_triple(ctx, scale, &s))
                return ZT_ERR_PARSE;
        } else {
            double k;
            if (load_number(ctx, scale, &k))
                return ZT_ERR_PARSE;
            s = v3(k, k, k);
        }
        if (s.x == 0 || s.y == 0 || s.z == 0)
            return load_fail(ctx, scale, "bad scale: a factor of 0 flattens the model");
        a[0] = s.x;
        a[4] = s.y;
        a[8] = s.z;
    }
    jref rotate = jref_member(ref.value, "rotate");
    if (rotate.value) {
        if (!json_is_array(rotate.value))
            return load_fail(ctx, rotate, "wrong type: rotate must be a list of "
                             "[ax, ay, az, degrees], not %s", load_type_name(rotate.value));
        for (size_t i = 0; i < json_array_size(rotate.value); i++) {
            jref r = jref_element(rotate.value, i);
            if (!json_is_array(r.value) || json_array_size(r.value) != 4)
                return load_fail(ctx, r, "wrong type: a rotation is [ax, ay, az, degrees]");
            double v[4];
            for (size_t k = 0; k < 4; k++)
                if (load_number(ctx, jref_element(r.value, k), &v[k]))
                    return ZT_ERR_PARSE;
            vec3 axis = v3(v[0], v[1], v[2]);
            if (!(v3_length(axis) > 0))
                return load_fail(ctx, r, "bad rotation: the axis is zero");
            double m[9];
            mat3_rotation(v3_normalize(axis), v[3], m);
            mat3_mul(m, a, a);
        }
    }
    jref translate = jref_member(ref.value, "translate");
    if (translate.value) {
        vec3 d;
        if (load_triple(ctx, translate, &d))
            return ZT_ERR_PARSE;
        v3_store(d, t);
    }
    return ZT_OK;
}

zt_status load_mesh_item(load_ctx *ctx, jref item, jref body, int line)
{
    static const char *const keys[] = {"file", "material", "emission", "transform",
                                       "backculled", "background", "smooth", NULL};
    if (load_object(ctx, body, "mesh") || load_known_keys(ctx, body, "mesh", keys) ||
        load_require(ctx, body, "file", "mesh"))
        return ZT_ERR_PARSE;
    jref file = jref_member(body.value, "file");
    if (!json_is_string(file.value) || json_string_length(file.value) == 0)
        return load_fail(ctx, file, "wrong type: a mesh's file must be a non-empty "
                         "string (a path relative to the scene file)");
    jref material = jref_member(body.value, "material");
    jref emission = jref_member(body.value, "emission");
    if (material.value && emission.value)
        return load_fail(ctx, emission, "a mesh with an emission is a light and takes "
                         "no material");

    object o;
    memset(&o, 0, sizeof o);
    o.mat = material_default();
    o.line = line;
    int smooth = 1;
    double a[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, t[3] = {0, 0, 0};
    jref transform = jref_member(body.value, "transform");
    if (transform.value && load_transform(ctx, transform, a, t))
        return ZT_ERR_PARSE;
    jref flag = jref_member(body.value, "backculled");
    if (flag.value && load_bool(ctx, flag, &o.backculled))
        return ZT_ERR_PARSE;
    flag = jref_member(body.value, "background");
    if (flag.value && load_bool(ctx, flag, &o.background))
        return ZT_ERR_PARSE;
    flag = jref_member(body.value, "smooth");
    if (flag.value && load_bool(ctx, flag, &smooth))
        return ZT_ERR_PARSE;
    if (material.value && load_material(ctx, material, &o.mat))
        return ZT_ERR_PARSE;
    if (emission.value) {
        if (load_radiance(ctx, emission, &o.emission))
            return ZT_ERR_PARSE;
        o.is_light = 1;
    }

    char path[4096];
    load_file_path(ctx, json_string_value(file.value), path, sizeof path);
    model_import_options opt = {.smooth = smooth};
    mesh *m = NULL;
    zt_error ierr;
    zt_error_clear(&ierr);
    zt_status st = model_import(path, &opt, &m, NULL, &ierr);
    if (st != ZT_OK)
        return load_fail_status(ctx, st, item, "mesh: %s", ierr.message);
    snprintf(m->file, sizeof m->file, "%s", json_string_value(file.value));
    if (transform.value)
        mesh_transform(m, a, t);
    if (material.value && !o.is_light) {
        /* One material for every triangle: the file's slots go. */
        m->slots[0].mat = o.mat;
        m->slots[0].emission = v3(0, 0, 0);
        m->slots[0].texture = m->slots[0].emissive_texture = -1;
        m->slots[0].rough_map.texture = m->slots[0].metal_map.texture = -1;
        m->slots[0].normal_texture = -1;
        m->slots[0].roughness = 0;
        m->slot_count = 1;
        m->rough_slots = 0;
        free(m->slot);
        m->slot = NULL;
    }
    if (scene_add_mesh_object(ctx->scene, &o, m) < 0) {
        mesh_release(m);
        return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN, "out of memory");
    }
    return ZT_OK;
}
