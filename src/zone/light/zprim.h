/* A primitive's exact geometry for the zone tracer's closed forms, in
 * double precision: a part of the scene model as written, or a mesh
 * triangle (its single-precision vertices widened). */
#ifndef ZT_ZONE_LIGHT_ZPRIM_H
#define ZT_ZONE_LIGHT_ZPRIM_H

#include "render/render_scene.h"
#include "scene/scene.h"

typedef struct zprim {
    int shape;          /* part_shape */
    vec3 p[3];          /* triangle vertices; sphere centre and point in p[0] */
    double radius;      /* sphere */
    vec3 normal;        /* plane: unit normal, the plane is normal . x = offset */
    double offset;
    int culled, background, is_light;
    int object;         /* rs->objects index */
} zprim;

void zprim_get(const zt_scene *sc, const rscene *rs, int prim, zprim *out);

#endif
