/* Triangle meshes of the scene model: what a "mesh" item brings in from a
 * model file, as flat arrays in single precision (no object per triangle),
 * in world space.
 *
 * A mesh is shared between copies of a scene (zt_scene_clone, a renderer's
 * own copy) by reference count: its arrays are never changed while shared.
 * A motion that moves a mesh object first makes the mesh the scene's own
 * (mesh_make_unique), then transforms it.  The renderers point into these
 * arrays (Embree's shared buffers) instead of copying them. */
#ifndef ZT_SCENE_MESH_H
#define ZT_SCENE_MESH_H

#include <stdint.h>

#include "scene/scene.h"

/* A base-colour texture: 8-bit sRGB RGBA texels, row 0 at the top of the
 * image (texture coordinate v = 1 at the top row, v = 0 at the bottom, the
 * convention of Assimp and OBJ; the importer converts). */
typedef struct mesh_texture {
    int width, height;
    unsigned char *rgba;    /* width * height * 4 bytes */
    int wrap;               /* 1 repeat (the default), 0 clamp to the edge */
} mesh_texture;

/* A scalar map of a slot: the value at a hit is `factor` times channel
 * `channel` (0 R, 1 G, 2 B) of texture `texture` read linearly (these are
 * data, not colours); texture -1: none (the value is the factor). */
typedef struct mesh_map {
    int texture;
    int channel;
} mesh_map;

/* What a model's materials may have that the renderers do not use, counted
 * for -v (mesh_unused_name gives the words). */
enum {
    MESH_UNUSED_EMISSIVE_TEXTURE, /* under a black emissive factor */
    MESH_UNUSED_OCCLUSION,
    MESH_UNUSED_SPECULAR,
    MESH_UNUSED_CLEARCOAT,
    MESH_UNUSED_SHEEN,
    MESH_UNUSED_BUMP,
    MESH_UNUSED_OTHER_TEXTURE,
    MESH_UNUSED_COUNT
};

/* "emissive textures", "alpha masks", ... (plural, for "N <name>"). */
const char *mesh_unused_name(int k);

/* One material of a mesh ("slot"): every triangle names one. */
typedef struct mesh_slot {
    material mat;           /* the four-weight material; colour is the base
                               colour factor (a texture multiplies it) */
    vec3 emission;          /* emitted radiance (the emissive factor times the
                               strength); not black: the slot's triangles
                               are area lights (and black otherwise, like
                               every light part) */
    int emissive_texture;   /* emission is times its texel (sRGB), -1: none */
    int texture;            /* base-colour texture (index into textures), -1 */
    double roughness;       /* the file's roughness factor (0 when absent),
                               also mat.roughness */
    double metallic;        /* the metallic factor (mat's metallic weight
                               when there is no metal map) */
    double transmission;    /* the non-metallic part's refractive share */
    mesh_map rough_map;     /* roughness at a hit: roughness x the map */
    mesh_map metal_map;     /* metallic at a hit: metallic x the map */
    int normal_texture;     /* tangent-space normal map, -1 */
    double normal_scale;    /* its x and y scale (glTF's normalTexture.scale) */
    char name[64];          /* the file's material name, for messages */
} mesh_slot;

typedef struct mesh {
    int refs;               /* owners; arrays are read-only while refs > 1 */
    int vertex_count, triangle_count;
    /* 3 floats per vertex, then one float of padding (Embree reads the last
     * vertex with a 16-byte load). */
    float *position;
    float *normal;          /* 3 per vertex, unit; NULL: flat shading */
    float *uv;              /* 2 per vertex; NULL: no texture coordinates */
    float *tangent;         /* 4 per vertex: the direction of growing u
                               (unit), then w = +-1, the bitangent being
                               w (normal x tangent); w = 0: none for that
                               vertex.  NULL unless a slot has a normal map */
    uint32_t *index;        /* 3 per triangle; the front face is counter-
                               clockwise, as for "triangle" parts */
    uint16_t *slot;         /* per triangle; NULL when slot_count == 1 */
    mesh_slot *slots;
    int slot_count;
    mesh_texture *textures;
    int texture_count;
    /* What the import dropped or could not represent (for -v). */
    int skipped_degenerate; /* zero-area or repeated-vertex triangles */
    int replaced_normals;   /* vertex normals not finite or zero in the file,
                               replaced by the faces' normals */
    int rough_slots;        /* slots with a rough (GGX) lobe */
    int missing_textures;   /* textures named but missing or undecodable */
    char texture_problem[160]; /* the first such texture and why */
    int map_fallbacks;      /* normal, roughness, metal or emissive maps left
                               out (missing or undecodable) */
    char map_problem[160];  /* the first such map and why */
    int alpha_fallbacks;    /* alpha cutoffs not in [0, 1], clamped */
    char alpha_problem[160]; /* the first such and what was taken */
    int unused[MESH_UNUSED_COUNT]; /* what the file has that is not used */
    int emissive_pieces;    /* triangles added by cutting emissive ones
                               (emissive_split.h) */
    char file[256];         /* the model file, as the scene names it */
} mesh;

/* A new mesh with room for the arrays (normal, uv, slot allocated when the
 * flags say so; slots and textures left empty), refs = 1.  NULL when out of
 * memory or the counts are negative or too large (more than 2^31 - 1
 * indices). */
mesh *mesh_create(int vertex_count, int triangle_count, int with_normals, int with_uv,
                  int with_slot_per_triangle);

/* Takes one more reference. */
mesh *mesh_retain(mesh *m);

/* Drops a reference; the last frees everything.  NULL is allowed. */
void mesh_release(mesh *m);

/* A deep copy with refs = 1, or NULL when out of memory. */
mesh *mesh_copy(const mesh *m);

/* Makes *m the caller's own (copies it when shared).  0 when out of memory
 * (*m is then unchanged). */
int mesh_make_unique(mesh **m);

/* Applies the affine map p -> a p + t (a row-major 3x3) to the positions,
 * and its inverse transpose to the normals (renormalised).  A mirroring
 * map (det a < 0) also reverses every triangle's winding, so the front face
 * stays the side the normals point to.  The mesh must be unique. */
void mesh_transform(mesh *m, const double a[9], const double t[3]);

/* The cofactor matrix of a (row-major 3x3): the inverse transpose times
 * the determinant, which it returns.  Normals go by it (its sign flips
 * them back when the map mirrors). */
double mesh_cofactors(const double a[9], double c[9]);

/* The box of the positions; lo > hi on every axis for an empty mesh. */
void mesh_bounds(const mesh *m, vec3 *lo, vec3 *hi);

/* The slot of triangle t. */
static inline int mesh_slot_of(const mesh *m, int t)
{
    return m->slot ? m->slot[t] : 0;
}

/* Bytes held by the mesh's arrays and textures. */
uint64_t mesh_memory(const mesh *m);

#endif
