/* The materials of a model file mapped onto the four-weight material, and
 * their textures decoded: base colour here, roughness, metal and normal
 * maps in model_maps.c (docs/scene-format.md, "Meshes from model files",
 * says what maps to what). */
#ifndef ZT_SCENE_MODEL_MATERIALS_H
#define ZT_SCENE_MODEL_MATERIALS_H

#include "scene/mesh.h"

struct aiScene;

/* Fills m->slots (slot_count slots; slot_of_material[i] is the slot of the
 * file's material i, -1 for materials no triangle uses) and m->textures.
 * path is the model file (external textures are relative to its folder).
 * A texture that is missing or cannot be decoded is left out (the slot
 * keeps its base colour) and counted in m->missing_textures with the first
 * reason in m->texture_problem: a model is still worth rendering without
 * one (maps: model_maps.h).  Fails only when out of memory. */
zt_status model_materials(const struct aiScene *sc, const char *path,
                          const int *slot_of_material, int slot_count, mesh *m, zt_error *err);

#endif
