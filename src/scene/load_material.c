/* Materials: the four lobe weights, the albedo, the refractive index,
 * the roughness of the non-diffuse lobes, the clear coat over the diffuse
 * one, whether the refractive lobe is
 * a thin pane, and the coverage. */
#include "scene/scene_reader.h"

#include <math.h>

#include "scene/load_values.h"

/* The weights are a probability distribution over the lobes. */
#define WEIGHT_SUM_TOLERANCE 1e-6

static const char *const lobe_names[LOBE_COUNT] = {
    "diffuse", "metallic", "reflecting", "refractive"
};

static zt_status load_character(load_ctx *ctx, jref ref, double *weight)
{
    static const char *const keys[] = {
        "diffuse", "metallic", "reflecting", "refractive", NULL
    };
    if (load_object(ctx, ref, "character") ||
        load_known_keys(ctx, ref, "character", keys))
        return ZT_ERR_PARSE;
    double sum = 0;
    for (int i = 0; i < LOBE_COUNT; i++) {
        jref w = jref_member(ref.value, lobe_names[i]);
        if (load_require(ctx, ref, lobe_names[i], "character") ||
            load_number(ctx, w, &weight[i]))
            return ZT_ERR_PARSE;
        if (weight[i] < 0 || weight[i] > 1)
            return load_fail(ctx, w, "weight out of range: %s %g is not in [0, 1]",
                             lobe_names[i], weight[i]);
        sum += weight[i];
    }
    if (fabs(sum - 1) > WEIGHT_SUM_TOLERANCE)
        return load_fail(ctx, ref, "weights must sum to 1, not %g", sum);
    return ZT_OK;
}

/* The optional member `key` of ref, a number in [0, 1], into *out (left
 * as it is when absent); *present says whether it was there. */
static zt_status load_unit_member(load_ctx *ctx, jref ref, const char *key, double *out,
                                  jref *present)
{
    *present = jref_member(ref.value, key);
    if (!present->value)
        return ZT_OK;
    if (load_number(ctx, *present, out))
        return ZT_ERR_PARSE;
    if (!(*out >= 0 && *out <= 1))
        return load_fail(ctx, *present, "%s must be in [0, 1], not %g", key, *out);
    return ZT_OK;
}

zt_status load_material(load_ctx *ctx, jref ref, material *out)
{
    static const char *const keys[] = {
        "character", "color", "coverage", "refractiveindex", "roughness", "specular", "thin",
        NULL
    };
    material m = material_default();
    if (load_object(ctx, ref, "material") ||
        load_known_keys(ctx, ref, "material", keys) ||
        load_require(ctx, ref, "character", "material") ||
        load_require(ctx, ref, "color", "material") ||
        load_character(ctx, jref_member(ref.value, "character"), m.weight) ||
        load_albedo(ctx, jref_member(ref.value, "color"), &m.color))
        return ZT_ERR_PARSE;
    jref ior = jref_member(ref.value, "refractiveindex");
    if (ior.value) {
        if (load_number(ctx, ior, &m.ior))
            return ZT_ERR_PARSE;
        if (m.ior <= 0)
            return load_fail(ctx, ior, "refractiveindex must be positive, not %g",
                             m.ior);
    }
    jref rough, spec, cover;
    if (load_unit_member(ctx, ref, "roughness", &m.roughness, &rough))
        return ZT_ERR_PARSE;
    /* A clear coat over the diffuse lobe (glTF's dielectric layer over
     * non-metals at 1): its Fresnel's scale. */
    if (load_unit_member(ctx, ref, "specular", &m.specular, &spec))
        return ZT_ERR_PARSE;
    if (m.specular > 0 && m.weight[LOBE_DIFFUSE] <= 0)
        return load_fail(ctx, spec,
                         "specular is a coat over the diffuse lobe, but its weight is 0");
    jref thin = jref_member(ref.value, "thin");
    if (thin.value) {
        if (load_bool(ctx, thin, &m.thin))
            return ZT_ERR_PARSE;
        if (m.thin && m.weight[LOBE_REFRACTIVE] <= 0)
            return load_fail(ctx, thin,
                             "thin makes the refractive lobe a pane, but its weight is 0");
    }
    /* Coverage below 1: the surface is that share of itself, the rest
     * lets light through untouched (as a model's alphaMode BLEND). */
    if (load_unit_member(ctx, ref, "coverage", &m.coverage, &cover))
        return ZT_ERR_PARSE;
    if (cover.value)
        m.alpha_mode = m.coverage < 1 ? ALPHA_BLEND : ALPHA_OPAQUE;
    /* A hand-written pane is tinted by the material's colour, as the
     * smooth refractive lobe is. */
    m.tint = m.color;
    *out = m;
    return ZT_OK;
}
