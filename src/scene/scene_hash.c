/* A scene's fingerprint: everything that shapes the light, and nothing of
 * the camera. */
#include "scene/scene_hash.h"

#include "light/env_map.h"
#include "scene/mesh.h"
#include "util/fnv1a.h"

uint64_t scene_hash(const zt_scene *sc)
{
    fnv1a h = {FNV1A_START};
    fnv_i32(&h, sc->object_count);
    fnv_i32(&h, sc->part_count);
    for (int i = 0; i < sc->object_count; i++) {
        const object *o = &sc->objects[i];
        fnv_i32(&h, o->is_light);
        fnv_i32(&h, o->index);
        fnv_i32(&h, o->background);
        fnv_i32(&h, o->backculled);
        for (int k = 0; k < LOBE_COUNT; k++)
            fnv_f64(&h, o->mat.weight[k]);
        fnv_v3(&h, o->mat.color);
        fnv_f64(&h, o->mat.ior);
        if (o->mat.thin) { /* (only then: earlier forests stay valid) */
            fnv_i32(&h, o->mat.thin);
            fnv_v3(&h, o->mat.tint);
        }
        if (o->mat.roughness > 0)
            fnv_f64(&h, o->mat.roughness);
        if (o->mat.specular > 0) /* (only then, as above) */
            fnv_f64(&h, o->mat.specular);
        if (o->mat.alpha_mode != ALPHA_OPAQUE) { /* (only then, as above) */
            fnv_i32(&h, o->mat.alpha_mode);
            fnv_f64(&h, o->mat.alpha_cutoff);
            fnv_f64(&h, o->mat.coverage);
        }
        fnv_v3(&h, o->emission);
        fnv_i32(&h, o->first_part);
        fnv_i32(&h, o->part_count);
    }
    for (int i = 0; i < sc->part_count; i++) {
        const part *p = &sc->parts[i];
        fnv_i32(&h, (int)p->shape);
        fnv_i32(&h, p->object);
        for (int k = 0; k < 3; k++)
            fnv_v3(&h, p->p[k]);
        fnv_f64(&h, p->radius);
        fnv_v3(&h, p->normal);
        fnv_f64(&h, p->offset);
    }
    /* Meshes: every array, the materials and the texture texels. */
    fnv_i32(&h, sc->mesh_count);
    for (int i = 0; i < sc->object_count; i++) {
        const object *o = &sc->objects[i];
        fnv_i32(&h, o->mesh);
        if (o->mesh < 0)
            continue;
        const mesh *m = sc->meshes[o->mesh];
        fnv_i32(&h, m->vertex_count);
        fnv_i32(&h, m->triangle_count);
        fnv_bytes(&h, (const unsigned char *)m->position, (size_t)m->vertex_count * 3 * sizeof(float));
        fnv_i32(&h, m->normal != NULL);
        if (m->normal)
            fnv_bytes(&h, (const unsigned char *)m->normal, (size_t)m->vertex_count * 3 * sizeof(float));
        fnv_i32(&h, m->uv != NULL);
        if (m->uv)
            fnv_bytes(&h, (const unsigned char *)m->uv, (size_t)m->vertex_count * 2 * sizeof(float));
        fnv_bytes(&h, (const unsigned char *)m->index, (size_t)m->triangle_count * 3 * sizeof(uint32_t));
        fnv_i32(&h, m->slot != NULL);
        if (m->slot)
            fnv_bytes(&h, (const unsigned char *)m->slot, (size_t)m->triangle_count * sizeof(uint16_t));
        fnv_i32(&h, m->slot_count);
        for (int k = 0; k < m->slot_count; k++) {
            const mesh_slot *sl = &m->slots[k];
            for (int l = 0; l < LOBE_COUNT; l++)
                fnv_f64(&h, sl->mat.weight[l]);
            fnv_v3(&h, sl->mat.color);
            fnv_f64(&h, sl->mat.ior);
            if (sl->mat.thin) {
                fnv_i32(&h, sl->mat.thin);
                fnv_v3(&h, sl->mat.tint);
            }
            /* (A roughness on a diffuse-only slot shapes nothing: glTF
             * gives every material one, and forests of such models saved
             * before roughness was read stay valid.) */
            if (sl->mat.roughness > 0 && sl->mat.weight[LOBE_DIFFUSE] < 1)
                fnv_f64(&h, sl->mat.roughness);
            if (sl->mat.specular > 0) { /* the coat's roughness too */
                fnv_f64(&h, sl->mat.specular);
                fnv_f64(&h, sl->mat.roughness);
            }
            fnv_v3(&h, sl->emission);
            fnv_i32(&h, sl->texture);
            if (sl->mat.alpha_mode != ALPHA_OPAQUE) {
                fnv_i32(&h, sl->mat.alpha_mode);
                fnv_f64(&h, sl->mat.alpha_cutoff);
                fnv_f64(&h, sl->mat.coverage);
            }
            /* Hashed only when present (earlier forests stay valid). */
            if (sl->emissive_texture >= 0)
                fnv_i32(&h, sl->emissive_texture);
            /* Maps: hashed only when present (earlier forests stay valid). */
            if (sl->rough_map.texture >= 0 || sl->metal_map.texture >= 0 ||
                sl->normal_texture >= 0) {
                fnv_i32(&h, sl->rough_map.texture);
                fnv_i32(&h, sl->rough_map.channel);
                fnv_i32(&h, sl->metal_map.texture);
                fnv_i32(&h, sl->metal_map.channel);
                fnv_i32(&h, sl->normal_texture);
                fnv_f64(&h, sl->roughness);
                fnv_f64(&h, sl->metallic);
                fnv_f64(&h, sl->transmission);
                fnv_f64(&h, sl->normal_scale);
            }
        }
        if (m->tangent)
            fnv_bytes(&h, (const unsigned char *)m->tangent,
                      (size_t)m->vertex_count * 4 * sizeof(float));
        fnv_i32(&h, m->texture_count);
        for (int k = 0; k < m->texture_count; k++) {
            const mesh_texture *t = &m->textures[k];
            fnv_i32(&h, t->width);
            fnv_i32(&h, t->height);
            fnv_i32(&h, t->wrap);
            fnv_bytes(&h, t->rgba, (size_t)t->width * t->height * 4);
        }
    }
    fnv_v3(&h, sc->sky);
    fnv_i32(&h, sc->has_sky);
    /* Daylight: hashed only when present, so that forests saved before it
     * existed keep their hash. */
    if (sc->sky_map) {
        const env_map *m = sc->sky_map;
        fnv_i32(&h, m->width);
        fnv_i32(&h, m->height);
        fnv_bytes(&h, (const unsigned char *)m->rgb, (size_t)m->width * m->height * 3 * sizeof(float));
        fnv_f64(&h, sc->sky_strength);
        fnv_f64(&h, sc->sky_rotate);
    }
    if (sc->sun.present) {
        fnv_v3(&h, sc->sun.direction);
        fnv_v3(&h, sc->sun.irradiance);
        fnv_f64(&h, sc->sun.angle);
    }
    return h.h;
}
