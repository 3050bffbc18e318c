/* Mesh triangles seen as parts, and shading normals and albedo at a hit. */
#include "render/prim.h"

#include <math.h>

#include "material/microfacet.h"
#include "material/texture.h"

static float channel(vec3f c, int k)
{
    return k == 0 ? c.x : k == 1 ? c.y : c.z;
}

/* m's material at texture coordinates (u, v) of its maps, into *out: the
 * metallic weight and the rest (diffuse and refractive as the slot's
 * transmission shares them), the GGX alpha, and the flags that follow. */
static void material_at(const rs_object *m, float u, float v, rs_object *out)
{
    const rs_maps *mp = m->maps;
    *out = *m;
    if (mp->metal) {
        float metal = mp->metallic * channel(texture_lookup_linear(mp->metal, u, v),
                                             mp->metal_channel);
        metal = metal > 0.0f ? (metal < 1.0f ? metal : 1.0f) : 0.0f;
        out->weight[LOBE_METALLIC] = metal;
        out->weight[LOBE_REFRACTIVE] = (1.0f - metal) * mp->transmission;
        out->weight[LOBE_DIFFUSE] = (1.0f - metal) * (1.0f - mp->transmission);
        out->weight[LOBE_REFLECTING] = 0.0f;
        int lobes = 0;
        for (int k = 0; k < LOBE_COUNT; k++)
            lobes += out->weight[k] > 0.0f;
        out->coat = (uint8_t)(out->specular > 0.0f && out->weight[LOBE_DIFFUSE] > 0.0f);
        out->lobe_choice = lobes > 1 || out->coat;
    }
    if (mp->rough) {
        float r = mp->roughness * channel(texture_lookup_linear(mp->rough, u, v),
                                          mp->rough_channel);
        out->alpha = r > 0.0f ? r * r : 0.0f;
        if (out->alpha > 0.0f && out->alpha < GGX_ALPHA_MIN)
            out->alpha = GGX_ALPHA_MIN;
    }
    out->rough = (uint8_t)(out->alpha > 0.0f &&
                           (out->weight[LOBE_METALLIC] > 0.0f ||
                            out->weight[LOBE_REFLECTING] > 0.0f ||
                            (out->weight[LOBE_REFRACTIVE] > 0.0f && !out->thin)));
}

void rs_mesh_part(const rscene *rs, const rs_mesh *mm, int prim, rs_part *out)
{
    const uint32_t *v = rs_mesh_tri(mm, prim);
    vec3f p0 = rs_mesh_vertex(mm, v[0]);
    out->shape = SHAPE_TRIANGLE;
    out->object = rs_mesh_object(mm, prim);
    const rs_object *o = &rs->objects[out->object];
    out->is_light = o->is_light;
    out->culled = mm->culled;
    out->background = mm->background;
    out->light = -1;
    out->p0 = p0;
    out->e1 = f3_sub(rs_mesh_vertex(mm, v[1]), p0);
    out->e2 = f3_sub(rs_mesh_vertex(mm, v[2]), p0);
    vec3f c = f3_cross(out->e1, out->e2);
    float len = f3_length(c);
    out->n = len > 0.0f ? f3_scale(c, 1.0f / len) : f3(0.0f, 0.0f, 1.0f);
    out->area = 0.5f * len;
    f3_basis(out->n, &out->tangent, &out->bitangent);
    out->radius = 0.0f;
    out->offset = 0.0f;
    out->select_pdf = 0.0f;
    if (o->is_light && rs->light_power > 0.0f) {
        /* As rscene_build weighs the lights: power = luminance x pi x area
         * x sides. */
        float power = f3_luminance(rs_emission_mean(rs, prim, o)) * out->area *
                      3.14159265358979f * (mm->culled ? 1.0f : 2.0f);
        out->select_pdf = power / rs->light_power;
    }
}

/* m's coverage for a base-texture alpha of a (1 without a texture). */
static float coverage_of(const rs_object *m, float a)
{
    float c = m->coverage * a;
    if (m->alpha_mode == ALPHA_MASK)
        return c >= m->alpha_cutoff ? 1.0f : 0.0f;
    return c > 0.0f ? (c < 1.0f ? c : 1.0f) : 0.0f;
}

