#include "geom/transmittance.h"

#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "material/bsdf.h"
#include "render/prim.h"

/* Panes crossed before giving up: a ray through more sheets of glass than
 * this carries nothing worth a ray (0.92^32 < 7%), and a ray stuck on a
 * surface cannot loop. */
#define PANES_MAX 32

vec3f accel_transmittance(const rscene *rs, vec3f o, vec3f d, float dist,
                          int target_is_background)
{
    return accel_transmittance_panes(rs, o, d, dist, target_is_background, NULL);
}

vec3f accel_transmittance_panes(const rscene *rs, vec3f o, vec3f d, float dist,
                                int target_is_background, int *first_pane)
{
    if (first_pane)
        *first_pane = -1;
    if (!rs->pane_count)
        return f3_splat(accel_occluded(rs, o, d, dist, target_is_background) ? 0.0f : 1.0f);
    vec3f tr = f3_splat(1.0f);
    for (int k = 0; k < PANES_MAX; k++) {
        hit h = accel_intersect(rs, o, d);
        if (h.part < 0 || !(h.t < dist)) {
            if (!target_is_background)
                return tr; /* no foreground hit before the target */
            break;
        }
        rs_part tmp;
        const rs_part *p = rs_prim(rs, h.part, &tmp);
        const rs_object *m = &rs->objects[p->object];
        if (!rs_passes(m) || p->is_light) {
            /* A foreground target is hidden by a foreground hit before it;
             * a background hit means there was none.  Other cases keep
             * the full rule. */
            if (!target_is_background)
                return p->background ? tr : f3_splat(0.0f);
            break;
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
