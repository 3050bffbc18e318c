/* The estimator, vertex by vertex:
 *   L += beta * Le * w_bsdf                      (emitter reached by a ray)
 *   L += beta * f * cos * Li / p_light * w_light (next-event estimation)
 *   beta *= f * cos / p_bsdf                     (continue the path)
 * with w the power-heuristic MIS weights, and levels counted as the number
 * of scattering events before the light reaches the eye.  Light from far
 * away (sun, environment map) is a second light of the same form: one more
 * next-event sample (distant.h's mixture) and its own MIS weight on the rays
 * that escape. */
#include "path/path_tracer.h"

#include <float.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "geom/transmittance.h"
#include "light/distant.h"
#include "light/mis.h"
#include "light/light_sample.h"
#include "material/bsdf.h"
#include "render/prim.h"
#include "util/sampler.h"

#define MEDIUM_STACK 8
/* Panes one path segment may cross (a stuck ray cannot loop). */
#define PANES_MAX 32
#define RR_START 3
/* Sampler dimension pairs: 0 is the pixel position; each scattering vertex
 * uses PAIRS_PER_VERTEX after it (light point, BSDF direction). */
#define PAIRS_PER_VERTEX 2
/* Vertices after the first carry less of the image and use the plain
 * stream: stratifying them measurably costs more than it gains. */
#define STRATIFIED_VERTICES 1
/* The first vertex's direction toward light from far away: the last pair,
 * so that the pairs before it keep their seeds. */
#define DISTANT_PAIR (1 + STRATIFIED_VERTICES * PAIRS_PER_VERTEX)
_Static_assert(DISTANT_PAIR + 1 == PATH_SEEDED_PAIRS,
               "the pixel holds the seed of every stratified pair");

/* The refractive objects the path is inside, innermost last: deciding
 * entering/leaving by object identity makes shells of two surfaces work. */
typedef struct media {
    int obj[MEDIUM_STACK];
    int n;
} media;

static float medium_ior(const rscene *rs, const media *m, int depth_from_top)
{
    int i = m->n - 1 - depth_from_top;
    return i >= 0 ? rs->objects[m->obj[i]].ior : 1.0f;
}

/* A rough lobe's share of next-event estimation toward wi: the sum over
 * the lobes of colour x weight x f x |cos| x MIS weight / p_light.  n is the
 * geometric normal on wo's side; a shading normal that puts wi on the
 * other side of it than the surface does gives nothing (light would leak). */
static vec3f nee_rough(const rs_object *m, const shading_frame *frame, vec3f n, vec3f wo,
                       vec3f wi, float eta_i, float eta_t, float p_light, int light_delta)
{
    if ((f3_dot(n, wi) > 0.0f) != (f3_dot(frame->n, wi) > 0.0f))
        return f3_splat(0.0f);
    float fcos[LOBE_COUNT], pdf[LOBE_COUNT], sum = 0.0f, metal = 0.0f, coat = 0.0f;
    bsdf_eval_rough(m, frame, wo, wi, eta_i, eta_t, fcos, pdf);
    for (int k = 0; k < LOBE_COUNT; k++)
        if (fcos[k] > 0.0f) {
            float v = fcos[k] * (light_delta ? 1.0f / p_light : power_heuristic_over(p_light, pdf[k]));
            if (k == LOBE_METALLIC)
                metal = v;
            else if (k == LOBE_DIFFUSE) /* the coat: white */
                coat = v;
            else
                sum += v;
        }
    if (metal == 0.0f)
        return f3_add(f3_scale(m->color, sum), f3_splat(coat));
    vec3f tint = bsdf_metal_tint(m, m->color, f3_dot(frame->n, wo));
    return f3_add(f3_mul(m->color, f3_add(f3_splat(sum), f3_scale(tint, metal))), f3_splat(coat));
}

