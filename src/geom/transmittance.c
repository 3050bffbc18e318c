#include "geom/transmittance.h"

#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "material/bsdf.h"
#include "render/prim.h"

/* Panes crossed before giving up: a ray through more sheets of glass than
 * this carries nothing worth a ray (0.92^32 < 7%), and a ray stuck on a
 * surface cannot loop. */
#define PANES_MAX 32

/* Rays accel_transmittance_panes_n traces together. */
#define TRANSMITTANCE_N_MAX 64

vec3f accel_transmittance(const rscene *rs, vec3f o, vec3f d, float dist,
                          int target_is_background)
{
    return accel_transmittance_panes(rs, o, d, dist, target_is_background, NULL);
}

/* accel_transmittance_panes in a scene with panes; `given`, when not
 * NULL, is the ray's first hit, already found. */
static vec3f through_panes(const rscene *rs, vec3f o, vec3f d, float dist, int target_is_background,
                           int *first_pane, const hit *given)
{
    vec3f tr = f3_splat(1.0f);
    for (int k = 0; k < PANES_MAX; k++) {
        hit h = k == 0 && given ? *given : accel_intersect(rs, o, d);
        /* The nearest hit decides accel_occluded's rule by itself: it is a
         * foreground one if any is on the ray.  Nothing hit: nothing
         * hides the target. */
        if (h.part < 0)
            return tr;
        rs_part tmp;
        const rs_part *p = rs_prim(rs, h.part, &tmp);
        if (!(h.t < dist)) {
            /* Beyond the target: a foreground target is seen; a background
             * one is hidden by the foreground anywhere, and the background
             * is not before it. */
            return !target_is_background || p->background ? tr : f3_splat(0.0f);
        }
        const rs_object *m = &rs->objects[p->object];
        if (!rs_passes(m) || p->is_light) {
            /* Before the target: a foreground hit hides any target; a
             * background hit means there was no foreground one, and hides
             * a background target only. */
            return !target_is_background && p->background ? tr : f3_splat(0.0f);
        }
        if (first_pane && *first_pane < 0 && m->thin)
            *first_pane = h.part;
        vec3f x = shape_hit_point(p, o, d, h.t);
        vec3f ng = shape_normal(p, x);
        float c = f3_dot(ng, d);
        tr = f3_mul(tr, bsdf_pass_through(m, rs_coverage(rs, h.part, p, m, x), fabsf(c)));
        if (f3_is_black(tr))
            return tr;
        o = ray_offset(x, c > 0.0f ? ng : f3_neg(ng));
        dist -= h.t;
    }
    return accel_occluded(rs, o, d, dist, target_is_background) ? f3_splat(0.0f) : tr;
}

vec3f accel_transmittance_panes(const rscene *rs, vec3f o, vec3f d, float dist,
                                int target_is_background, int *first_pane)
{
    if (first_pane)
        *first_pane = -1;
    if (!rs->pane_count)
        return f3_splat(accel_occluded(rs, o, d, dist, target_is_background) ? 0.0f : 1.0f);
    return through_panes(rs, o, d, dist, target_is_background, first_pane, NULL);
}

void accel_transmittance_panes_n(const rscene *rs, vec3f o, const vec3f *d, const float *dist,
                                 int n, int target_is_background, vec3f *tr, int *first_pane)
{
    hit first[TRANSMITTANCE_N_MAX];
    unsigned char hidden[TRANSMITTANCE_N_MAX];
    for (int base = 0; base < n; base += TRANSMITTANCE_N_MAX) {
        int m = n - base < TRANSMITTANCE_N_MAX ? n - base : TRANSMITTANCE_N_MAX;
        if (!rs->pane_count) {
            accel_occluded_n(rs, o, d + base, dist + base, m, target_is_background, hidden);
            for (int i = 0; i < m; i++) {
                tr[base + i] = f3_splat(hidden[i] ? 0.0f : 1.0f);
                if (first_pane)
                    first_pane[base + i] = -1;
            }
            continue;
        }
        accel_intersect_n(rs, o, d + base, m, first);
        for (int i = 0; i < m; i++) {
            int *fp = first_pane ? first_pane + base + i : NULL;
            if (fp)
                *fp = -1;
            tr[base + i] = through_panes(rs, o, d[base + i], dist[base + i], target_is_background,
                                         fp, &first[i]);
        }
    }
}
