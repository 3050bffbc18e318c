/* What a glTF file says that Assimp 5.2 does not pass on, read from the
 * file's JSON: KHR_materials_emissive_strength (newer Assimp gives it as
 * AI_MATKEY_EMISSIVE_INTENSITY, which model_materials.c reads first) and
 * KHR_materials_specular's specularFactor.
 * (Assimp 5.2 does give a material without an emissiveFactor glTF's
 * default, black, also when it has an emissive texture.) */
#ifndef ZT_SCENE_GLTF_EXTENSIONS_H
#define ZT_SCENE_GLTF_EXTENSIONS_H

/* The emissiveStrength of each of the file's first `count` materials into
 * strength[] (glTF's materials in their order, which is Assimp's; 1 where
 * a material has none or a negative or non-finite one).  `path` is a .gltf
 * (JSON) or .glb (its JSON chunk); when it cannot be read or parsed
 * (Assimp has read it already, so that is only short of memory) every
 * strength is 1. */
void gltf_emissive_strengths(const char *path, int count, double *strength);

/* The same for each material's KHR_materials_specular specularFactor
 * (the layer over non-metals; 1 where a material has none, clamped to
 * [0, 1], 1 where it is not a number). */
void gltf_specular_factors(const char *path, int count, double *factor);

#endif
