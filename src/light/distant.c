/* Light from far away: evaluation and sampling (distant.h). */
#include "light/distant.h"

#include <math.h>

#include "light/env_map.h"
#include "util/vec3_convert.h"

#define PI_F 3.14159265358979f

void distant_build(rs_distant *d, const zt_scene *scene)
{
    *d = (rs_distant){0};
    const sun_light *sun = &scene->sun;
    if (scene->sky_map && scene->sky_strength > 0 && scene->sky_map->weight_sum > 0) {
        d->map = scene->sky_map;
        d->sampling = scene->sky_map;
        d->strength = (float)scene->sky_strength;
        d->rot_cos = (float)cos(scene->sky_rotate);
        d->rot_sin = (float)sin(scene->sky_rotate);
    }
    if (sun->present && !v3_is_black(sun->irradiance)) {
        double r = sun->angle / 2;
        /* 1 - cos r in a form that keeps its digits for a small disc. */
        double s = sin(r / 2);
        double sin2 = sin(r) * sin(r);
        d->sun = 1;
        d->sun_dir = v3_to_f3(sun->direction);
        f3_basis(d->sun_dir, &d->sun_t, &d->sun_b);
        d->sun_one_minus_cos = (float)(2 * s * s);
        d->sun_sin2 = (float)sin2;
        d->sun_radiance = v3_to_f3(v3_scale(sun->irradiance, 1.0 / (3.14159265358979 * sin2)));
    }
    d->any = d->map || d->sun;
    if (d->sun && d->map) {
        /* The sun by its irradiance against what the map sends a surface
         * (pi times its mean luminance for a uniform map). */
        double e_sun = f3_luminance(v3_to_f3(sun->irradiance));
        double e_map = 3.14159265358979 * d->map->mean_luminance * d->strength;
        d->sun_select = (float)(e_sun / (e_sun + e_map));
    } else {
        d->sun_select = d->sun ? 1.0f : 0.0f;
    }
}

/* From the scene's frame into the map's and back (the map turned by the
 * angle about +y). */
static inline vec3f to_map(const rs_distant *d, vec3f w)
{
    return f3(d->rot_cos * w.x - d->rot_sin * w.z, w.y, d->rot_sin * w.x + d->rot_cos * w.z);
}

static inline vec3f from_map(const rs_distant *d, vec3f w)
{
    return f3(d->rot_cos * w.x + d->rot_sin * w.z, w.y, -d->rot_sin * w.x + d->rot_cos * w.z);
}

int distant_in_sun(const rs_distant *d, vec3f w)
{
    /* sin^2 of the angle to the sun's centre from the cross product: the
     * dot product of two nearly equal unit vectors has no digits left for
     * a disc half a degree wide. */
    vec3f c = f3_cross(w, d->sun_dir);
    return d->sun && f3_dot(w, d->sun_dir) > 0.0f && f3_dot(c, c) <= d->sun_sin2;
}

vec3f distant_map_radiance(const rs_distant *d, vec3f w)
{
    return d->map ? f3_scale(env_map_radiance(d->map, to_map(d, w)), d->strength) : f3_splat(0.0f);
}

vec3f distant_radiance(const rs_distant *d, vec3f w)
{
    vec3f l = f3_splat(0.0f);
    if (d->map)
        l = f3_scale(env_map_radiance(d->map, to_map(d, w)), d->strength);
    if (distant_in_sun(d, w))
        l = f3_add(l, d->sun_radiance);
    return l;
}

float distant_pdf(const rs_distant *d, vec3f w)
{
    float p = 0.0f;
    if (d->map && d->sun_select < 1.0f)
        p = (1.0f - d->sun_select) * env_map_pdf(d->sampling, to_map(d, w));
    if (distant_in_sun(d, w))
        p += d->sun_select / (2.0f * PI_F * d->sun_one_minus_cos);
    return p;
}

vec3f distant_eval(const rs_distant *d, vec3f w, float *pdf)
{
    if (!d->map || d->sampling != d->map) {
        *pdf = distant_pdf(d, w);
        return distant_radiance(d, w);
    }
    float map_pdf;
    vec3f l = f3_scale(env_map_lookup(d->map, to_map(d, w), &map_pdf), d->strength);
    float p = (1.0f - d->sun_select) * map_pdf;
    if (distant_in_sun(d, w)) {
        l = f3_add(l, d->sun_radiance);
        p += d->sun_select / (2.0f * PI_F * d->sun_one_minus_cos);
    }
    *pdf = p;
    return l;
}

vec3f distant_sun_direction(const rs_distant *d, const float u[2])
{
    /* Uniform in the cone: 1 - cos theta uniform in [0, 1 - cos r]. */
    float omc = u[0] * d->sun_one_minus_cos;
    float sin_t = sqrtf(f_max0(omc * (2.0f - omc)));
    float phi = 2.0f * PI_F * u[1];
    vec3f w = f3_scale(d->sun_dir, 1.0f - omc);
    w = f3_madd(w, d->sun_t, sin_t * cosf(phi));
    return f3_madd(w, d->sun_b, sin_t * sinf(phi));
}

float distant_map_sample(const rs_distant *d, const float u[2], vec3f *w, vec3f *l)
{
    vec3f wm;
    float pdf = d->map ? env_map_sample(d->sampling, u, &wm) : 0.0f;
    if (pdf <= 0.0f)
        return 0.0f;
    *w = from_map(d, wm);
    *l = f3_scale(env_map_radiance(d->map, wm), d->strength);
    return pdf;
}

int distant_sample(const rs_distant *d, float u_select, const float u[2], vec3f *w,
                   float *pdf, vec3f *li)
{
    if (!d->any)
        return 0;
    if (u_select < d->sun_select) {
        *w = distant_sun_direction(d, u);
    } else {
        vec3f wm;
        if (env_map_sample(d->sampling, u, &wm) <= 0.0f)
            return 0;
        *w = from_map(d, wm);
    }
    *li = distant_eval(d, *w, pdf);
    return *pdf > 0.0f;
}
