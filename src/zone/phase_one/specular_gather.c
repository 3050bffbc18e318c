#include "zone/phase_one/specular_gather.h"

#include <math.h>

#include "geom/ray_offset.h"
#include "util/sampler.h"
#include "util/vec3_convert.h"
#include "zone/phase_one/specular_targets.h"

/* A cone gets at least q.gather / AIM_MIN_SHARE directions; a target seen
 * under a wider cone than AIM_MAX_OMEGA is left to the hemisphere. */
#define AIM_MIN_SHARE 8
#define AIM_MAX_OMEGA 3.14159265358979 /* sr: a cone of half-angle 60 degrees */

typedef struct aim_cone {
    vec3 w;       /* axis, unit */
    double omc;   /* 1 - cos of the half-angle */
    double dens;  /* count / solid angle */
    int count;
} aim_cone;

/* The sum of the strategies' count x density in direction d (unit). */
static double aim_density(const aim_cone *cone, int cones, int hemi, vec3 n, vec3 d, int own)
{
    double p = hemi * fmax(0.0, v3_dot(n, d)) / 3.14159265358979;
    for (int j = 0; j < cones; j++)
        if (j == own || 1.0 - v3_dot(cone[j].w, d) <= cone[j].omc)
            p += cone[j].dens;
    return p;
}

#define AIM_CONES_MAX 64
vec3 zone_specular_gather(zone_trace *t, vec3 x, vec3 n, int level)
{
    const zone_forest *f = t->f;
    const int flags = ZR_SKIP_DIFFUSE | ZR_NO_GLINT | ZR_NO_CAUSTIC;
    vec3f o = ray_offset(v3_to_f3(x), v3_to_f3(n));
    aim_cone cone[AIM_CONES_MAX];
    int cones = 0, hemi = f->spec_unaimable, aimed = 0;
    int min_count = f->q.gather / AIM_MIN_SHARE;
    for (int i = 0; i < f->spec_target_count && !hemi; i++) {
        const specular_target *tg = &f->spec_targets[i];
        vec3 to = v3_sub(tg->c, x);
        double dist = v3_length(to);
        if (dist <= tg->r) {
            hemi = 1;
            break;
        }
        vec3 w = v3_scale(to, 1.0 / dist);
        double sin_max = tg->r / dist;
        if (v3_dot(w, n) < -sin_max) /* the whole cone below the horizon */
            continue;
        double omc = specular_cone_omc(tg->r, dist), omega = 2.0 * 3.14159265358979 * omc;
        if (omega > AIM_MAX_OMEGA || cones == AIM_CONES_MAX) {
            hemi = 1;
            break;
        }
        int count = (int)ceil(f->q.gather * omega / 3.14159265358979);
        if (count < min_count)
            count = min_count;
        cone[cones++] = (aim_cone){w, omc, count / omega, count};
        aimed += count;
    }
    if (aimed > f->q.gather) /* many targets: the hemisphere alone */
        hemi = 1, cones = 0;
    vec3 tt, bb;
    vec3 sum = v3(0, 0, 0);
    if (hemi) {
        /* Over the hemisphere, as cos / pi x count; alone, each direction
         * weighs pi / count. */
        v3_frame(n, &tt, &bb);
        for (int k = 0; k < f->q.gather; k++) {
            const vec3 *dk = &f->dirs[k];
            vec3 d = v3_normalize(
                v3_add(v3_add(v3_scale(tt, dk->x), v3_scale(bb, dk->y)), v3_scale(n, dk->z)));
            vec3 l = zone_radiance(t, o, v3_to_f3(d), level, level, flags, NULL, 0);
            if (v3_is_black(l))
                continue;
            if (!cones) {
                sum = v3_add(sum, l);
                continue;
            }
            double c = v3_dot(n, d);
            sum = v3_add(sum, v3_scale(l, c / aim_density(cone, cones, f->q.gather, n, d, -1)));
        }
        if (!cones)
            return v3_scale(sum, 3.14159265358979 / f->q.gather);
    }
    for (int j = 0; j < cones; j++) {
        v3_frame(cone[j].w, &tt, &bb);
        for (int k = 0; k < cone[j].count; k++) {
            uint32_t b = sampler_reverse_bits((uint32_t)k);
            double u = (k + 0.5) / cone[j].count * cone[j].omc;
            double cz = 1.0 - u, sz = sqrt(fmax(0.0, u * (2.0 - u)));
            double phi = 2.0 * 3.14159265358979 * (b * (1.0 / 4294967296.0));
            vec3 d = v3_add(v3_add(v3_scale(tt, sz * cos(phi)), v3_scale(bb, sz * sin(phi))),
                            v3_scale(cone[j].w, cz));
            double c = v3_dot(n, d);
            if (c <= 0.0)
                continue;
            vec3 l = zone_radiance(t, o, v3_to_f3(d), level, level, flags, NULL, 0);
            if (!v3_is_black(l))
                sum = v3_add(sum, v3_scale(l, c / aim_density(cone, cones, hemi ? f->q.gather : 0,
                                                              n, d, j)));
        }
    }
    return sum;
}

