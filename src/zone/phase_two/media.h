/* Crossing a glass surface: the refracted direction, and the stack of the
 * refractive objects a ray is inside, by object identity (entering an
 * object pushes it, leaving pops it), so hollow shells and nested glass
 * work.  Shared by the radiance along rays and the caustic photons. */
#ifndef ZT_ZONE_MEDIA_H
#define ZT_ZONE_MEDIA_H

#include <math.h>

#include "render/render_scene.h"
#include "util/vec3f.h"

#define MEDIA_MAX 8 /* the deepest nesting followed */

/* The refracted direction of d at a surface with unit normal nf (facing
 * d's origin), cos_o = -d . nf, for the ratio eta = eta_i / eta_t. */
static inline vec3f media_refract(vec3f d, vec3f nf, float cos_o, float eta)
{
    float sin2 = eta * eta * (1.0f - cos_o * cos_o);
    float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin2));
    return f3_normalize(f3_sub(f3_scale(d, eta), f3_scale(nf, cos_t - eta * cos_o)));
}

/* At a surface of `object` (material m) met inside media[0..count): whether
 * the ray enters it, and the indices on its side (*eta_i) and beyond
 * (*eta_t). */
static inline int media_indices(const rscene *rs, const int *media, int count, int object,
                                const rs_object *m, float *eta_i, float *eta_t)
{
    int entering = count == 0 || media[count - 1] != object;
    *eta_i = count ? rs->objects[media[count - 1]].ior : 1.0f;
    *eta_t = entering ? m->ior : (count > 1 ? rs->objects[media[count - 2]].ior : 1.0f);
    return entering;
}

/* The stack after crossing object's surface: media[0..count) into next,
 * then object pushed (entering) or the top popped.  Returns the new count. */
static inline int media_cross(const int *media, int count, int object, int entering,
                              int next[MEDIA_MAX])
{
    int n = count;
    for (int i = 0; i < n && i < MEDIA_MAX; i++)
        next[i] = media[i];
    if (entering) {
        if (n < MEDIA_MAX)
            next[n++] = object;
    } else {
        n--;
    }
    return n;
}

#endif
