/* Model materials onto the four-weight material (model_materials.h).
 *
 * glTF's metallic-roughness model and OBJ's MTL both reach us through
 * Assimp's material keys.  The mapping keeps what the material model can
 * show: base colour, metal, glass, roughness, emission, and glTF's thin
 * dielectric layer over non-metals (a 4% Fresnel reflection head-on) as
 * the diffuse lobe's clear coat. */
#define _POSIX_C_SOURCE 200809L
#include "scene/model_materials.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <assimp/material.h>
#include <assimp/scene.h>
#include <assimp/texture.h>

#include "scene/gltf_extensions.h"
#include "scene/model_maps.h"
#include "scene/texture_decode.h"
#include "util/error.h"

#define METAL_IOR MODEL_METAL_IOR /* model_maps.h */
#define GLASS_IOR 1.5
/* Model files are untrusted: an external texture larger than this is not
 * read (the decoder has its own limit on the decoded size). */
#define TEXTURE_FILE_MAX (256L << 20)

static double clamp01(double x)
{
    return isfinite(x) ? (x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x) : 0.0;
}

static int get_color(const struct aiMaterial *am, const char *key, unsigned type, unsigned index,
                     vec3 *out)
{
    struct aiColor4D c;
    if (aiGetMaterialColor(am, key, type, index, &c) != aiReturn_SUCCESS)
        return 0;
    if (!isfinite(c.r) || !isfinite(c.g) || !isfinite(c.b))
        return 0;
    *out = v3(c.r, c.g, c.b);
    return 1;
}

/* The model file's folder, with a trailing slash ("" for the current one). */
static void folder_of(const char *path, char *out, size_t n)
{
    const char *slash = strrchr(path, '/');
    size_t len = slash ? (size_t)(slash - path + 1) : 0;
    if (len >= n)
        len = 0;
    memcpy(out, path, len);
    out[len] = '\0';
}

static unsigned char *read_whole(const char *file, size_t *size, char *why, size_t n)
{
    FILE *fp = fopen(file, "rb");
    if (!fp) {
        snprintf(why, n, "cannot be opened");
        return NULL;
    }
    unsigned char *buf = NULL;
    long len = -1;
    if (fseek(fp, 0, SEEK_END) == 0)
        len = ftell(fp);
    if (len < 0 || len > TEXTURE_FILE_MAX || fseek(fp, 0, SEEK_SET) != 0) {
        snprintf(why, n, len > TEXTURE_FILE_MAX ? "larger than 256 MB" : "cannot be read");
        fclose(fp);
        return NULL;
    }
    buf = malloc(len > 0 ? (size_t)len : 1);
    if (!buf || fread(buf, 1, (size_t)len, fp) != (size_t)len) {
        snprintf(why, n, buf ? "cannot be read" : "out of memory");
        free(buf);
        buf = NULL;
    }
    fclose(fp);
    *size = (size_t)len;
    return buf;
}

/* An uncompressed embedded texture: Assimp's texels are BGRA, row 0 at the
 * top. */
static int copy_texels(const struct aiTexture *t, mesh_texture *out, char *why, size_t n)
{
    if (t->mWidth == 0 || t->mHeight == 0 || t->mWidth > TEXTURE_MAX_SIDE ||
        t->mHeight > TEXTURE_MAX_SIDE ||
        (unsigned long long)t->mWidth * t->mHeight > TEXTURE_MAX_TEXELS || !t->pcData) {
        snprintf(why, n, "embedded texture of %ux%u texels is empty or too large", t->mWidth,
                 t->mHeight);
        return 0;
    }
    size_t count = (size_t)t->mWidth * t->mHeight;
    out->rgba = malloc(count * 4);
    if (!out->rgba) {
        snprintf(why, n, "out of memory");
        return 0;
    }
    for (size_t i = 0; i < count; i++) {
        out->rgba[4 * i + 0] = t->pcData[i].r;
        out->rgba[4 * i + 1] = t->pcData[i].g;
        out->rgba[4 * i + 2] = t->pcData[i].b;
        out->rgba[4 * i + 3] = t->pcData[i].a;
    }
    out->width = (int)t->mWidth;
    out->height = (int)t->mHeight;
    out->wrap = 1;
    return 1;
}

