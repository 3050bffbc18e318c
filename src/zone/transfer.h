/* Diffuse-to-point light transfer over the irradiance maps: what a point
 * receives from the level-k radiance of every flat diffuse surface.
 *
 * The source surface is split recursively (over its map's texels) until
 * each piece looks small from the receiver; each piece then contributes its
 * mean radiance (from summed-area tables of the map, so exact for the piece)
 * times its exact form factor (Lambert's formula over the piece's polygon,
 * clipped to the receiver's horizon), if a ray from the receiver reaches its
 * centre.  No direction is sampled, so nothing aliases but visibility; the
 * refinement threshold is the quality knob. */
#ifndef ZT_ZONE_TRANSFER_H
#define ZT_ZONE_TRANSFER_H

#include "zone/zone_internal.h"

/* What may hide a piece from a receiver (transfer.c); NULL when out of
 * memory. */
transfer_blockers *transfer_blockers_build(const zt_scene *sc);
void transfer_blockers_free(transfer_blockers *b);

/* Summed-area tables of one map level (weight*value and weight), for mean
 * values over texel rectangles in constant time. */
int transfer_build_tables(part_map *m, int level);

/* Irradiance at x (normal n, on part `receiver`) from the radiance of
 * level `level` (>= 1) leaving the flat diffuse parts, read from the maps
 * of level-1.  theta: a piece is split while its size over its distance
 * exceeds theta. */
vec3 transfer_irradiance(zone_trace *t, int receiver, vec3 x, vec3 n, int level,
                         double theta);

#endif
