/* Scene model: construction, copies, queries and rigid motions. */
#include "scene/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "light/env_map.h"
#include "scene/mesh.h"
#include "util/error.h"

zt_scene *scene_create(void)
{
    return calloc(1, sizeof(zt_scene));
}

void zt_scene_release(zt_scene *scene)
{
    if (!scene)
        return;
    free(scene->objects);
    free(scene->parts);
    for (int i = 0; i < scene->mesh_count; i++)
        mesh_release(scene->meshes[i]);
    free(scene->meshes);
    env_map_release(scene->sky_map);
    free(scene);
}

static int grow(void **data, int *capacity, int needed, size_t elem)
{
    if (needed <= *capacity)
        return 1;
    int cap = *capacity ? *capacity * 2 : 16;
    while (cap < needed)
        cap *= 2;
    void *p = realloc(*data, (size_t)cap * elem);
    if (!p)
        return 0;
    *data = p;
    *capacity = cap;
    return 1;
}

int scene_add_object(zt_scene *scene, const object *obj)
{
    if (!grow((void **)&scene->objects, &scene->object_capacity,
              scene->object_count + 1, sizeof(object)))
        return -1;
    object *o = &scene->objects[scene->object_count];
    *o = *obj;
    o->index = obj->is_light ? scene->light_count++ : scene->thing_count++;
    o->first_part = scene->part_count;
    o->part_count = 0;
    o->mesh = -1;
    return scene->object_count++;
}

int scene_add_mesh_object(zt_scene *scene, const object *obj, struct mesh *m)
{
    if (!grow((void **)&scene->meshes, &scene->mesh_capacity, scene->mesh_count + 1,
              sizeof(struct mesh *)))
        return -1;
    int i = scene_add_object(scene, obj);
    if (i < 0)
        return -1;
    scene->meshes[scene->mesh_count] = m;
    scene->objects[i].mesh = scene->mesh_count++;
    return i;
}

long long scene_mesh_triangles(const zt_scene *scene)
{
    long long n = 0;
    for (int i = 0; i < scene->mesh_count; i++)
        n += scene->meshes[i]->triangle_count;
    return n;
}

int scene_add_part(zt_scene *scene, const part *p)
{
    if (scene->object_count == 0)
        return -1;
    if (!grow((void **)&scene->parts, &scene->part_capacity,
              scene->part_count + 1, sizeof(part)))
        return -1;
    part *q = &scene->parts[scene->part_count];
    *q = *p;
    q->object = scene->object_count - 1;
    scene->objects[q->object].part_count++;
    return scene->part_count++;
}

material material_default(void)
{
    material m;
    memset(&m, 0, sizeof m);
    m.weight[LOBE_DIFFUSE] = 1.0;
    m.ior = 1.0;
    m.tint = v3(1, 1, 1);
    m.alpha_cutoff = 0.5;
    m.coverage = 1.0;
    return m;
}

zt_scene *zt_scene_clone(const zt_scene *scene)
{
    zt_scene *c = scene_create();
    if (!c)
        return NULL;
    *c = *scene;
    c->objects = NULL;
    c->parts = NULL;
    c->meshes = NULL;
    c->mesh_count = 0;
    c->object_capacity = scene->object_count;
    c->part_capacity = scene->part_count;
    c->mesh_capacity = scene->mesh_count;
    if (scene->sky_map)
        env_map_retain(scene->sky_map);
    if (scene->object_count) {
        c->objects = malloc((size_t)scene->object_count * sizeof(object));
        if (c->objects)
            memcpy(c->objects, scene->objects, (size_t)scene->object_count * sizeof(object));
    }
    if (scene->part_count) {
        c->parts = malloc((size_t)scene->part_count * sizeof(part));
        if (c->parts)
            memcpy(c->parts, scene->parts, (size_t)scene->part_count * sizeof(part));
    }
    if (scene->mesh_count) {
        c->meshes = malloc((size_t)scene->mesh_count * sizeof *c->meshes);
        if (c->meshes)
            for (; c->mesh_count < scene->mesh_count; c->mesh_count++)
                c->meshes[c->mesh_count] = mesh_retain(scene->meshes[c->mesh_count]);
    }
    if ((scene->object_count && !c->objects) || (scene->part_count && !c->parts) ||
        (scene->mesh_count && !c->meshes)) {
        zt_scene_release(c);
        return NULL;
    }
    return c;
}

