/* A model material's maps besides its base colour (docs/scene-format.md,
 * "Materials from the model file"): glTF's metallic-roughness, normal and
 * emissive textures, MTL's map_Pr, map_Pm, norm and map_Ke; and what the
 * file has that the renderers do not use, counted for -v.  Used by
 * model_materials.c. */
#ifndef ZT_SCENE_MODEL_MAPS_H
#define ZT_SCENE_MODEL_MAPS_H

#include <math.h>
#include <stddef.h>

#include <assimp/material.h>

#include "scene/mesh.h"

/* A material's float `key` (texture type and index as Assimp keys them)
 * into *out; 0 when the file has none or it is not finite. */
static inline int model_material_float(const struct aiMaterial *am, const char *key, unsigned type,
                                       unsigned index, double *out)
{
    ai_real v;
    unsigned n = 1;
    if (aiGetMaterialFloatArray(am, key, type, index, &v, &n) != aiReturn_SUCCESS || n < 1 ||
        !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

/* The most textures one slot decodes: base colour, roughness, metal,
 * normal, emissive. */
#define MODEL_SLOT_TEXTURES 5

/* The refractive index given to metals: Schlick's term with index 0 is 1
 * at every angle, so the base colour is the reflectance, as glTF defines a
 * metal's at normal incidence.  Only metals without a refractive lobe
 * take it (a scene file's index must be positive). */
#define MODEL_METAL_IOR 0.0

/* Where a file's textures are decoded into: m->textures, their names
 * (each decoded once), room for `capacity`. */
struct aiScene;
typedef struct model_textures {
    const struct aiScene *sc;
    const char *folder;     /* the model's folder, with its slash */
    const char *path;       /* the model file, for messages */
    mesh *m;
    char (*names)[256];
    int capacity;
} model_textures;

/* The material's first texture of `type`, decoded (or found decoded):
 * its index in m->textures; -1 when the material has none; -2 when it
 * cannot be had (the reason in why, room for n), and then *st is set to
 * ZT_ERR_MEMORY when that was memory.  (model_materials.c) */
int model_texture_find(model_textures *tx, const struct aiMaterial *am, enum aiTextureType type,
                       char *why, size_t n, zt_status *st, zt_error *err);

/* printf into a buffer, cut to its size. */
void clip_text(char *to, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Reads slot s's maps (s already mapped from am's factors: roughness,
 * metallic, transmission, emission) and sets its material to what the renderers
 * take when they are not reading the maps at a hit: the metallic weight
 * the maps' mean, the roughness their largest value (so that a slot is
 * rough when any of its texels is).  A map that cannot be decoded is left
 * out and counted in m->map_fallbacks.  Counts what am has that is unused in m->unused.
 * Fails only when out of memory. */
zt_status model_maps(model_textures *tx, const struct aiMaterial *am, int gltf, mesh_slot *s,
                     zt_error *err);

#endif