path_pixel path_pixel_make(uint32_t key)
{
    path_pixel px = {key, {0}};
    for (uint32_t p = 0; p < PATH_SEEDED_PAIRS; p++)
        px.pair_seed[p] = sampler_pair_seed(key, p);
    return px;
}

/* The loop, with `plain` a constant in each of its two copies: in a plain
 * scene (rscene.plain) the branches for what it lacks fold away. */
#define HAS(feature) (!plain && (feature))

__attribute__((always_inline))
static inline vec3f trace(const rscene *rs, const path_params *pp, vec3f o, vec3f d,
                          const path_pixel *px, uint32_t index, uint32_t rev_index,
                          uint64_t *rays, const int plain)
{
    vec3f radiance = f3_splat(0.0f), beta = f3_splat(1.0f);
    int k = 0;                /* scattering events so far */
    int prev_delta = 1;       /* the camera counts as a delta vertex */
    float prev_pdf = 0.0f;
    vec3f prev_x = o;
    float seg_t = 0.0f;       /* distance from prev_x to o, across panes */
    int panes = 0;
    media med;
    med.n = 0; /* obj[] is read only below n */
    sampler_stream rng = sampler_stream_start(px->key, index);
    /* Counted in a register, not through the pointer at every ray. */
    uint64_t n_rays = 0;

    for (;;) {
        hit h = accel_intersect(rs, o, d);
        n_rays++;
        int counted = k >= pp->min_level;
        if (h.part < 0) {
            if (counted) {
                vec3f le = rs->sky;
                if (__builtin_expect(HAS(rs->distant.any), 0)) {
                    float far_pdf;
                    vec3f ld = distant_eval(&rs->distant, d, &far_pdf);
                    if (!prev_delta && !f3_is_black(ld))
                        ld = f3_scale(ld, power_heuristic(prev_pdf, far_pdf));
                    le = f3_add(le, ld);
                }
                radiance = f3_add(radiance, f3_mul(beta, le));
            }
            break;
        }
        rs_part tri;
        const rs_part *p = rs_prim(rs, h.part, &tri);
        vec3f x = shape_hit_point(p, o, d, h.t);
        if (p->is_light) {
            if (counted) {
                vec3f le = light_emitted(rs, h.part, p, x, d);
                float w = 1.0f;
                if (!prev_delta && p->select_pdf > 0.0f)
                    w = power_heuristic(prev_pdf, light_pdf(p, prev_x, d, seg_t + h.t));
                radiance = f3_add(radiance, f3_scale(f3_mul(beta, le), w));
            }
            break; /* lights absorb what reaches them */
        }
        const rs_object *m = &rs->objects[p->object];
        /* A pane passes the light it does not reflect undeviated: not a
         * scattering event (the level, the MIS state and the segment's
         * start stay), chosen with its probability so the weight is the
         * tint.  Otherwise the vertex is the rest of the material, its
         * weights renormalised, the pane's lobe reflecting only. */
        /* A surface of coverage cov < 1 (alpha) passes the uncovered share
         * the same way, untinted: passing has probability 1 - cov plus
         * cov times the pane's, and the covered share that does not pass
         * is the material as it is (the pane's lobe reflecting only). */
        float pane_keep = 1.0f, pane_r = 0.0f;
        if (__builtin_expect(HAS(rs_passes(m)), 0)) {
            vec3f ng = shape_normal(p, x);
            float c = f3_dot(ng, d);
            float cov = rs_coverage(rs, h.part, p, m, x), p_pane = 0.0f;
            if (m->thin) {
                pane_r = bsdf_pane_reflectance(fabsf(c), m->ior);
                p_pane = m->weight[LOBE_REFRACTIVE] * (1.0f - pane_r);
            }
            float p_pass = cov < 1.0f ? (1.0f - cov) + cov * p_pane : p_pane;
            if (sampler_next(&rng) < p_pass) {
                vec3f w = m->tint;
                if (cov < 1.0f)
                    w = f3_scale(f3_add(f3_splat(1.0f - cov), f3_scale(m->tint, cov * p_pane)),
                                 1.0f / p_pass);
                beta = f3_mul(beta, w);
                if (f3_is_black(beta) || ++panes > PANES_MAX)
                    break;
                o = ray_offset(x, c > 0.0f ? ng : f3_neg(ng));
                seg_t += h.t;
                continue;
            }
            pane_keep = 1.0f - p_pane;
        }
        if (k >= pp->max_level)
            break;
        k++;

        vec3f ng = shape_normal(p, x);
        vec3f n = f3_dot(ng, d) < 0.0f ? ng : f3_neg(ng);
        vec3f wo = f3_neg(d);
        /* Meshes: the shading normal ns (the geometric n still decides
         * sides) and a textured albedo, in a copy of the material (with
         * maps, the material at the hit). */
        vec3f ns = n;
        int bent = 0;
        rs_object textured;
        if (HAS(rs_needs_shade(rs, h.part, m))) {
            rs_shade sh;
            rs_shade_at(rs, h.part, p, m, x, n, &sh);
            ns = sh.ns;
            bent = ns.x != n.x || ns.y != n.y || ns.z != n.z;
            if (m->texture || sh.m) {
                textured = *rs_shade_material(&sh, m);
                textured.color = sh.albedo;
                m = &textured;
            }
        }
        rs_object pane_vertex;
        if (__builtin_expect(HAS(m->thin), 0)) {
            pane_vertex = *m;
            float inv = 1.0f / pane_keep;
            int lobes = 0;
            for (int l = 0; l < LOBE_COUNT; l++) {
                float w = l == LOBE_REFRACTIVE ? m->weight[l] * pane_r : m->weight[l];
                pane_vertex.weight[l] = w * inv;
                lobes += w > 0.0f;
            }
            pane_vertex.lobe_choice = lobes > 1;
            m = &pane_vertex;
        }
        uint32_t pair = 1 + (uint32_t)(k - 1) * PAIRS_PER_VERTEX;
        int nee = k >= pp->min_level && (m->weight[LOBE_DIFFUSE] > 0.0f || HAS(m->rough));
        /* Numbers from the stream are drawn only where a choice needs
         * them: most materials have one lobe, most scenes few lights. */
        float u_light[2] = {0.0f, 0.0f}, u_dir[2];
        if (k <= STRATIFIED_VERTICES) {
            sampler_get2_seeded(px->pair_seed[pair], rev_index, u_light);
            sampler_get2_seeded(px->pair_seed[pair + 1], rev_index, u_dir);
        } else {
            if (nee) {
                u_light[0] = sampler_next(&rng);
                u_light[1] = sampler_next(&rng);
            }
            u_dir[0] = sampler_next(&rng);
            u_dir[1] = sampler_next(&rng);
        }
        float u_select = nee && rs->light_count > 1 ? sampler_next(&rng) : 0.0f;
        vec3f x_out = ray_offset(x, n);

        /* Flat parts carry their frame; with n flipped, (t, b, n) is still
         * orthonormal (left-handed), which isotropic lobes do not mind. */
        shading_frame frame = {p->tangent, p->bitangent, ns};
        if (p->shape == SHAPE_SPHERE || bent)
            f3_basis(ns, &frame.t, &frame.b);
        int entering = med.n == 0 || med.obj[med.n - 1] != p->object;
        float eta_i = 1.0f, eta_t = 1.0f;
        if (m->weight[LOBE_REFRACTIVE] > 0.0f) {
            eta_i = medium_ior(rs, &med, 0);
            eta_t = entering ? m->ior : medium_ior(rs, &med, 1);
        }

        /* Next-event estimation through the diffuse lobe, and the rough
         * lobes (each with its own MIS weight: its density is its own
         * strategy's). */
        light_sample ls;
        if (nee && light_sample_point(rs, x, u_select, u_light, &ls) && !f3_is_black(ls.li)) {
            float bsdf_pdf = 0.0f;
            vec3f fcos = f3_splat(0.0f), rough = f3_splat(0.0f);
            /* (Below the surface only rough lobes and bent normals see
             * light: never in a plain scene.) */
            int below = HAS(f3_dot(n, ls.wi) <= 0.0f);
            if (!bent || !below)
                fcos = plain ? bsdf_eval_diffuse(m, ns, ls.wi, &bsdf_pdf)
                             : bsdf_eval_base(m, ns, ls.wi, f3_dot(ns, wo), &bsdf_pdf);
            if (HAS(m->rough | m->coat))
                rough = nee_rough(m, &frame, n, wo, ls.wi, eta_i, eta_t, ls.pdf, ls.delta);
            if (bsdf_pdf > 0.0f || !f3_is_black(rough)) {
                n_rays++;
                rs_part ltri;
                const rs_part *lp = rs_prim(rs, ls.part, &ltri);
                /* Aim the shadow ray from the offset origin at the sampled
                 * point itself: near a sphere's rim, keeping the direction
                 * and distance measured from x would graze the light and
                 * find it blocking itself. */
                vec3f from = below ? ray_offset(x, f3_neg(n)) : x_out;
                vec3f y = f3_madd(x, ls.wi, ls.dist);
                vec3f to_y = f3_sub(y, from);
                float dist_y = f3_length(to_y);
                vec3f dir_y = f3_scale(to_y, 1.0f / dist_y);
                vec3f tr = accel_transmittance(rs, from, dir_y, shadow_ray_end(from, y, dist_y),
                                               lp->background);
                if (!f3_is_black(tr)) {
                    if (bsdf_pdf > 0.0f) {
                        float w_over_pdf = ls.delta ? 1.0f / ls.pdf
                                                    : power_heuristic_over(ls.pdf, bsdf_pdf);
                        radiance = f3_add(radiance,
                                          f3_scale(f3_mul(f3_mul(f3_mul(beta, fcos), ls.li), tr),
                                                   w_over_pdf));
                    }
                    if (HAS(m->rough | m->coat))
                        radiance = f3_add(radiance, f3_mul(f3_mul(f3_mul(beta, rough), ls.li), tr));
                }
            }
        }

        /* Next-event estimation of light from far away. */
        if (__builtin_expect(nee && HAS(rs->distant.any), 0)) {
            float u_far[2], u_pick = rs->distant.map && rs->distant.sun ? sampler_next(&rng) : 0.0f;
            if (k <= STRATIFIED_VERTICES) {
                sampler_get2_seeded(px->pair_seed[DISTANT_PAIR], rev_index, u_far);
            } else {
                u_far[0] = sampler_next(&rng);
                u_far[1] = sampler_next(&rng);
            }
            vec3f wi, li;
            float far_pdf, bsdf_pdf = 0.0f;
            if (distant_sample(&rs->distant, u_pick, u_far, &wi, &far_pdf, &li) &&
                !f3_is_black(li)) {
                vec3f fcos = f3_splat(0.0f), rough = f3_splat(0.0f);
                int below = f3_dot(n, wi) <= 0.0f;
                if (!bent || !below)
                    fcos = bsdf_eval_base(m, ns, wi, f3_dot(ns, wo), &bsdf_pdf);
                if (HAS(m->rough | m->coat))
                    rough = nee_rough(m, &frame, n, wo, wi, eta_i, eta_t, far_pdf, 0);
                if (bsdf_pdf > 0.0f || !f3_is_black(rough)) {
                    n_rays++;
                    /* Escaping means meeting nothing, background included. */
                    vec3f tr = accel_transmittance(rs, below ? ray_offset(x, f3_neg(n)) : x_out,
                                                   wi, FLT_MAX, 1);
                    if (!f3_is_black(tr)) {
                        if (bsdf_pdf > 0.0f)
                            radiance = f3_add(
                                radiance,
                                f3_scale(f3_mul(f3_mul(f3_mul(beta, fcos), li), tr),
                                         power_heuristic_over(far_pdf, bsdf_pdf)));
                        radiance = f3_add(radiance, f3_mul(f3_mul(f3_mul(beta, rough), li), tr));
                    }
                }
            }
        }

        /* Continue along a sampled direction. */
        bsdf_sample bs;
        if (!m->lobe_choice && m->weight[LOBE_DIFFUSE] > 0.0f) {
            /* Diffuse only, the common case: no lobe or split to draw, no
             * medium to track, and the same sample as the general call. */
            if (!bsdf_sample_diffuse(m, &frame, u_dir, &bs))
                break;
            /* Below the geometric surface: the light would leak. */
            if (bent && f3_dot(bs.wi, n) <= 0.0f)
                break;
            beta = f3_mul(beta, bs.weight);
            if (f3_is_black(beta))
                break;
            o = x_out;
        } else {
            float u_lobe = m->lobe_choice ? sampler_next(&rng) : 0.0f;
            float u_split = m->weight[LOBE_REFRACTIVE] > 0.0f ? sampler_next(&rng) : 0.0f;
            if (!bsdf_sample_material(m, &frame, wo, u_lobe, u_split, u_dir,
                                      eta_i, eta_t, &bs))
                break;
            if (bent && (f3_dot(bs.wi, n) > 0.0f) == (bs.transmit != 0))
                break;
            beta = f3_mul(beta, bs.weight);
            if (f3_is_black(beta))
                break;
            if (bs.transmit) {
                if (entering) {
                    if (med.n < MEDIUM_STACK)
                        med.obj[med.n++] = p->object;
                } else {
                    med.n--;
                }
                o = ray_offset(x, f3_neg(n));
            } else {
                o = x_out;
            }
        }
        prev_delta = bs.delta;
        prev_pdf = bs.pdf;
        prev_x = x;
        seg_t = 0.0f;
        d = bs.wi;

        /* Russian roulette: a path whose throughput has fallen below 1
         * survives with probability equal to it, and is boosted by as
         * much, which keeps the estimate unbiased. */
        float q = f3_max(beta);
        if (k >= RR_START && q < 1.0f) {
            if (sampler_next(&rng) >= q)
                break;
            beta = f3_scale(beta, 1.0f / q);
        }
    }
    *rays += n_rays;
    if (!isfinite(radiance.x) || !isfinite(radiance.y) || !isfinite(radiance.z))
        return f3_splat(0.0f);
    return radiance;
}

#undef HAS

/* Each copy flattened on its own (every call inlined, so the loop's
 * registers do not spill around calls); in one function together they
 * were allocated worse than either alone. */
__attribute__((flatten, noinline))
static vec3f trace_plain(const rscene *rs, const path_params *pp, vec3f o, vec3f d,
                         const path_pixel *px, uint32_t index, uint32_t rev_index,
                         uint64_t *rays)
{
    return trace(rs, pp, o, d, px, index, rev_index, rays, 1);
}

__attribute__((flatten, noinline))
static vec3f trace_general(const rscene *rs, const path_params *pp, vec3f o, vec3f d,
                           const path_pixel *px, uint32_t index, uint32_t rev_index,
                           uint64_t *rays)
{
    return trace(rs, pp, o, d, px, index, rev_index, rays, 0);
}

vec3f path_trace_sample(const rscene *rs, const path_params *pp, vec3f o,
                        vec3f d, const path_pixel *px, uint32_t index,
                        uint32_t rev_index, uint64_t *rays)
{
    return rs->plain ? trace_plain(rs, pp, o, d, px, index, rev_index, rays)
                     : trace_general(rs, pp, o, d, px, index, rev_index, rays);
}
