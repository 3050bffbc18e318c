/* The forest on disk: a versioned little-endian binary file holding what
 * Phase One computes (zones, occluder lists, irradiance maps), tied to the
 * scene and to the options that shape the forest by hashes.  The format is
 * documented in docs/zone-tracer.md ("The forest file"). */
#ifndef ZT_ZONE_FOREST_IO_H
#define ZT_ZONE_FOREST_IO_H

#include "zone/zone_internal.h"

/* 8: the layout of 7; its quality-5 windows follow new rules (kinks
 * refined, fine cells read apart across crossings), so a forest of 7
 * would not render what a build of 8 would.  9: the same layout, fine
 * cells measured against texels made at their own piece size.  10:
 * windows around the ends of crossings, and a window's coarse texels
 * stored only after a flag.  11: the second values of refinement cells
 * a crossing passes through, after a flag (docs/zone-tracer.md). */
#define FOREST_FILE_VERSION 11

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

/* 64-bit FNV-1a of the scene's geometry, materials, lights and sky (not
 * the camera). */
uint64_t forest_scene_hash(const zt_scene *sc);

/* Bytes held by the zones, the occluder lists and the maps. */
void forest_memory(const zone_forest *f, uint64_t *zones, uint64_t *occluders,
                   uint64_t *maps);

#endif
