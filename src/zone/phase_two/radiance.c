/* Radiance by level along a ray, from the forest:
 *   level 0      lights (and sky) seen directly;
 *   level 1      diffuse: rho/pi * exact direct irradiance (camera paths) or
 *                the level-0 map (gathers);
 *   level l >= 2 diffuse: rho/pi * the level l-1 irradiance map, or on a
 *                mesh (camera paths) the level l-1 light gathered there;
 *   specular lobes (mirror, metal, glass) pass the levels below theirs on
 *   along the reflected and refracted rays, deterministically: the glass
 *   lobe follows both the reflected and the transmitted ray;
 *   a thin pane passes the light behind it at the same levels (crossing
 *   it is no scattering), tinted and less what it reflects;
 *   a surface of coverage c < 1 (alpha) is c times all of the above, plus
 *   1 - c times the light behind it at the same levels. */
#include "zone/zone.h"

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "light/distant.h"
#include "light/light_sample.h"
#include "light/mis.h"
#include "material/bsdf.h"
#include "render/prim.h"
#include "util/vec3_convert.h"
#include "zone/phase_two/media.h"
#include "zone/phase_one/specular_targets.h"
#include "zone/phase_one/glint.h"
#include "zone/light/sky_gather.h"



/* An escaping ray's radiance; light from far away weighed against a rough
 * lobe's light samples when mis (the lobe's density) is set; without the
 * sun when no_sun (its photons carry it). */
static vec3 background(const rscene *rs, vec3f d, float mis, int no_sun)
{
    vec3f sun = no_sun && distant_in_sun(&rs->distant, d) ? rs->distant.sun_radiance
                                                          : f3_splat(0.0f);
    if (!rs->distant.any || !(mis > 0.0f))
        return f3_to_v3(f3_sub(zone_background(rs, d), sun));
    float pdf;
    vec3f l = f3_sub(distant_eval(&rs->distant, d, &pdf), sun);
    return f3_to_v3(f3_add(rs->sky, f3_scale(l, power_heuristic(mis, pdf))));
}

