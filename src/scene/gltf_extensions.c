/* glTF extensions read from the file itself (gltf_extensions.h). */
#include "scene/gltf_extensions.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "util/error.h"
#include "util/read_file.h"

/* Model files are untrusted: the JSON of one larger than this is not
 * read again (Assimp has its own limits). */
#define GLTF_FILE_MAX (512u << 20)

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The JSON text of a .gltf (the whole file) or a .glb (its first chunk,
 * which the format requires to be the JSON one). */
static json_t *parse(const char *text, size_t length)
{
    const unsigned char *b = (const unsigned char *)text;
    if (length >= 20 && memcmp(b, "glTF", 4) == 0) {
        uint32_t chunk = le32(b + 12);
        if (le32(b + 16) != 0x4E4F534Au || chunk > length - 20)
            return NULL;
        return json_loadb(text + 20, chunk, 0, NULL);
    }
    return json_loadb(text, length, 0, NULL);
}

/* The number `key` of extension `ext` of each of the first `count`
 * materials into out[] where `ok` accepts it (out[] keeps what it had
 * elsewhere). */
static void material_numbers(const char *path, int count, const char *ext, const char *key,
                             int (*ok)(double *), double *out)
{
    char *text = NULL;
    size_t length = 0;
    zt_error err;
    zt_error_clear(&err);
    if (read_text_file(path, "model file", GLTF_FILE_MAX, &text, &length, &err) != ZT_OK)
        return;
    json_t *root = parse(text, length);
    free(text);
    json_t *materials = json_object_get(root, "materials");
    for (int i = 0; i < count && (size_t)i < json_array_size(materials); i++) {
        json_t *e = json_object_get(json_object_get(json_array_get(materials, (size_t)i),
                                                    "extensions"),
                                    ext);
        json_t *v = json_object_get(e, key);
        double x = json_is_number(v) ? json_number_value(v) : NAN;
        if (json_is_number(v) && ok(&x))
            out[i] = x;
    }
    json_decref(root);
}

static int strength_ok(double *x)
{
    return isfinite(*x) && *x >= 0.0;
}

static int factor_ok(double *x)
{
    if (!isfinite(*x))
        return 0;
    *x = *x < 0.0 ? 0.0 : *x > 1.0 ? 1.0 : *x;
    return 1;
}

void gltf_emissive_strengths(const char *path, int count, double *strength)
{
    for (int i = 0; i < count; i++)
        strength[i] = 1.0;
    material_numbers(path, count, "KHR_materials_emissive_strength", "emissiveStrength",
                     strength_ok, strength);
}

void gltf_specular_factors(const char *path, int count, double *factor)
{
    for (int i = 0; i < count; i++)
        factor[i] = 1.0;
    material_numbers(path, count, "KHR_materials_specular", "specularFactor", factor_ok, factor);
}