void zt_scene_get_info(const zt_scene *scene, zt_scene_info *out)
{
    memset(out, 0, sizeof *out);
    long long unused[MESH_UNUSED_COUNT] = {0};
    out->lights = scene->light_count;
    out->things = scene->thing_count;
    out->has_sky = scene->has_sky;
    for (int i = 0; i < scene->part_count; i++) {
        const part *p = &scene->parts[i];
        if (scene->objects[p->object].is_light)
            out->light_parts++;
        else
            out->thing_parts++;
        switch (p->shape) {
        case SHAPE_SPHERE: out->spheres++; break;
        case SHAPE_PLANE: out->planes++; break;
        case SHAPE_TRIANGLE: out->triangles++; break;
        case SHAPE_POINT: out->points++; break;
        }
    }
    for (int i = 0; i < scene->object_count; i++) {
        const object *o = &scene->objects[i];
        out->panes += o->mesh < 0 && o->mat.thin;
        out->alpha_masks += o->mesh < 0 && !o->is_light && o->mat.alpha_mode == ALPHA_MASK;
        out->alpha_blends += o->mesh < 0 && !o->is_light && o->mat.alpha_mode == ALPHA_BLEND;
        out->rough_lobes += o->mesh < 0 && !o->is_light && o->mat.roughness > 0 &&
                            o->mat.weight[LOBE_DIFFUSE] < 1;
        if (o->mesh < 0)
            continue;
        const struct mesh *m = scene->meshes[o->mesh];
        out->meshes++;
        out->mesh_triangles += m->triangle_count;
        out->skipped_triangles += m->skipped_degenerate;
        out->replaced_normals += m->replaced_normals;
        out->rough_materials += m->rough_slots;
        for (int s = 0; s < m->slot_count; s++) {
            out->panes += m->slots[s].mat.thin;
            out->alpha_masks += m->slots[s].mat.alpha_mode == ALPHA_MASK;
            out->alpha_blends += m->slots[s].mat.alpha_mode == ALPHA_BLEND;
        }
        if (m->alpha_fallbacks && !out->alpha_fallbacks)
            snprintf(out->alpha_problem, sizeof out->alpha_problem, "%s", m->alpha_problem);
        out->alpha_fallbacks += m->alpha_fallbacks;
        if (m->missing_textures && !out->missing_textures)
            snprintf(out->texture_problem, sizeof out->texture_problem, "%s", m->texture_problem);
        out->missing_textures += m->missing_textures;
        if (m->map_fallbacks && !out->map_fallbacks)
            snprintf(out->map_problem, sizeof out->map_problem, "%s", m->map_problem);
        out->map_fallbacks += m->map_fallbacks;
        out->emissive_pieces += m->emissive_pieces;
        for (int k = 0; k < MESH_UNUSED_COUNT; k++)
            unused[k] += m->unused[k];
        for (int t = 0; t < m->triangle_count; t++) {
            int light = o->is_light || !v3_is_black(m->slots[mesh_slot_of(m, t)].emission);
            if (light)
                out->light_parts++;
            else
                out->thing_parts++;
        }
    }
    size_t len = 0;
    for (int k = 0; k < MESH_UNUSED_COUNT; k++)
        if (unused[k] && len < sizeof out->unused) {
            int w = snprintf(out->unused + len, sizeof out->unused - len, "%s%lld %s",
                             len ? ", " : "", unused[k], mesh_unused_name(k));
            len += w > 0 ? (size_t)w : 0;
        }
}

zt_camera zt_scene_get_camera(const zt_scene *scene)
{
    return scene->camera;
}

void zt_scene_set_camera(zt_scene *scene, const zt_camera *camera)
{
    scene->camera = *camera;
    scene->has_camera = 1;
}

int zt_scene_object_count(const zt_scene *scene, zt_object_class cls)
{
    return cls == ZT_OBJECT_LIGHT ? scene->light_count : scene->thing_count;
}

object *scene_find_object(zt_scene *scene, zt_object_class cls, int index)
{
    int want_light = cls == ZT_OBJECT_LIGHT;
    for (int i = 0; i < scene->object_count; i++) {
        object *o = &scene->objects[i];
        if (o->is_light == want_light && o->index == index)
            return o;
    }
    return NULL;
}

