/* Visibility through thin panes and partial coverage: the one query that
 * lets light cross a window or a see-through texture.  A pane (a material
 * whose refractive lobe is "thin") passes the light it does not reflect
 * undeviated, a surface of coverage c < 1 (alpha) the share 1 - c, so a
 * shadow ray that meets one goes on, carrying that transmittance
 * (bsdf_pass_through); anything else blocks it.  Holes (coverage 0) are
 * not hits at all (accel.h). */
#ifndef ZT_GEOM_TRANSMITTANCE_H
#define ZT_GEOM_TRANSMITTANCE_H

#include "geom/accel.h"

/* What reaches o from the point at distance dist along unit d, as a
 * colour factor: accel_occluded's rule (the same background rule), with
 * panes and partial coverage on the way multiplying instead of blocking.
 * Scenes without either pay one accel_occluded call and get 0 or 1. */
vec3f accel_transmittance(const rscene *rs, vec3f o, vec3f d, float dist,
                          int target_is_background);

/* accel_transmittance, and in *first_pane the primitive of the first thin
 * pane (a material with "thin") the ray crosses, -1 when it crosses none.
 * Partial coverage does not count as a pane. */
vec3f accel_transmittance_panes(const rscene *rs, vec3f o, vec3f d, float dist,
                                int target_is_background, int *first_pane);

/* accel_transmittance_panes for n rays from one origin o (unit directions
 * d[i], distances dist[i]) into tr[i] and, when first_pane is not NULL,
 * first_pane[i]: the same answers, the rays' first hits found together
 * (packets, accel_intersect_n). */
void accel_transmittance_panes_n(const rscene *rs, vec3f o, const vec3f *d, const float *dist,
                                 int n, int target_is_background, vec3f *tr, int *first_pane);

/* The same as one number (the channels' mean), for the zone tracer's
 * scalar visibility. */
static inline float accel_transmittance_mean(const rscene *rs, vec3f o, vec3f d, float dist,
                                             int target_is_background)
{
    if (!rs->pane_count)
        return accel_occluded(rs, o, d, dist, target_is_background) ? 0.0f : 1.0f;
    vec3f t = accel_transmittance(rs, o, d, dist, target_is_background);
    return (t.x + t.y + t.z) * (1.0f / 3.0f);
}

#endif
