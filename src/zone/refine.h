/* Exact irradiance where a map's bilinear read cannot follow the light
 * (crossings, steep texel steps), kept as detail windows (refine.c). */
#ifndef ZT_ZONE_REFINE_H
#define ZT_ZONE_REFINE_H

#include "zone/zone_internal.h"

/* Adds the refinement windows of one level to the maps, once that level's
 * texels and tables are built and before the next level is; a no-op below
 * the quality that asks for it or where a map holds more than transfer.
 * Returns 0 when out of memory. */
int refine_level(zone_forest *f, const zt_renderer *r, int level);

/* Frees E_0's windows once every level is built: only the transfer reads
 * them. */
void refine_drop_level0(zone_forest *f);

#endif