vec3 zone_radiance(zone_trace *t, vec3f o, vec3f d, int lo, int hi,
                   int flags, const int *media, int media_count)
{
    int exact_direct = flags & ZR_EXACT_DIRECT;
    int whole = flags & ZR_WHOLE_HIT;
    flags &= ~ZR_WHOLE_HIT;
    /* A rough lobe's direction: its light of level 0 is weighed against
     * the lobe's light samples (rough.c). */
    float mis = t->mis_pdf;
    t->mis_pdf = 0.0f;
    const hit *given = t->first_hit;
    t->first_hit = NULL;
    if (hi < 0 || lo > hi)
        return v3(0, 0, 0);
    const rscene *rs = &t->r->rs;
    hit h;
    if (given) {
        h = *given;
    } else {
        h = accel_intersect(rs, o, d);
        t->rays++;
    }
    if (h.part < 0)
        return lo <= 0 ? background(rs, d, mis,
                                    (flags & ZR_CAUSTIC_LIGHT) && t->f->sun_photons)
                       : v3(0, 0, 0);
    rs_part tmp;
    const rs_part *p = rs_prim(rs, h.part, &tmp);
    vec3f xf = shape_hit_point(p, o, d, h.t);
    /* Lights that send caustic photons (caustic.h) are theirs to count
     * after a caustic target. */
    int photons = (flags & ZR_CAUSTIC_LIGHT) &&
                  (p->shape == SHAPE_TRIANGLE || p->shape == SHAPE_SPHERE);
    /* Light parts seen by the camera are measured by coverage; mesh lights
     * are shaded on the samples. */
    if (p->is_light) {
        if (lo > 0 || ((flags & ZR_NO_EMISSION) && h.part < rs->part_count) || photons)
            return v3(0, 0, 0);
        vec3f le = light_emitted(rs, h.part, p, xf, d);
        if (mis > 0.0f && p->select_pdf > 0.0f)
            le = f3_scale(le, power_heuristic(
                                  mis, light_pdf(p, t->mis_from, d,
                                                 f3_length(f3_sub(xf, t->mis_from)))));
        return f3_to_v3(le);
    }
    const rs_object *m = &rs->objects[p->object];
    /* Coverage cov < 1 (alpha): the surface is cov of what follows, and
     * the light behind it arrives at the same levels by the rest,
     * untouched (weighed deterministically, not chosen). */
    float cov = 1.0f;
    vec3 behind = v3(0, 0, 0);
    if (__builtin_expect(m->alpha_mode != 0, 0) && !whole) {
        cov = rs_coverage_at(rs, h.part, p, m, xf);
        if (cov < 1.0f) {
            vec3f ng = shape_normal(p, xf);
            t->mis_pdf = mis;
            behind = v3_scale(zone_radiance(t, ray_offset(xf, f3_dot(ng, d) > 0.0f ? ng : f3_neg(ng)),
                                            d, lo, hi, flags, media, media_count),
                              1.0 - cov);
        }
    }
    if (hi < 1 && !m->thin) /* a pane passes level 0 on */
        return behind;

    vec3f ngf = shape_normal(p, xf);
    int back = f3_dot(ngf, d) > 0.0f;
    vec3f nf = back ? f3_neg(ngf) : ngf;
    /* Meshes: shading normal and texture; the geometric normal decides
     * the side. */
    rs_shade sh; /* its mat is filled only when the maps give it */
    sh.ns = nf;
    sh.albedo = m->color;
    sh.m = NULL;
    if (rs_needs_shade(rs, h.part, m)) {
        rs_shade_at(rs, h.part, p, m, xf, nf, &sh);
        m = rs_shade_material(&sh, m); /* with maps: the material here */
    }
    vec3 x = f3_to_v3(xf), n = f3_to_v3(sh.ns), color = f3_to_v3(sh.albedo);
    vec3 out = v3(0, 0, 0);

    if (m->weight[LOBE_DIFFUSE] > 0.0f && !(flags & ZR_SKIP_DIFFUSE)) {
        vec3 e = v3(0, 0, 0);
        int l = lo > 1 ? lo : 1;
        if (l == 1 && exact_direct) {
            /* Exact direct light from the lights, and the sky's. */
            e = v3_add(e, zone_lights_at(t, h.part, x, n));
            if (t->f->sky)
                e = v3_add(e, zone_sky_irradiance(t, x, n));
            l++;
        }
        /* A camera path reads the caustics from the photons. */
        if (exact_direct && !(flags & ZR_BLURRED) && l <= hi && t->f->caustic)
            e = v3_add(e, zone_caustic_read(t, l - 1, hi - 1, h.part, back, x, f3_to_v3(nf)));
        if (exact_direct && zone_gathers(rs, h.part)) {
            for (; l <= hi; l++)
                e = v3_add(e, zone_mesh_irradiance(t, xf, nf, n, l - 1, h.part, back));
        } else if (l <= hi) {
            /* The maps of the remaining levels, read at once. */
            e = zone_map_read_levels(t->f, rs, l - 1, hi - 1, h.part, back, x, e);
        }
        /* Under a coat (bsdf.h) the base keeps 1 - s E(cos_o). */
        double keep = m->coat ? 1.0 - bsdf_coat_albedo(m, -f3_dot(sh.ns, d)) : 1.0;
        out = v3_add(out, v3_scale(v3_mul(color, e),
                                   keep * m->weight[LOBE_DIFFUSE] / 3.14159265358979));
        if (m->coat && (flags & ZR_SMOOTH_COAT))
            out = v3_add(out, v3_scale(e, (1.0 - keep) * m->weight[LOBE_DIFFUSE] /
                                              3.14159265358979));
    }
    if (m->coat && hi >= 1 && !(flags & (ZR_SKIP_DIFFUSE | ZR_SMOOTH_COAT))) {
        zone_rough_at at = {m, h.part, xf, nf, sh.ns, color, d, 1.0f, 1.0f, p->object, 0,
                            media, media_count, 0.0f};
        out = v3_add(out, zone_coat_on_the_way(t, &at, lo - 1, hi - 1, flags));
    }

    /* Smooth lobes here; rough ones (m->rough: all but a pane's) below. */
    float wm = bsdf_smooth_weight(m, LOBE_METALLIC), wr = bsdf_smooth_weight(m, LOBE_REFLECTING);
    float wt = bsdf_smooth_weight(m, LOBE_REFRACTIVE);
    if ((hi >= 1 || m->thin) && (wm > 0.0f || wr > 0.0f || wt > 0.0f)) {
        vec3f ng_facing = nf;
        nf = sh.ns;
        vec3f wo = f3_neg(d);
        float cos_o = f3_dot(nf, wo);
        vec3f refl = f3_normalize(f3_sub(d, f3_scale(nf, 2.0f * f3_dot(d, nf))));
        vec3f out_o = ray_offset(xf, ng_facing);
        double k_refl = wr;
        if (wm > 0.0f)
            k_refl += wm * bsdf_schlick(cos_o, m->ior);
        double k_tran = 0;
        float eta_i, eta_t;
        int entering = media_indices(rs, media, media_count, p->object, m, &eta_i, &eta_t);
        vec3 pass = v3(0, 0, 0);
        if (wt > 0.0f && m->thin) {
            float fr = bsdf_pane_reflectance(cos_o, m->ior);
            k_refl += wt * fr;
            pass = v3_scale(f3_to_v3(m->tint), wt * (1.0 - fr));
        } else if (wt > 0.0f) {
            float fr = bsdf_fresnel_dielectric(cos_o, eta_i, eta_t);
            k_refl += wt * fr;
            k_tran = wt * (1.0 - fr);
        }
        /* Under ZR_NO_CAUSTIC every specular ray passes it on, and marks
         * the rays that leave a caustic target. */
        int cflags = flags & (ZR_BLURRED | ZR_SMOOTH_COAT);
        if (flags & ZR_NO_CAUSTIC)
            cflags |= ZR_NO_CAUSTIC | (specular_target_part(rs, h.part) ? ZR_CAUSTIC_LIGHT : 0);
        if (k_refl > 0) {
            int rflags = exact_direct | cflags;
            if ((flags & ZR_NO_GLINT) && !back && media_count == 0 && glint_sphere(rs, h.part))
                rflags |= ZR_NO_EMISSION;
            vec3 l = zone_radiance(t, out_o, refl, lo - 1, hi - 1, rflags, media, media_count);
            out = v3_add(out, v3_scale(v3_mul(color, l), k_refl));
        }
        if (!v3_is_black(pass)) {
            t->mis_pdf = mis; /* crossing a pane, the ray goes on */
            vec3 l = zone_radiance(t, ray_offset(xf, f3_neg(ng_facing)), d, lo, hi,
                                   flags, media, media_count);
            out = v3_add(out, v3_mul(pass, l));
        }
        if (k_tran > 0) {
            float eta = eta_i / eta_t;
            vec3f tr = media_refract(d, nf, cos_o, eta);
            int next[MEDIA_MAX];
            int nc = media_cross(media, media_count, p->object, entering, next);
            vec3 l = zone_radiance(t, ray_offset(xf, f3_neg(ng_facing)), tr, lo - 1, hi - 1,
                                   exact_direct | cflags, next, nc);
            out = v3_add(out, v3_scale(v3_mul(color, l), k_tran * eta * eta));
        }
    }
    if (m->rough && hi >= 1) {
        zone_rough_at at = {m, h.part, xf, back ? f3_neg(ngf) : ngf, sh.ns, color, d, 1.0f,
                            1.0f, p->object, 0, media, media_count, 0.0f};
        at.entering = media_indices(rs, media, media_count, p->object, m, &at.eta_i, &at.eta_t);
        out = v3_add(out, zone_rough_radiance(t, &at, ~0u, lo - 1, hi - 1, flags));
    }
    if (cov < 1.0f)
        out = v3_add(v3_scale(out, cov), behind);
    return out;
}
