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
#include <string.h>

#include <assimp/scene.h>

#include "util/error.h"

static int get_float(const struct aiMaterial *am, const char *key, unsigned type, unsigned index,
                     double *out)
{
    ai_real v;
    unsigned n = 1;
    if (aiGetMaterialFloatArray(am, key, type, index, &v, &n) != aiReturn_SUCCESS || n < 1 ||
        !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

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
    if (k < 0)
        return -1;
    /* A map is drawn over the base texture's texels: one of another size
     * is taken for a file that does not belong (docs/scene-format.md). */
    const mesh_texture *t = &tx->m->textures[k];
    if (s->texture >= 0) {
        const mesh_texture *b = &tx->m->textures[s->texture];
        if (t->width != b->width || t->height != b->height) {
            char size[96];
            snprintf(size, sizeof size, "is %dx%d, the base texture %dx%d", t->width, t->height,
                     b->width, b->height);
            fallback(tx->m, s, what, size);
            return -1;
        }
    }
    return k;
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
            if (!get_float(am, AI_MATKEY_ROUGHNESS_FACTOR, &v))
                s->roughness = 1.0;
        }
        k = st == ZT_OK ? find_map(tx, am, aiTextureType_METALNESS, "metal map (map_Pm)", s, &st,
                                   err)
                        : -1;
        if (k >= 0) {
            s->metal_map = (mesh_map){k, 0};
            if (!get_float(am, AI_MATKEY_METALLIC_FACTOR, &v))
                s->metallic = 1.0;
        }
    }
    int k = st == ZT_OK ? find_map(tx, am, aiTextureType_NORMALS, "normal map", s, &st, err) : -1;
    if (k >= 0) {
        s->normal_texture = k;
        /* glTF's normalTexture.scale; MTL's -bm. */
        if (get_float(am, "$tex.scale", aiTextureType_NORMALS, 0, &v) ||
            get_float(am, "$tex.bumpmult", aiTextureType_NORMALS, 0, &v))
            s->normal_scale = v;
    }
    if (st != ZT_OK)
        return st;
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