float rs_coverage_mean(const rs_object *m, const float *uv0, const float *uv1, const float *uv2,
                       int n)
{
    if (!m->alpha_mode)
        return 1.0f;
    if (!m->texture || !uv0)
        return coverage_of(m, 1.0f);
    float sum = 0.0f;
    int count = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; i + j < n; j++) {
            float b1 = (i + 1.0f / 3.0f) / n, b2 = (j + 1.0f / 3.0f) / n, b0 = 1.0f - b1 - b2;
            sum += coverage_of(m, texture_lookup_alpha(m->texture,
                                                       b0 * uv0[0] + b1 * uv1[0] + b2 * uv2[0],
                                                       b0 * uv0[1] + b1 * uv1[1] + b2 * uv2[1]));
            count++;
        }
    return count ? sum / (float)count : 1.0f;
}

float rs_coverage_at(const rscene *rs, int prim, const rs_part *p, const rs_object *m, vec3f x)
{
    float a = 1.0f;
    if (m->texture && prim >= rs->part_count) {
        const rs_mesh *mm = rs_mesh_of(rs, prim);
        const uint32_t *v = rs_mesh_tri(mm, prim);
        float b1, b2;
        rs_triangle_barycentric(p, x, &b1, &b2);
        float b0 = 1.0f - b1 - b2;
        const float *t0 = mm->m->uv + 2 * (size_t)v[0], *t1 = mm->m->uv + 2 * (size_t)v[1];
        const float *t2 = mm->m->uv + 2 * (size_t)v[2];
        a = texture_lookup_alpha(m->texture, b0 * t0[0] + b1 * t1[0] + b2 * t2[0],
                                 b0 * t0[1] + b1 * t1[1] + b2 * t2[1]);
    }
    return coverage_of(m, a);
}

vec3f rs_emission_bary(const rscene *rs, int prim, const rs_object *o, float b1, float b2)
{
    if (!o->emissive || prim < rs->part_count)
        return o->emission;
    const rs_mesh *mm = rs_mesh_of(rs, prim);
    const uint32_t *v = rs_mesh_tri(mm, prim);
    const float *uv = mm->m->uv;
    float b0 = 1.0f - b1 - b2;
    float u = b0 * uv[2 * v[0]] + b1 * uv[2 * v[1]] + b2 * uv[2 * v[2]];
    float w = b0 * uv[2 * v[0] + 1] + b1 * uv[2 * v[1] + 1] + b2 * uv[2 * v[2] + 1];
    return f3_mul(o->emission, texture_lookup(o->emissive, u, w));
}

vec3f rs_emission_triangle_mean(const rs_object *o, const mesh *m, int t)
{
    const uint32_t *v = m->index + 3 * (size_t)t;
    const float *uv[3] = {m->uv + 2 * (size_t)v[0], m->uv + 2 * (size_t)v[1],
                          m->uv + 2 * (size_t)v[2]};
    const mesh_texture *tex = o->emissive;
    /* The longest side in texels: a step between texels is then crossed
     * by about 4 points, which puts the mean of a texture with sharp
     * edges within a few parts in a thousand. */
    double span = 0.0;
    for (int k = 0; k < 3; k++) {
        const float *a = uv[k], *b = uv[(k + 1) % 3];
        double du = fabs((double)b[0] - a[0]) * tex->width;
        double dv = fabs((double)b[1] - a[1]) * tex->height;
        span = fmax(span, fmax(du, dv));
    }
    int n = isfinite(span) ? (int)fmin(64.0, ceil(4.0 * span)) : 64;
    n = n < 2 ? 2 : n;
    vec3f sum = f3_splat(0.0f);
    /* The centroids of the n^2 triangles: (i + 1/3, j + 1/3) / n for the
     * ones pointing as the whole does, (i + 2/3, j + 2/3) / n for the
     * others. */
    for (int i = 0; i < n; i++)
        for (int j = 0; i + j < n; j++)
            for (int up = 0; up < 2 && (up == 0 || i + j < n - 1); up++) {
                float off = up ? 2.0f / 3.0f : 1.0f / 3.0f;
                float b1 = (i + off) / n, b2 = (j + off) / n, b0 = 1.0f - b1 - b2;
                sum = f3_add(sum, texture_lookup(tex, b0 * uv[0][0] + b1 * uv[1][0] + b2 * uv[2][0],
                                                 b0 * uv[0][1] + b1 * uv[1][1] + b2 * uv[2][1]));
            }
    return f3_mul(o->emission, f3_scale(sum, 1.0f / ((float)n * (float)n)));
}