/* printf into a buffer, cut to its size: the names and reasons a model
 * file supplies may be longer than a message needs. */
void clip_text(char *to, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(to, n, fmt, ap);
    va_end(ap);
}

/* Decodes the texture the material names ("*N" for the file's embedded
 * texture N, else a file name relative to the model).  Returns 1, or 0 with
 * the reason. */
static int load_texture(const struct aiScene *sc, const char *folder, const char *name,
                        mesh_texture *out, char *why, size_t n)
{
    memset(out, 0, sizeof *out);
    if (name[0] == '*') {
        char *end;
        long k = strtol(name + 1, &end, 10);
        if (*end || k < 0 || (unsigned long)k >= sc->mNumTextures || !sc->mTextures[k]) {
            clip_text(why, n, "names embedded texture %s, which the file does not have", name);
            return 0;
        }
        const struct aiTexture *t = sc->mTextures[k];
        if (t->mHeight != 0)
            return copy_texels(t, out, why, n);
        if (!t->pcData) {
            clip_text(why, n, "embedded texture %s is empty", name);
            return 0;
        }
        return texture_decode((const unsigned char *)t->pcData, t->mWidth, out, why, n);
    }
    char file[4096];
    /* An absolute name is taken as it is; anything else is relative to the
     * model's folder (OBJ and glTF both mean that). */
    if (name[0] == '/')
        snprintf(file, sizeof file, "%s", name);
    else if ((size_t)snprintf(file, sizeof file, "%s%s", folder, name) >= sizeof file) {
        snprintf(why, n, "the texture's file name is too long");
        return 0;
    }
    for (char *c = file; *c; c++)
        if (*c == '\\')
            *c = '/'; /* models written on Windows */
    size_t size = 0;
    char reason[128];
    unsigned char *data = read_whole(file, &size, reason, sizeof reason);
    if (!data) {
        clip_text(why, n, "%s %s", file, reason);
        return 0;
    }
    int ok = texture_decode(data, size, out, reason, sizeof reason);
    free(data);
    if (!ok)
        clip_text(why, n, "%s: %s", file, reason);
    return ok;
}