static object *find_or_fail(zt_scene *scene, zt_object_class cls, int index,
                            zt_error *err)
{
    object *o = scene_find_object(scene, cls, index);
    if (!o)
        zt_fail(err, ZT_ERR_ARGUMENT, "no %s with index %d (the scene has %d)",
                cls == ZT_OBJECT_LIGHT ? "light" : "thing", index,
                zt_scene_object_count(scene, cls));
    return o;
}

zt_status zt_scene_translate_object(zt_scene *scene, zt_object_class cls,
                                    int index, const double delta[3],
                                    zt_error *err)
{
    object *o = find_or_fail(scene, cls, index, err);
    if (!o)
        return ZT_ERR_ARGUMENT;
    vec3 d = v3_from(delta);
    if (o->mesh >= 0) {
        const double a[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        if (!mesh_make_unique(&scene->meshes[o->mesh]))
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory moving a mesh");
        mesh_transform(scene->meshes[o->mesh], a, delta);
        return ZT_OK;
    }
    for (int i = 0; i < o->part_count; i++) {
        part *p = &scene->parts[o->first_part + i];
        for (int k = 0; k < 3; k++)
            p->p[k] = v3_add(p->p[k], d);
        if (p->shape == SHAPE_PLANE)
            p->offset += v3_dot(p->normal, d);
    }
    return ZT_OK;
}

zt_status zt_scene_rotate_object(zt_scene *scene, zt_object_class cls,
                                 int index, int axis, double angle,
                                 zt_error *err)
{
    if (axis < 0 || axis > 2)
        return zt_fail(err, ZT_ERR_ARGUMENT, "rotation axis must be 0, 1 or 2");
    object *o = find_or_fail(scene, cls, index, err);
    if (!o)
        return ZT_ERR_ARGUMENT;
    if (o->mesh >= 0) {
        double a[9];
        for (int c = 0; c < 3; c++) {
            vec3 e = v3_rotate_axis(v3(c == 0, c == 1, c == 2), axis, angle);
            a[0 + c] = e.x;
            a[3 + c] = e.y;
            a[6 + c] = e.z;
        }
        const double t[3] = {0, 0, 0};
        if (!mesh_make_unique(&scene->meshes[o->mesh]))
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory moving a mesh");
        mesh_transform(scene->meshes[o->mesh], a, t);
        return ZT_OK;
    }
    for (int i = 0; i < o->part_count; i++) {
        part *p = &scene->parts[o->first_part + i];
        for (int k = 0; k < 3; k++)
            p->p[k] = v3_rotate_axis(p->p[k], axis, angle);
        /* A plane through the origin-centred rotation keeps its offset. */
        if (p->shape == SHAPE_PLANE)
            p->normal = v3_rotate_axis(p->normal, axis, angle);
    }
    return ZT_OK;
}

zt_status zt_scene_object_position(const zt_scene *scene, zt_object_class cls,
                                   int index, double out[3], zt_error *err)
{
    object *o = find_or_fail((zt_scene *)scene, cls, index, err);
    if (!o)
        return ZT_ERR_ARGUMENT;
    if (o->mesh >= 0) {
        /* The centre of the mesh's box: one point, cheap for big meshes. */
        vec3 lo, hi;
        mesh_bounds(scene->meshes[o->mesh], &lo, &hi);
        v3_store(v3_scale(v3_add(lo, hi), 0.5), out);
        return ZT_OK;
    }
    vec3 sum = v3(0, 0, 0);
    for (int i = 0; i < o->part_count; i++) {
        const part *p = &scene->parts[o->first_part + i];
        vec3 c;
        if (p->shape == SHAPE_TRIANGLE)
            c = v3_scale(v3_add(v3_add(p->p[0], p->p[1]), p->p[2]), 1.0 / 3.0);
        else if (p->shape == SHAPE_PLANE)
            c = v3_scale(p->normal, p->offset);
        else
            c = p->p[0];
        sum = v3_add(sum, c);
    }
    v3_store(o->part_count ? v3_scale(sum, 1.0 / o->part_count) : sum, out);
    return ZT_OK;
}

zt_status zt_camera_set_resolution(zt_camera *camera, int width, int height,
                                   zt_error *err)
{
    if (width < 1 || height < 1 || width > 32768 || height > 32768 ||
        (long long)width * height > (1LL << 28))
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "resolution %dx%d is out of range (1..32768 per side, "
                       "at most 268435456 pixels)", width, height);
    camera->width = width;
    camera->height = height;
    return ZT_OK;
}