float rs_maps_diffuse_mean(const rs_object *m, const float *uv0, const float *uv1,
                           const float *uv2, int n)
{
    float sum = 0.0f;
    int count = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; i + j < n; j++) {
            float b1 = (i + 1.0f / 3.0f) / n, b2 = (j + 1.0f / 3.0f) / n, b0 = 1.0f - b1 - b2;
            rs_object at;
            material_at(m, b0 * uv0[0] + b1 * uv1[0] + b2 * uv2[0],
                        b0 * uv0[1] + b1 * uv1[1] + b2 * uv2[1], &at);
            sum += at.weight[LOBE_DIFFUSE];
            count++;
        }
    return count ? sum / (float)count : m->weight[LOBE_DIFFUSE];
}

/* The tangent at barycentric (b0, b1, b2) of the triangle with vertices v
 * (not unit) and the bitangent's side: from the mesh's vertex tangents,
 * else from the triangle's texture coordinates (the direction of growing
 * u, the side that of growing v).  0 when there is none. */
static int tangent_at(const rs_mesh *mm, const rs_part *p, const uint32_t *v, float b0, float b1,
                      float b2, vec3f n, vec3f *t, float *side)
{
    const float *tg = mm->m->tangent;
    if (tg) {
        const float *t0 = tg + 4 * (size_t)v[0], *t1 = tg + 4 * (size_t)v[1];
        const float *t2 = tg + 4 * (size_t)v[2];
        if (t0[3] != 0.0f && t1[3] != 0.0f && t2[3] != 0.0f) {
            *t = f3_add(f3_add(f3_scale(f3(t0[0], t0[1], t0[2]), b0),
                               f3_scale(f3(t1[0], t1[1], t1[2]), b1)),
                        f3_scale(f3(t2[0], t2[1], t2[2]), b2));
            *side = t0[3] + t1[3] + t2[3] < 0.0f ? -1.0f : 1.0f;
            return 1;
        }
    }
    const float *uv = mm->m->uv;
    const float *w0 = uv + 2 * (size_t)v[0], *w1 = uv + 2 * (size_t)v[1];
    const float *w2 = uv + 2 * (size_t)v[2];
    float du1 = w1[0] - w0[0], dv1 = w1[1] - w0[1], du2 = w2[0] - w0[0], dv2 = w2[1] - w0[1];
    float det = du1 * dv2 - du2 * dv1;
    if (!(det != 0.0f) || !isfinite(det))
        return 0;
    float r = 1.0f / det;
    *t = f3_scale(f3_sub(f3_scale(p->e1, dv2), f3_scale(p->e2, dv1)), r);
    vec3f bt = f3_scale(f3_sub(f3_scale(p->e2, du1), f3_scale(p->e1, du2)), r);
    *side = f3_dot(f3_cross(n, *t), bt) < 0.0f ? -1.0f : 1.0f;
    return 1;
}

/* ns (unit, facing the ray; back: seen from behind the front face) bent
 * by the tangent-space normal map at the hit: n' = normalize(x s t + y s b
 * + z n), (x, y, z) the texel times 2 minus 1, s the map's scale, t the
 * tangent made orthogonal to the front normal n, b = side (n x t), as glTF
 * defines it.  ns itself where the frame or the texel gives no direction. */