int model_texture_find(model_textures *tx, const struct aiMaterial *am, enum aiTextureType type,
                       char *why, size_t n, zt_status *st, zt_error *err)
{
    if (aiGetMaterialTextureCount(am, type) == 0)
        return -1;
    struct aiString name;
    enum aiTextureMapMode mode[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
    if (aiGetMaterialTexture(am, type, 0, &name, NULL, NULL, NULL, NULL, mode, NULL) !=
            aiReturn_SUCCESS ||
        name.length == 0)
        return -1;
    mesh *m = tx->m;
    for (int k = 0; k < m->texture_count; k++)
        if (strcmp(tx->names[k], name.data) == 0)
            return k;
    if (m->texture_count >= tx->capacity) {
        clip_text(why, n, "%s: more textures than the file has materials for", name.data);
        return -2;
    }
    mesh_texture tex;
    if (!load_texture(tx->sc, tx->folder, name.data, &tex, why, n)) {
        if (strstr(why, "out of memory"))
            *st = zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory for a texture", tx->path);
        return -2;
    }
    tex.wrap = mode[0] != aiTextureMapMode_Clamp && mode[0] != aiTextureMapMode_Decal;
    int k = m->texture_count++;
    m->textures[k] = tex;
    clip_text(tx->names[k], sizeof tx->names[k], "%s", name.data);
    return k;
}

/* The base-colour texture of a material: glTF's base colour, else the
 * diffuse one (OBJ's map_Kd).  Textures shared by several materials are
 * decoded once.  Returns the texture index or -1. */
static int material_texture(model_textures *tx, const struct aiMaterial *am, zt_status *st,
                            zt_error *err)
{
    enum aiTextureType types[2] = {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE};
    mesh *m = tx->m;
    for (int i = 0; i < 2; i++) {
        char why[sizeof m->texture_problem];
        int k = model_texture_find(tx, am, types[i], why, sizeof why, st, err);
        if (k == -1)
            continue;
        if (k == -2 && *st == ZT_OK && m->missing_textures++ == 0)
            snprintf(m->texture_problem, sizeof m->texture_problem, "%s", why);
        return k < 0 ? -1 : k;
    }
    return -1;
}

/* One material of the file as a slot; strength and specular: glTF's
 * emissiveStrength and specularFactor as read from the file
 * (gltf_extensions.h; 1 for other formats), which Assimp 5.2 does not
 * give. */
static void map_material(const struct aiMaterial *am, int gltf, int obj, double strength,
                         double specular, mesh_slot *s)
{
    memset(s, 0, sizeof *s);
    s->mat.alpha_cutoff = 0.5;
    s->mat.coverage = 1.0;
    struct aiString name;
    if (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS)
        clip_text(s->name, sizeof s->name, "%s", name.data);
    vec3 color = v3(0.8, 0.8, 0.8); /* a material without colour: light grey */
    if (!get_color(am, AI_MATKEY_BASE_COLOR, &color))
        get_color(am, AI_MATKEY_COLOR_DIFFUSE, &color);
    s->mat.color = v3(clamp01(color.x), clamp01(color.y), clamp01(color.z));

    double metallic = 0.0, transmission = 0.0, ior = GLASS_IOR, v;
    int thin = 0;
    if (model_material_float(am, AI_MATKEY_METALLIC_FACTOR, &v))
        metallic = clamp01(v);
    if (model_material_float(am, AI_MATKEY_TRANSMISSION_FACTOR, &v)) {
        transmission = clamp01(v);
        /* glTF: transmission without a volume's thickness is thin-walled. */
        thin = !(model_material_float(am, AI_MATKEY_VOLUME_THICKNESS_FACTOR, &v) && v > 0.0);
    }
    /* MTL's dissolve and IFC's transparency arrive as opacity: see-through
     * surfaces, not refracting solids, so panes (the thing behind is seen
     * undistorted).  glTF's base-colour alpha arrives there too, but means
     * coverage (alpha blending), not glass: ignored. */
    else if (!gltf && model_material_float(am, AI_MATKEY_OPACITY, &v)) {
        transmission = 1.0 - clamp01(v);
        thin = 1;
    }
    if (model_material_float(am, AI_MATKEY_REFRACTI, &v) && v >= 1.0 && v <= 4.0)
        ior = v;
    s->metallic = metallic;
    s->transmission = transmission;
    s->mat.weight[LOBE_METALLIC] = metallic;
    s->mat.weight[LOBE_REFRACTIVE] = (1.0 - metallic) * transmission;
    s->mat.weight[LOBE_DIFFUSE] = (1.0 - metallic) * (1.0 - transmission);
    s->mat.weight[LOBE_REFLECTING] = 0.0;
    /* A pane's light crosses it untinted: the file's colour is its
     * surface's (the diffuse part), as a viewer blends it. */
    s->mat.thin = thin && transmission > 0.0;
    s->mat.tint = v3(1, 1, 1);
    /* One index serves both the metallic lobe's Fresnel term and glass. */
    s->mat.ior = s->mat.weight[LOBE_REFRACTIVE] > 0.0 ? ior : metallic > 0.0 ? METAL_IOR : ior;

    /* glTF: emissiveFactor (Assimp gives glTF's default, black, when there
     * is none) times KHR_materials_emissive_strength. */
    vec3 e = v3(0, 0, 0);
    if (get_color(am, AI_MATKEY_COLOR_EMISSIVE, &e)) {
        double k = strength;
        if (model_material_float(am, AI_MATKEY_EMISSIVE_INTENSITY, &v) && v >= 0.0)
            k = v;
        e = v3(fmax(e.x, 0.0) * k, fmax(e.y, 0.0) * k, fmax(e.z, 0.0) * k);
        if (isfinite(e.x) && isfinite(e.y) && isfinite(e.z))
            s->emission = e;
    }
    /* glTF's roughness factor (default 1: a material that gives none is
     * rough), onto the metallic and refractive lobes (diffuse has none). */
    if (model_material_float(am, AI_MATKEY_ROUGHNESS_FACTOR, &v))
        s->roughness = clamp01(v);
    /* MTL without Pr: the Phong exponent Ns.  Beckmann's alpha for a Phong
     * lobe of exponent n is sqrt(2 / (n + 2)) (Walter et al. 2007), GGX's
     * alpha is taken equal to it, and alpha = roughness^2. */
    else if (obj && model_material_float(am, AI_MATKEY_SHININESS, &v) && v >= 0.0)
        s->roughness = clamp01(pow(2.0 / (v + 2.0), 0.25));
    s->mat.roughness = s->roughness;
    /* glTF's non-metals have a dielectric layer (F0 = 0.04 at the
     * material's roughness) over the base colour: the coat, scaled by
     * KHR_materials_specular's factor (read from the file).  MTL's Ks is
     * a Phong highlight's colour; as Blender's OBJ importer does, its mean
     * is the strength of a dielectric layer whose F0 is 0.08 times it
     * (Principled's "Specular"), so s = 2 mean(Ks): Blender writes Ks 0.5
     * for its default, F0 0.04. */
    vec3 ks;
    if (gltf)
        s->mat.specular = specular;
    else if (obj && get_color(am, AI_MATKEY_COLOR_SPECULAR, &ks))
        s->mat.specular = clamp01(2.0 * (ks.x + ks.y + ks.z) / 3.0);
    s->texture = s->emissive_texture = -1;
    s->rough_map.texture = s->metal_map.texture = s->normal_texture = -1;
    s->normal_scale = 1.0;
}

/* glTF's alphaMode, alphaCutoff and the base colour factor's alpha into
 * the slot's material.  A cutoff that is not a number in [0, 1] is
 * clamped into it (NaN: glTF's default 0.5), counted in m->alpha_fallbacks
 * and named in m->alpha_problem. */
static void map_alpha(const struct aiMaterial *am, mesh *m, mesh_slot *s)
{
    material *mat = &s->mat;
    mat->alpha_mode = ALPHA_OPAQUE;
    mat->alpha_cutoff = 0.5;
    mat->coverage = 1.0;
    struct aiString mode;
    if (aiGetMaterialString(am, "$mat.gltf.alphaMode", 0, 0, &mode) != aiReturn_SUCCESS)
        return;
    if (strcmp(mode.data, "MASK") == 0)
        mat->alpha_mode = ALPHA_MASK;
    else if (strcmp(mode.data, "BLEND") == 0)
        mat->alpha_mode = ALPHA_BLEND;
    else
        return;
    struct aiColor4D c;
    if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &c) == aiReturn_SUCCESS)
        mat->coverage = clamp01(c.a);
    ai_real v;
    unsigned n = 1;
    if (mat->alpha_mode != ALPHA_MASK ||
        aiGetMaterialFloatArray(am, "$mat.gltf.alphaCutoff", 0, 0, &v, &n) != aiReturn_SUCCESS ||
        n < 1)
        return;
    if (v >= 0.0f && v <= 1.0f) {
        mat->alpha_cutoff = v;
        return;
    }
    mat->alpha_cutoff = isnan(v) ? 0.5 : v < 0.0f ? 0.0 : 1.0;
    if (m->alpha_fallbacks++ == 0)
        snprintf(m->alpha_problem, sizeof m->alpha_problem,
                 "material \"%s\": alphaCutoff %g is not in [0, 1], %g taken", s->name,
                 (double)v, mat->alpha_cutoff);
}

