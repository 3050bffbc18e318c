/* Caustic photons kept as points, to read a caustic at a camera sample
 * by density estimation instead of from the nodes.
 *
 * Phase One deposits each caustic photon's flux on the nodes around it
 * (caustic.c), which blurs a caustic over about a node spacing: the
 * bright cusp under a glass ball is a few node spacings wide.  The same
 * photons kept here give the camera's samples the caustic at the
 * resolution of the photons themselves: the irradiance at x is the flux
 * of the k photons nearest to x on the same surface, weighed by a kernel
 * over the disc that holds them (k nearest neighbours, Jensen 1996).  The
 * nodes keep the photons' light for everything else (the transfer, the
 * gathers), so the caustic read at a sample replaces only the nodes'
 * caustic part there (zone_caustic_read, forest.c).
 *
 * The photons of each level and surface form a k-d tree of their own,
 * built in place (median splits on the box's longest axis) from the
 * photons in the order they were traced, which is the same at any thread
 * count: the same trees, and the same image.  A search reaches no farther than a radius the caller
 * gives (about the nodes' spacing, where the nodes' own estimate is as
 * sharp): fewer than k photons within it are taken over that disc. */
#ifndef ZT_ZONE_MAPS_PHOTON_MAP_H
#define ZT_ZONE_MAPS_PHOTON_MAP_H

#include <stddef.h>
#include <stdint.h>

#include "util/vec3.h"

/* One photon where it met a diffuse surface (32 bytes). */
typedef struct zone_photon {
    float x[3];
    float flux[3];      /* W, per channel */
    int32_t surface;    /* zone_surface_of its primitive */
    int8_t n[3];        /* the side it arrived on: its unit normal x 127 */
    uint8_t level;      /* specular events before it (>= 1) */
} zone_photon;

/* One tree: the photons of one level on one surface. */
typedef struct photon_group {
    int32_t level, surface;
    size_t first, count;    /* its photons, in tree order */
} photon_group;

typedef struct photon_map {
    zone_photon *p;
    size_t count, capacity;
    /* After photon_map_build: groups ascending by (level, surface);
     * axis[i] the split axis at median i of its tree. */
    photon_group *group;
    int group_count;
    uint8_t *axis;
} photon_map;

/* Photons the density estimate takes at a point at least (fewer only where
 * fewer lie within the reach): its noise is about 1 / sqrt(k).  On a glass
 * ball's caustic at quality 2 (tests/test_zone_caustic.c) 128, 256 and 512
 * gave a mean error of 3.9%, 3.4% and 1.8% along a line through it, the
 * worst point 22%, 16% and 5%; the images of materials.json and
 * cornell_rough.json moved by less than 0.02 points, Phase Two's time on
 * cornell_rough by 12% from 128 to 512. */
#define PHOTON_MAP_K 512

/* Appends a photon; returns 0 when out of memory. */
int photon_map_add(photon_map *m, const zone_photon *p);

/* The photons of parts[0..count), in that order, into m's trees (m is
 * emptied first and must not be one of the parts), each part's photons
 * freed once taken: photons by level (below `levels`) and surface (below
 * `surfaces`), each group in the parts' order, then each group a tree.
 * The same parts in the same order give the same trees.  Returns 0 when
 * out of memory. */
int photon_map_build(photon_map *m, photon_map *parts, int count, int levels, int surfaces);

/* Takes photons and axes already in tree order (read back from a forest
 * file): finds the groups.  Returns 1, 0 when they are not in order (the
 * file is corrupt), -1 when out of memory. */
int photon_map_adopt(photon_map *m);

/* The irradiance at x (facing normal nf) on `surface` of the photons of
 * `level`: the PHOTON_MAP_K nearest on the same surface and side within
 * r_max, weighed by Epanechnikov's kernel over the disc that reaches the
 * k-th (or the disc of radius r_max, when fewer lie within it); where
 * they lie closer than r_min (or r_max, if smaller), every photon within
 * it over that disc (a pixel's footprint: what the image can show). */
vec3 photon_map_irradiance(const photon_map *m, int level, int surface, vec3 x, vec3 nf,
                           double r_min, double r_max);

void photon_map_free(photon_map *m);

#endif
