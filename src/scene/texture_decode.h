/* Texture images (PNG and JPEG) from memory into 8-bit RGBA, for the
 * textures of model files.  Images are untrusted: a corrupt one is an
 * error, never a crash. */
#ifndef ZT_SCENE_TEXTURE_DECODE_H
#define ZT_SCENE_TEXTURE_DECODE_H

#include <stddef.h>

#include "scene/mesh.h"

/* The largest texture accepted: per side, and in all. */
#define TEXTURE_MAX_SIDE 16384
#define TEXTURE_MAX_TEXELS (1 << 28)

/* Decodes a PNG or JPEG (told apart by their signatures) into *out (its
 * rgba the caller's; wrap set to repeat).  Returns 1, or 0 with a short
 * reason in why (room for `why_size`): not an image, corrupt, too large,
 * out of memory. */
int texture_decode(const unsigned char *data, size_t size, mesh_texture *out, char *why,
                   size_t why_size);

#endif