static vec3f normal_mapped(const rs_mesh *mm, const rs_part *p, const uint32_t *v, float b0,
                           float b1, float b2, const rs_maps *mp, vec3f ns, int back)
{
    vec3f n = back ? f3_neg(ns) : ns;
    vec3f t;
    float side;
    if (!tangent_at(mm, p, v, b0, b1, b2, n, &t, &side))
        return ns;
    t = f3_sub(t, f3_scale(n, f3_dot(n, t)));
    float tl = f3_length(t);
    if (!(tl > 0.0f) || !isfinite(tl))
        return ns;
    t = f3_scale(t, 1.0f / tl);
    vec3f b = f3_scale(f3_cross(n, t), side);
    const float *uv = mm->m->uv;
    float u = b0 * uv[2 * v[0]] + b1 * uv[2 * v[1]] + b2 * uv[2 * v[2]];
    float w = b0 * uv[2 * v[0] + 1] + b1 * uv[2 * v[1] + 1] + b2 * uv[2 * v[2] + 1];
    vec3f c = texture_lookup_linear(mp->normal, u, w);
    float x = (2.0f * c.x - 1.0f) * mp->normal_scale, y = (2.0f * c.y - 1.0f) * mp->normal_scale;
    float z = 2.0f * c.z - 1.0f;
    vec3f d = f3_add(f3_add(f3_scale(t, x), f3_scale(b, y)), f3_scale(n, z));
    float len = f3_length(d);
    if (!(len > 0.0f) || !isfinite(len))
        return ns;
    d = f3_scale(d, 1.0f / len);
    return back ? f3_neg(d) : d;
}

void rs_shade_at(const rscene *rs, int prim, const rs_part *p, const rs_object *m, vec3f x,
                 vec3f n_facing, rs_shade *out)
{
    out->ns = n_facing;
    out->albedo = m->color;
    out->m = NULL;
    if (prim < rs->part_count)
        return;
    const rs_mesh *mm = rs_mesh_of(rs, prim);
    const uint32_t *v = rs_mesh_tri(mm, prim);
    float b1, b2;
    rs_triangle_barycentric(p, x, &b1, &b2);
    float b0 = 1.0f - b1 - b2;
    if ((m->texture || m->maps) && mm->m->uv) {
        const float *t0 = mm->m->uv + 2 * (size_t)v[0], *t1 = mm->m->uv + 2 * (size_t)v[1];
        const float *t2 = mm->m->uv + 2 * (size_t)v[2];
        float u = b0 * t0[0] + b1 * t1[0] + b2 * t2[0];
        float w = b0 * t0[1] + b1 * t1[1] + b2 * t2[1];
        if (m->texture)
            out->albedo = f3_mul(m->color, texture_lookup(m->texture, u, w));
        if (m->maps) {
            material_at(m, u, w, &out->mat);
            out->mat.color = out->albedo;
            out->m = &out->mat;
        }
    }
    int mapped = m->maps && m->maps->normal && mm->m->uv;
    if (!mm->smooth && !mapped)
        return;
    /* Seen from behind, the front face's normals turn with the geometric
     * normal. */
    int back = f3_dot(p->n, n_facing) < 0.0f;
    vec3f ns = n_facing;
    if (mm->smooth) {
        const float *nrm = mm->m->normal;
        vec3f n0 = f3(nrm[3 * v[0]], nrm[3 * v[0] + 1], nrm[3 * v[0] + 2]);
        vec3f n1 = f3(nrm[3 * v[1]], nrm[3 * v[1] + 1], nrm[3 * v[1] + 2]);
        vec3f n2 = f3(nrm[3 * v[2]], nrm[3 * v[2] + 1], nrm[3 * v[2] + 2]);
        vec3f ni = f3_add(f3_add(f3_scale(n0, b0), f3_scale(n1, b1)), f3_scale(n2, b2));
        if (back)
            ni = f3_neg(ni);
        float len = f3_length(ni);
        if (len > 0.0f)
            ns = f3_scale(ni, 1.0f / len);
        else if (!mapped)
            return;
    }
    if (mapped)
        ns = normal_mapped(mm, p, v, b0, b1, b2, m->maps, ns, back);
    /* A normal bent to or beyond the geometric horizon (a coarse mesh's
     * silhouette, a steep normal map) is lifted to a small angle above
     * it. */
    float c = f3_dot(ns, n_facing);
    const float min_c = 0.01f;
    if (c < min_c) {
        vec3f tang = f3_sub(ns, f3_scale(n_facing, c));
        float tl = f3_length(tang);
        if (tl > 0.0f) {
            float s = sqrtf(1.0f - min_c * min_c);
            ns = f3_add(f3_scale(tang, s / tl), f3_scale(n_facing, min_c));
        } else {
            ns = n_facing;
        }
    }
    out->ns = ns;
}