static int has_extension(const char *path, const char *a, const char *b)
{
    const char *dot = strrchr(path, '.');
    return dot && (strcasecmp(dot, a) == 0 || (b && strcasecmp(dot, b) == 0));
}

/* A material the file did not state: Assimp's default (a model without
 * materials, an OBJ without its MTL) or any material of a format that has
 * none.  Its slot keeps the default, light grey: Assimp's white for PLY and
 * STL made a model under the white sky nearly invisible (its albedo 1). */
static int invented_material(const struct aiMaterial *am, int no_materials)
{
    struct aiString name;
    return no_materials || (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS &&
                            strcmp(name.data, AI_DEFAULT_MATERIAL_NAME) == 0);
}

zt_status model_materials(const struct aiScene *sc, const char *path,
                          const int *slot_of_material, int slot_count, mesh *m, zt_error *err)
{
    m->slots = calloc((size_t)slot_count, sizeof *m->slots);
    /* At most MODEL_SLOT_TEXTURES textures per slot. */
    size_t capacity = (size_t)slot_count * MODEL_SLOT_TEXTURES;
    m->textures = calloc(capacity, sizeof *m->textures);
    char(*names)[256] = calloc(capacity, sizeof *names);
    if (!m->slots || !m->textures || !names) {
        free(names);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
    }
    m->slot_count = slot_count;
    for (int s = 0; s < slot_count; s++) {
        m->slots[s].mat.weight[LOBE_DIFFUSE] = 1.0;
        m->slots[s].mat.color = v3(0.8, 0.8, 0.8);
        m->slots[s].mat.ior = 1.0;
        m->slots[s].mat.tint = v3(1, 1, 1);
        m->slots[s].texture = m->slots[s].emissive_texture = -1;
        m->slots[s].rough_map.texture = m->slots[s].metal_map.texture = -1;
        m->slots[s].normal_texture = -1;
        m->slots[s].normal_scale = 1.0;
        m->slots[s].mat.alpha_cutoff = 0.5;
        m->slots[s].mat.coverage = 1.0;
    }
    char folder[4096];
    folder_of(path, folder, sizeof folder);
    int gltf = has_extension(path, ".gltf", ".glb"), obj = has_extension(path, ".obj", NULL);
    /* Formats without materials: Assimp invents one (PLY's and STL's
     * white, OFF's 0.6 grey), which is not the file's. */
    int no_materials = has_extension(path, ".ply", ".stl") || has_extension(path, ".off", NULL);
    model_textures tx = {sc, folder, path, m, names, (int)capacity};
    /* Assimp 5.2 drops KHR_materials_emissive_strength: read from the
     * file, by material index (Assimp keeps glTF's order; its default
     * material comes after). */
    double *strength = malloc(2 * ((size_t)sc->mNumMaterials + 1) * sizeof *strength);
    double *specular = strength ? strength + sc->mNumMaterials + 1 : NULL;
    if (!strength) {
        free(names);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
    }
    for (unsigned i = 0; i < sc->mNumMaterials; i++)
        strength[i] = specular[i] = 1.0;
    if (gltf) {
        gltf_emissive_strengths(path, (int)sc->mNumMaterials, strength);
        gltf_specular_factors(path, (int)sc->mNumMaterials, specular);
    }
    zt_status st = ZT_OK;
    for (unsigned i = 0; i < sc->mNumMaterials && st == ZT_OK; i++) {
        int s = slot_of_material[i];
        if (s < 0 || s >= slot_count || !sc->mMaterials[i] ||
            invented_material(sc->mMaterials[i], no_materials))
            continue;
        map_material(sc->mMaterials[i], gltf, obj, strength[i], specular[i], &m->slots[s]);
        if (gltf)
            map_alpha(sc->mMaterials[i], m, &m->slots[s]);
        m->slots[s].texture = material_texture(&tx, sc->mMaterials[i], &st, err);
        if (st == ZT_OK)
            st = model_maps(&tx, sc->mMaterials[i], gltf, &m->slots[s], err);
        const material *mat = &m->slots[s].mat;
        if (mat->roughness > 0.0 &&
            (mat->weight[LOBE_METALLIC] > 0.0 || (mat->weight[LOBE_REFRACTIVE] > 0.0 && !mat->thin)))
            m->rough_slots++;
    }
    free(strength);
    free(names);
    return st;
}
