/* A model material's roughness, metal and normal maps (model_maps.h).
 *
 * glTF keeps roughness in the green channel and metalness in the blue one
 * of one metallic-roughness texture; Assimp 5.2 names that texture
 * aiTextureType_UNKNOWN (and, for the same file, METALNESS and
 * DIFFUSE_ROUGHNESS).  MTL's map_Pr and map_Pm arrive as DIFFUSE_ROUGHNESS
 * and METALNESS, one grey image each (its red channel is read), and `norm`
 * as NORMALS, like glTF's normal texture.  All of them are data: their
 * texels are read linearly, not through the sRGB curve. */
#include "scene/model_maps.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <assimp/scene.h>

#include "util/error.h"

/* A map left out: counted, the first one named with the reason. */
static void fallback(mesh *m, const mesh_slot *s, const char *what, const char *why)
{
    if (m->map_fallbacks++ == 0)
        clip_text(m->map_problem, sizeof m->map_problem, "material '%s': %s %s", s->name, what,
                  why);
}

/* The material's map of `type`, or -1 (none, or left out). */
static int find_map(model_textures *tx, const struct aiMaterial *am, enum aiTextureType type,
                    const char *what, const mesh_slot *s, zt_status *st, zt_error *err)
{
    char why[160];
    int k = model_texture_find(tx, am, type, why, sizeof why, st, err);
    if (k == -2 && *st == ZT_OK)
        fallback(tx->m, s, what, why);
    /* Maps are looked up by texture coordinates: their size need not be
     * the base texture's (glTF files often have a smaller normal map). */
    return k < 0 ? -1 : k;
}

/* MTL's map_Bump (Assimp's HEIGHT texture) is a height map by the
 * letter of the format, but exporters (Blender's among them) write normal
 * maps there, MTL's `norm` being little known.  An image whose mean is a
 * normal map's (blue near 1, red and green near a half; a grey height map
 * has the three equal) is taken as one, with -bm as its scale.  Returns 1
 * when it was; a height map is not used (and not kept). */
static int bump_as_normal_map(model_textures *tx, const struct aiMaterial *am, mesh_slot *s,
                              zt_status *st, zt_error *err)
{
    mesh *m = tx->m;
    int before = m->texture_count;
    char why[160];
    int k = model_texture_find(tx, am, aiTextureType_HEIGHT, why, sizeof why, st, err);
    if (k < 0)
        return 0;
    const mesh_texture *t = &m->textures[k];
    double mean[3] = {0, 0, 0};
    size_t n = (size_t)t->width * (size_t)t->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            mean[c] += t->rgba[4 * i + (size_t)c];
    for (int c = 0; c < 3; c++)
        mean[c] /= 255.0 * (double)(n ? n : 1);
    int normals = mean[2] > 0.75 && fabs(mean[0] - 0.5) < 0.15 && fabs(mean[1] - 0.5) < 0.15;
    if (!normals) {
        if (k == before && m->texture_count == before + 1) {
            /* Decoded for this look alone: dropped again. */
            free(m->textures[k].rgba);
            memset(&m->textures[k], 0, sizeof m->textures[k]);
            m->texture_count--;
        }
        return 0;
    }
    s->normal_texture = k;
    double v;
    if (model_material_float(am, "$tex.bumpmult", aiTextureType_HEIGHT, 0, &v))
        s->normal_scale = v;
    return 1;
}

/* Counts in m->unused what the material has that the renderers do not
 * use (bump: a height map was named and not used; dark: the emission is
 * black, so an emissive texture would multiply nothing). */
static void count_unused(const struct aiMaterial *am, int gltf, mesh *m, int bump, int dark)
{
    int has[MESH_UNUSED_COUNT] = {0};
    has[MESH_UNUSED_EMISSIVE_TEXTURE] =
        dark && (aiGetMaterialTextureCount(am, aiTextureType_EMISSIVE) ||
                 aiGetMaterialTextureCount(am, aiTextureType_EMISSION_COLOR));
    has[MESH_UNUSED_OCCLUSION] = aiGetMaterialTextureCount(am, aiTextureType_LIGHTMAP) ||
                                 aiGetMaterialTextureCount(am, aiTextureType_AMBIENT_OCCLUSION);
    double v;
    struct aiColor4D c;
    /* A specular texture (MTL's map_Ks, glTF's specular-glossiness or
     * KHR_materials_specular's), or a specular colour that is not grey:
     * glTF's specular factor and MTL's Ks are read as the coat's strength,
     * which is white. */
    has[MESH_UNUSED_SPECULAR] =
        aiGetMaterialTextureCount(am, aiTextureType_SPECULAR) ||
        (!gltf && aiGetMaterialColor(am, AI_MATKEY_COLOR_SPECULAR, &c) == aiReturn_SUCCESS &&
         (fabsf(c.r - c.g) > 1e-3f || fabsf(c.g - c.b) > 1e-3f));
    has[MESH_UNUSED_CLEARCOAT] = (model_material_float(am, AI_MATKEY_CLEARCOAT_FACTOR, &v) && v > 0) ||
                                 aiGetMaterialTextureCount(am, aiTextureType_CLEARCOAT);
    has[MESH_UNUSED_SHEEN] =
        (aiGetMaterialColor(am, AI_MATKEY_SHEEN_COLOR_FACTOR, &c) == aiReturn_SUCCESS &&
         (c.r > 0 || c.g > 0 || c.b > 0)) ||
        aiGetMaterialTextureCount(am, aiTextureType_SHEEN);
    has[MESH_UNUSED_BUMP] = bump || aiGetMaterialTextureCount(am, aiTextureType_DISPLACEMENT);
    /* Textures of the kinds not named above or read (glTF's
     * metallic-roughness texture also arrives as METALNESS and
     * DIFFUSE_ROUGHNESS). */
    static const enum aiTextureType other[] = {
        aiTextureType_AMBIENT,    aiTextureType_SHININESS,     aiTextureType_OPACITY,
        aiTextureType_REFLECTION, aiTextureType_NORMAL_CAMERA, aiTextureType_TRANSMISSION,
    };
    for (size_t i = 0; i < sizeof other / sizeof other[0]; i++)
        has[MESH_UNUSED_OTHER_TEXTURE] |= aiGetMaterialTextureCount(am, other[i]) > 0;
    for (int k = 0; k < MESH_UNUSED_COUNT; k++)
        m->unused[k] += has[k] != 0;
}

