/* Textures as the renderers read them: bilinear between texel
 * centres, in linear light (texels are stored as 8-bit sRGB). */
#ifndef ZT_MATERIAL_TEXTURE_H
#define ZT_MATERIAL_TEXTURE_H

#include "scene/mesh.h"
#include "util/vec3f.h"

/* The linear value of each 8-bit sRGB code. */
extern const float texture_srgb_to_linear[256];

/* The texture's linear RGB at texture coordinates (u, v): v = 1 is the top
 * row of the image.  Texel (i, j) (column i, row j from the top) has its
 * centre at u = (i + 0.5) / width, v = 1 - (j + 0.5) / height; between
 * centres the value is bilinear, beyond the outermost centres it repeats
 * the texture (wrap) or holds the edge texels (clamp).  Non-finite
 * coordinates read texel (0, 0). */
vec3f texture_lookup(const mesh_texture *t, float u, float v);

/* The same for a texture of data (roughness, metalness, normals): the
 * texels' codes c read as c / 255, without the sRGB curve. */
vec3f texture_lookup_linear(const mesh_texture *t, float u, float v);

/* The texture's alpha (coverage, linear: c / 255) at (u, v), filtered
 * as texture_lookup filters colours. */
float texture_lookup_alpha(const mesh_texture *t, float u, float v);

/* The mean linear colour of the texture over the triangle of texture
 * coordinates uv0, uv1, uv2 (2 floats each), estimated on a fixed lattice
 * of n (n + 1) / 2 points (n >= 1); for a per-triangle albedo. */
vec3f texture_triangle_mean(const mesh_texture *t, const float *uv0, const float *uv1,
                            const float *uv2, int n);

#endif
