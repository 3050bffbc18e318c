#include "zone/light/zprim.h"

#include "render/prim.h"
#include "util/vec3_convert.h"

void zprim_get(const zt_scene *sc, const rscene *rs, int prim, zprim *out)
{
    if (prim < rs->part_count) {
        const part *p = &sc->parts[prim];
        const object *o = &sc->objects[p->object];
        out->shape = p->shape;
        for (int k = 0; k < 3; k++)
            out->p[k] = p->p[k];
        out->radius = p->radius;
        out->normal = p->normal;
        out->offset = p->offset;
        out->culled = o->backculled;
        out->background = o->background;
        out->is_light = o->is_light;
        out->object = p->object;
        return;
    }
    const rs_mesh *mm = rs_mesh_of(rs, prim);
    const uint32_t *v = rs_mesh_tri(mm, prim);
    out->shape = SHAPE_TRIANGLE;
    for (int k = 0; k < 3; k++)
        out->p[k] = f3_to_v3(rs_mesh_vertex(mm, v[k]));
    out->radius = 0;
    out->normal = v3(0, 0, 0);
    out->offset = 0;
    out->culled = mm->culled;
    out->background = mm->background;
    out->object = rs_mesh_object(mm, prim);
    out->is_light = rs->objects[out->object].is_light;
}
