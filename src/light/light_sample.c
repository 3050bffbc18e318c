#include "light/light_sample.h"

#include "geom/shapes.h"
#include "render/prim.h"
#include "material/bsdf.h"
#include "util/sincos_turn.h"

vec3f light_emitted(const rscene *rs, int prim, const rs_part *p, vec3f y, vec3f d)
{
    const rs_object *o = &rs->objects[p->object];
    if (p->culled && f3_dot(shape_normal(p, y), d) >= 0.0f)
        return f3_splat(0.0f);
    return rs_emission_at(rs, prim, p, o, y);
}

/* Binary search with the halves chosen by conditional moves: u is
 * random, so a branch on it is mispredicted half the time. */
static int pick_light(const rscene *rs, float u)
{
    int lo = 0, hi = rs->light_count - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        int below = u < rs->lights[mid].select_cdf;
        hi = below ? mid : hi;
        lo = below ? lo : mid + 1;
    }
    return lo;
}

/* 1 - cos(theta_max) of the cone a sphere of radius r subtends from
 * distance dc > r, without cancellation for small cones. */
static float cone_one_minus_cos(float r, float dc)
{
    float s2 = (r / dc) * (r / dc);
    if (s2 < 1e-3f)
        return 0.5f * s2 + 0.125f * s2 * s2;
    return 1.0f - sqrtf(f_max0(1.0f - s2));
}

/* Points the sample from x at the light point y; returns the squared
 * distance (0 when y is x). */
static float aim_at(vec3f x, vec3f y, light_sample *out)
{
    vec3f v = f3_sub(y, x);
    float d2 = f3_dot(v, v), d = sqrtf(d2);
    if (d <= 0.0f)
        return 0.0f;
    out->wi = f3_scale(v, 1.0f / d);
    out->dist = d;
    return d2;
}

static int sample_sphere(const rs_part *p, vec3f x, const float u2[2],
                         light_sample *out)
{
    vec3f to_c = f3_sub(p->p0, x);
    float dc = f3_length(to_c);
    if (dc <= p->radius) {
        if (p->culled)
            return 0; /* inside a culled sphere: it is invisible */
        float z = 1.0f - 2.0f * u2[0], r = sqrtf(f_max0(1.0f - z * z));
        float sin_phi, cos_phi;
        sincos_turn(u2[1], &sin_phi, &cos_phi);
        vec3f nrm = f3(r * cos_phi, r * sin_phi, z);
        float d2 = aim_at(x, f3_madd(p->p0, nrm, p->radius), out);
        if (d2 <= 0.0f)
            return 0;
        float c = fabsf(f3_dot(nrm, out->wi));
        if (c <= 0.0f)
            return 0;
        out->pdf = d2 / (p->area * c);
        return 1;
    }
    float omc = cone_one_minus_cos(p->radius, dc);
    float cos_t = 1.0f - u2[0] * omc;
    float sin_t = sqrtf(f_max0(u2[0] * omc * (2.0f - u2[0] * omc)));
    float sin_phi, cos_phi;
    sincos_turn(u2[1], &sin_phi, &cos_phi);
    vec3f w = f3_scale(to_c, 1.0f / dc), t, b;
    f3_basis(w, &t, &b);
    out->wi = f3_normalize(f3_add(f3_scale(w, cos_t),
                                  f3_add(f3_scale(t, sin_t * cos_phi),
                                         f3_scale(b, sin_t * sin_phi))));
    /* Distance to the near side; at the rim the discriminant may round
     * below zero, where the tangent point is the answer. */
    float proj = dc * cos_t;
    float disc = p->radius * p->radius - dc * dc * sin_t * sin_t;
    out->dist = proj - sqrtf(f_max0(disc));
    out->pdf = 1.0f / (2.0f * ZT_PI * omc);
    return out->dist > 0.0f;
}

static int sample_triangle(const rs_part *p, vec3f x, const float u2[2],
                           light_sample *out, float *b1_out, float *b2_out)
{
    float su = sqrtf(u2[0]);
    float b1 = su * (1.0f - u2[1]), b2 = su * u2[1];
    *b1_out = b1;
    *b2_out = b2;
    vec3f y = f3_add(p->p0, f3_add(f3_scale(p->e1, b1), f3_scale(p->e2, b2)));
    float d2 = aim_at(x, y, out);
    if (d2 <= 0.0f)
        return 0;
    float c = f3_dot(p->n, out->wi); /* > 0: x sees the back */
    if (c == 0.0f || (p->culled && c > 0.0f))
        return 0;
    out->pdf = d2 / (p->area * fabsf(c));
    return 1;
}

int light_sample_point(const rscene *rs, vec3f x, float u_select,
                       const float u2[2], light_sample *out)
{
    if (rs->light_count == 0)
        return 0;
    const rs_light *l = &rs->lights[pick_light(rs, u_select)];
    rs_part tmp;
    const rs_part *p = rs_prim(rs, l->part, &tmp);
    const rs_object *o = &rs->objects[p->object];
    out->part = l->part;
    out->delta = 0;
    int ok;
    float b1 = 0.0f, b2 = 0.0f;
    switch (p->shape) {
    case SHAPE_POINT: {
        vec3f v = f3_sub(p->p0, x);
        float d2 = f3_dot(v, v);
        if (d2 <= 0.0f)
            return 0;
        out->dist = sqrtf(d2);
        out->wi = f3_scale(v, 1.0f / out->dist);
        out->li = f3_scale(o->emission, 1.0f / d2);
        out->pdf = p->select_pdf;
        out->delta = 1;
        return 1;
    }
    case SHAPE_SPHERE: ok = sample_sphere(p, x, u2, out); break;
    case SHAPE_TRIANGLE: ok = sample_triangle(p, x, u2, out, &b1, &b2); break;
    default: ok = 0; break;
    }
    if (!ok || !(out->pdf > 0.0f) || !isfinite(out->pdf))
        return 0;
    /* The texel at the point: the choice went by the mean, so the
     * estimate stays unbiased and MIS's densities are unchanged. */
    out->li = o->emissive ? rs_emission_bary(rs, l->part, o, b1, b2) : o->emission;
    out->pdf *= p->select_pdf;
    return 1;
}

float light_pdf(const rs_part *p, vec3f x, vec3f wi, float t)
{
    float sel = p->select_pdf;
    if (!(sel > 0.0f))
        return 0.0f;
    switch (p->shape) {
    case SHAPE_TRIANGLE: {
        float c = fabsf(f3_dot(p->n, wi));
        return c > 0.0f ? sel * t * t / (p->area * c) : 0.0f;
    }
    case SHAPE_SPHERE: {
        float dc = f3_length(f3_sub(p->p0, x));
        if (dc <= p->radius) {
            vec3f y = f3_madd(x, wi, t);
            float c = fabsf(f3_dot(shape_normal(p, y), wi));
            return c > 0.0f ? sel * t * t / (p->area * c) : 0.0f;
        }
        return sel / (2.0f * ZT_PI * cone_one_minus_cos(p->radius, dc));
    }
    default:
        return 0.0f;
    }
}
