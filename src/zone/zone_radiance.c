/* Radiance by level along a ray, from the forest:
 *   level 0      lights (and sky) seen directly;
 *   level 1      diffuse: rho/pi * exact direct irradiance (camera paths) or
 *                the level-0 map (gathers);
 *   level l >= 2 diffuse: rho/pi * the level l-1 irradiance map;
 *   specular lobes (mirror, metal, glass) pass the levels below theirs on
 *   along the reflected and refracted rays, deterministically: the glass
 *   lobe follows both the reflected and the transmitted ray. */
#include "zone/zone_internal.h"

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "light/light_sample.h"
#include "material/bsdf.h"
#include "util/vec3_convert.h"
#include "zone/media.h"
#include "zone/caustic.h"
#include "zone/glint.h"



static vec3 direct_light(zone_trace *t, int receiver, vec3 x, vec3 n)
{
    const rscene *rs = &t->r->rs;
    vec3 e = v3(0, 0, 0);
    for (int i = 0; i < rs->part_count; i++) {
        const rs_part *lp = &rs->parts[i];
        if (!lp->is_light)
            continue;
        vec3f em = rs->objects[lp->object].emission;
        if (f3_is_black(em))
            continue;
        double g = direct_irradiance(&t->f->direct, i, x, n, receiver);
        e = v3_add(e, v3_scale(f3_to_v3(em), g));
    }
    return e;
}


vec3 zone_radiance(zone_trace *t, vec3f o, vec3f d, int lo, int hi,
                   int flags, const int *media, int media_count)
{
    int exact_direct = flags & ZR_EXACT_DIRECT;
    if (hi < 0 || lo > hi)
        return v3(0, 0, 0);
    const rscene *rs = &t->r->rs;
    hit h = accel_intersect(rs, o, d);
    t->rays++;
    if (h.part < 0)
        return lo <= 0 ? f3_to_v3(rs->sky) : v3(0, 0, 0);
    const rs_part *p = &rs->parts[h.part];
    vec3f xf = f3_madd(o, d, h.t);
    /* Lights that send caustic photons (caustic.h) are theirs to count
     * after a caustic target. */
    int photons = (flags & ZR_CAUSTIC_LIGHT) &&
                  (p->shape == SHAPE_TRIANGLE || p->shape == SHAPE_SPHERE);
    if (p->is_light)
        return lo <= 0 && !(flags & ZR_NO_EMISSION) && !photons
                   ? f3_to_v3(light_emitted(rs, p, xf, d))
                   : v3(0, 0, 0);
    if (hi < 1)
        return v3(0, 0, 0);

    const rs_object *m = &rs->objects[p->object];
    vec3f ngf = shape_normal(p, xf);
    int back = f3_dot(ngf, d) > 0.0f;
    vec3f nf = back ? f3_neg(ngf) : ngf;
    vec3 x = f3_to_v3(xf), n = f3_to_v3(nf), color = f3_to_v3(m->color);
    vec3 out = v3(0, 0, 0);

    int skip_diffuse = (flags & ZR_SKIP_FLAT_DIFFUSE) && p->shape != SHAPE_SPHERE;
    if (m->weight[LOBE_DIFFUSE] > 0.0f && !skip_diffuse) {
        vec3 e = v3(0, 0, 0);
        const part_map *pm = &t->f->maps[h.part];
        for (int l = lo > 1 ? lo : 1; l <= hi; l++) {
            if (l == 1 && exact_direct) {
                /* Exact direct light from the lights; the sky's share
                 * (a gathered quantity) is the level-0 map minus that. */
                e = v3_add(e, direct_light(t, h.part, x, n));
                if (t->f->sky_slot >= 0)
                    e = v3_add(e, forest_sky_irradiance(t, x, n));
            } else if (l - 1 < t->f->map_levels) {
                /* A gather ray's value is an average over its cone's
                 * footprint: read the map at that width. */
                double width = 0;
                if (t->cone > 0.0f)
                    width = 2.0 * t->cone * h.t / fmax(0.2, fabs(f3_dot(d, ngf)));
                e = v3_add(e, map_lookup_wide(pm, l - 1, back, x, width));
            }
        }
        out = v3_add(out, v3_scale(v3_mul(color, e), m->weight[LOBE_DIFFUSE] / 3.14159265358979));
    }

    float wm = m->weight[LOBE_METALLIC], wr = m->weight[LOBE_REFLECTING];
    float wt = m->weight[LOBE_REFRACTIVE];
    if (hi >= 1 && (wm > 0.0f || wr > 0.0f || wt > 0.0f)) {
        vec3f wo = f3_neg(d);
        float cos_o = f3_dot(nf, wo);
        vec3f refl = f3_normalize(f3_sub(d, f3_scale(nf, 2.0f * f3_dot(d, nf))));
        vec3f out_o = ray_offset(xf, nf);
        double k_refl = wr;
        if (wm > 0.0f)
            k_refl += wm * bsdf_schlick(cos_o, m->ior);
        double k_tran = 0;
        int entering = media_count == 0 || media[media_count - 1] != p->object;
        float eta_i = media_count ? rs->objects[media[media_count - 1]].ior : 1.0f;
        float eta_t = entering ? m->ior
                               : (media_count > 1 ? rs->objects[media[media_count - 2]].ior : 1.0f);
        if (wt > 0.0f) {
            float fr = bsdf_fresnel_dielectric(cos_o, eta_i, eta_t);
            k_refl += wt * fr;
            k_tran = wt * (1.0 - fr);
        }
        /* Under ZR_NO_CAUSTIC every specular ray passes it on, and marks
         * the rays that leave a caustic target. */
        int cflags = 0;
        if (flags & ZR_NO_CAUSTIC)
            cflags = ZR_NO_CAUSTIC | (caustic_target(rs, h.part) ? ZR_CAUSTIC_LIGHT : 0);
        if (k_refl > 0) {
            int rflags = exact_direct | cflags;
            if ((flags & ZR_NO_GLINT) && !back && media_count == 0 && glint_sphere(rs, h.part))
                rflags |= ZR_NO_EMISSION;
            vec3 l = zone_radiance(t, out_o, refl, lo - 1, hi - 1, rflags, media, media_count);
            out = v3_add(out, v3_scale(v3_mul(color, l), k_refl));
        }
        if (k_tran > 0) {
            float eta = eta_i / eta_t;
            vec3f tr = media_refract(d, nf, cos_o, eta);
            int next[MEDIA_MAX];
            int nc = media_cross(media, media_count, p->object, entering, next);
            vec3 l = zone_radiance(t, ray_offset(xf, f3_neg(nf)), tr, lo - 1, hi - 1,
                                   exact_direct | cflags, next, nc);
            out = v3_add(out, v3_scale(v3_mul(color, l), k_tran * eta * eta));
        }
    }
    return out;
}
