/* Exact irradiance where a map's bilinear read cannot follow the light
 * (crossings, steep texel steps), kept as detail windows (refine.c). */
#ifndef ZT_ZONE_REFINE_H
#define ZT_ZONE_REFINE_H

#include "zone/zone_internal.h"

/* Adds the refinement windows to the maps of levels 1 and up, after every
 * level is built; a no-op below the quality that asks for it or where a
 * map holds more than transfer.  Returns 0 when out of memory. */
int refine_build(zone_forest *f, const zt_renderer *r);

#endif