/* The mean and the largest value of channel c over the texture, in [0, 1]. */
static void channel_stats(const mesh_texture *t, int c, double *mean, double *max)
{
    size_t n = (size_t)t->width * (size_t)t->height;
    unsigned long long sum = 0;
    unsigned top = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned v = t->rgba[4 * i + (size_t)c];
        sum += v;
        top = v > top ? v : top;
    }
    *mean = n ? (double)sum / (double)n / 255.0 : 0.0;
    *max = top / 255.0;
}

/* The four weights of a metallic share `metal` and the slot's
 * transmission, as model_materials.c sets them from the factors. */
static void set_weights(mesh_slot *s, double metal)
{
    s->mat.weight[LOBE_METALLIC] = metal;
    s->mat.weight[LOBE_REFRACTIVE] = (1.0 - metal) * s->transmission;
    s->mat.weight[LOBE_DIFFUSE] = (1.0 - metal) * (1.0 - s->transmission);
    s->mat.weight[LOBE_REFLECTING] = 0.0;
}

zt_status model_maps(model_textures *tx, const struct aiMaterial *am, int gltf, mesh_slot *s,
                     zt_error *err)
{
    zt_status st = ZT_OK;
    mesh *m = tx->m;
    double v;
    if (gltf) {
        int k = find_map(tx, am, aiTextureType_UNKNOWN, "metallic-roughness texture", s, &st,
                         err);
        if (k >= 0) {
            s->rough_map = (mesh_map){k, 1};
            s->metal_map = (mesh_map){k, 2};
        }
    } else {
        /* MTL: a map without its factor (Pr, Pm) is the value itself. */
        int k = find_map(tx, am, aiTextureType_DIFFUSE_ROUGHNESS, "roughness map (map_Pr)", s,
                         &st, err);
        if (k >= 0) {
            s->rough_map = (mesh_map){k, 0};
            if (!model_material_float(am, AI_MATKEY_ROUGHNESS_FACTOR, &v))
                s->roughness = 1.0;
        }
        k = st == ZT_OK ? find_map(tx, am, aiTextureType_METALNESS, "metal map (map_Pm)", s, &st,
                                   err)
                        : -1;
        if (k >= 0) {
            s->metal_map = (mesh_map){k, 0};
            if (!model_material_float(am, AI_MATKEY_METALLIC_FACTOR, &v))
                s->metallic = 1.0;
        }
    }
    int k = st == ZT_OK ? find_map(tx, am, aiTextureType_NORMALS, "normal map", s, &st, err) : -1;
    if (k >= 0) {
        s->normal_texture = k;
        /* glTF's normalTexture.scale; MTL's -bm. */
        if (model_material_float(am, "$tex.scale", aiTextureType_NORMALS, 0, &v) ||
            model_material_float(am, "$tex.bumpmult", aiTextureType_NORMALS, 0, &v))
            s->normal_scale = v;
    }
    int bump_unused = 0;
    if (st == ZT_OK && !gltf && k < 0 && aiGetMaterialTextureCount(am, aiTextureType_HEIGHT))
        bump_unused = !bump_as_normal_map(tx, am, s, &st, err);
    /* glTF's emissiveTexture, MTL's map_Ke: a colour (sRGB) times the
     * emission.  Under a black emission (glTF's default emissiveFactor)
     * it multiplies nothing and is not decoded.  Left out, the emission
     * is the factor alone, as before textures were read. */
    int dark = v3_is_black(s->emission);
    if (st == ZT_OK && !dark)
        s->emissive_texture =
            find_map(tx, am, aiTextureType_EMISSIVE, "emissive texture", s, &st, err);
    if (st != ZT_OK)
        return st;
    count_unused(am, gltf, m, bump_unused, dark);
    /* What the renderers take where they do not read the maps. */
    double mean, max;
    if (s->metal_map.texture >= 0) {
        channel_stats(&m->textures[s->metal_map.texture], s->metal_map.channel, &mean, &max);
        set_weights(s, s->metallic * mean);
        if (s->metallic * mean > 0.0 && s->mat.weight[LOBE_REFRACTIVE] <= 0.0)
            s->mat.ior = MODEL_METAL_IOR;
    }
    if (s->rough_map.texture >= 0) {
        channel_stats(&m->textures[s->rough_map.texture], s->rough_map.channel, &mean, &max);
        s->mat.roughness = s->roughness * max;
    }
    return ZT_OK;
}
