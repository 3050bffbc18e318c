#include "zone/phase_one/specular_targets.h"

#include <math.h>
#include <stdlib.h>

#include "geom/shapes.h"
#include "render/prim.h"
#include "scene/mesh.h"
#include "util/vec3_convert.h"

static int specular(const rs_object *m)
{
    return m->weight[LOBE_REFLECTING] > 0.0f || m->weight[LOBE_METALLIC] > 0.0f ||
           m->weight[LOBE_REFRACTIVE] > 0.0f;
}

int specular_target_part(const rscene *rs, int i)
{
    rs_part tmp;
    const rs_part *p = rs_prim(rs, i, &tmp);
    if (p->is_light || (p->shape != SHAPE_TRIANGLE && p->shape != SHAPE_SPHERE))
        return 0;
    return specular(&rs->objects[p->object]);
}

double specular_cone_omc(double r, double d)
{
    double s2 = (r / d) * (r / d);
    return s2 < 1e-3 ? 0.5 * s2 + 0.125 * s2 * s2 : 1.0 - sqrt(fmax(0.0, 1.0 - s2));
}

/* A sphere around a triangle or sphere part. */
void part_bounding_sphere(const rs_part *p, vec3 *c, double *r)
{
    if (p->shape == SHAPE_SPHERE) {
        *c = f3_to_v3(p->p0);
        *r = p->radius;
        return;
    }
    vec3 a = f3_to_v3(p->p0), b = v3_add(a, f3_to_v3(p->e1)), d = v3_add(a, f3_to_v3(p->e2));
    *c = v3_scale(v3_add(v3_add(a, b), d), 1.0 / 3.0);
    *r = fmax(v3_length(v3_sub(a, *c)), fmax(v3_length(v3_sub(b, *c)), v3_length(v3_sub(d, *c))));
}

int specular_targets_make(const rscene *rs, specular_target **out, int *unaimable)
{
    specular_target *tg = malloc(((size_t)rs->part_count + rs->mesh_count + 1) * sizeof *tg);
    if (!tg)
        return -1;
    int n = 0;
    if (unaimable)
        *unaimable = 0;
    for (int i = 0; i < rs->part_count; i++) {
        const rs_part *p = &rs->parts[i];
        if (specular_target_part(rs, i)) {
            tg[n].part = i;
            tg[n].mesh = -1;
            part_bounding_sphere(p, &tg[n].c, &tg[n].r);
            n++;
        } else if (unaimable && !p->is_light && specular(&rs->objects[p->object])) {
            *unaimable = 1;
        }
    }
    for (int k = 0; k < rs->mesh_count; k++) {
        const rs_mesh *mm = &rs->meshes[k];
        int any = 0;
        if (!mm->is_light)
            for (int s = 0; s < mm->m->slot_count && !any; s++)
                any = specular(&rs->objects[mm->object_base + s]);
        if (!any)
            continue;
        vec3 lo, hi;
        mesh_bounds(mm->m, &lo, &hi);
        tg[n].part = -1;
        tg[n].mesh = k;
        tg[n].c = v3_scale(v3_add(lo, hi), 0.5);
        tg[n].r = 0.5 * v3_length(v3_sub(hi, lo)) * 1.0001;
        n++;
    }
    *out = tg;
    return n;
}

int specular_target_hit(const rscene *rs, const specular_target *tg, int prim)
{
    if (tg->part >= 0)
        return prim == tg->part;
    return prim >= rs->part_count && rs_mesh_of(rs, prim) == &rs->meshes[tg->mesh];
}
