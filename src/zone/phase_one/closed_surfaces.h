/* Which triangles lie on a closed piece of surface: a thing's triangles, or
 * a mesh's, split into pieces that share vertices; a piece is closed when
 * every edge of it is shared by exactly two of its triangles, once in each
 * direction (a consistently wound closed surface).  From outside such a surface only its front faces
 * show, so a node that sees its back faces in most directions is inside it
 * (node_life.c), whether the surface is backculled or not: a box standing
 * on the floor hides the floor's nodes under it, which else were read with
 * no light beside the lit nodes just outside, and darkened the floor along
 * the box's foot. */
#ifndef ZT_ZONE_PHASE_ONE_CLOSED_SURFACES_H
#define ZT_ZONE_PHASE_ONE_CLOSED_SURFACES_H

#include <stdint.h>

#include "render/render_scene.h"
#include "scene/scene.h"

typedef struct closed_surfaces {
    uint8_t *prim;      /* per primitive: on a closed piece */
} closed_surfaces;

/* Finds them; 0 when out of memory (then none is closed). */
int closed_surfaces_find(closed_surfaces *cs, const zt_scene *sc, const rscene *rs);

/* Whether primitive prim belongs to a closed surface. */
int closed_surfaces_has(const closed_surfaces *cs, int prim);

void closed_surfaces_free(closed_surfaces *cs);

#endif
