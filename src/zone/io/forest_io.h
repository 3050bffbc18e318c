/* The forest on disk: a versioned little-endian binary file holding what
 * Phase One computes (zones, the nodes' irradiance), tied to the scene and
 * to the options that shape the forest by hashes.  The format is
 * documented in docs/zone-tracer.md ("The forest file"). */
#ifndef ZT_ZONE_FOREST_IO_H
#define ZT_ZONE_FOREST_IO_H

#include "zone/zone.h"

/* 12: the forest of nodes (docs/zone-tracer.md): zones per surface, lobe
 * and level, and the irradiance of every node. */
/* 14: the same fields; level 0 under a sky takes window panes as portals
 * (light/sky_portals.h), so levels made before differ. */
/* 15: the caustic photons.  16: the same fields; a mesh node takes a
 * quarter of the sky's and the gather's directions (light/sky_gather.h),
 * so levels made before differ. */
#define FOREST_FILE_VERSION 16

/* Writes f (the forest of renderer r) to path, through a temporary file
 * renamed into place. */
zt_status forest_save(const zone_forest *f, const zt_renderer *r, const char *path,
                      zt_error *err);

/* Reads the forest for renderer r (its scene and options) from path into f
 * (zeroed).  expect holds the quality settings r would build with: the
 * file's must match in everything but the texel size, which depends on the
 * camera the forest was built with and is taken from the file. */
zt_status forest_load(zone_forest *f, const zt_renderer *r, const zone_quality *expect,
                      const char *path, zt_error *err);

/* Bytes held by the zones, the nodes, their irradiance and the occluder
 * index. */
uint64_t forest_memory(const zone_forest *f);

#endif
