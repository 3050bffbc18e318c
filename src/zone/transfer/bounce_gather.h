/* A level's light at a node by gathering: the radiance of the level below
 * read from the forest along fixed directions, the other way of taking
 * the transfer (transfer.h).
 *
 * A cut (cut.h) bounds each cluster of senders by its power over its
 * nearest distance, without visibility: where light arrives from every
 * side, as under the sky, those bounds stay loose and the cut opens
 * clusters up to its limit.  A gather costs its directions whatever the
 * light, and is accurate where that light is smooth.  Each node therefore
 * takes the gather when the gather's own error estimate is within the
 * limit the cut would have to meet, and the cut otherwise. */
#ifndef ZT_ZONE_TRANSFER_BOUNCE_GATHER_H
#define ZT_ZONE_TRANSFER_BOUNCE_GATHER_H

#include "zone/zone.h"

/* n cosine-weighted directions about +z whose first 2^m, for every m, are
 * a (0, m, 2)-net (van der Corput's sequence and the second dimension of
 * Sobol's): a gather can stop after any power-of-two prefix and still
 * have cast a stratified set. */
vec3 *bounce_directions(int n);

/* The fewest of n_dirs that a node held to a div-th of the directions (a
 * mesh's node: ZONE_MESH_NODE_DIV) may stop at: n_dirs / div, but no
 * fewer than a gather needs for its first quarter's test (64), nor more
 * than n_dirs. */
int bounce_gather_count(int n_dirs, int div);

typedef struct bounce_limit {
    double eps;     /* the error allowed, as a share of ... */
    double lower;   /* ... the node's light of the levels below (luminance) */
    double floor;   /* and at least eps x this (the cut's floor) */
} bounce_limit;

/* The irradiance of level `level` at x (unit normal n) by gathering over
 * dirs[0..n_dirs): each direction reads the radiance of level `level`
 * along its ray (diffuse maps, specular chains; not glints or caustics,
 * which are taken apart).  A quarter of `least` first; then, at each
 * count cast, the gather stops when it has cast at least `least` and its
 * estimated error (pi times the samples' standard deviation over the
 * square root of the count) is within eps x max(lower + the estimate,
 * floor); else it goes on to the smallest of least, 4 least, ... n_dirs
 * at which the error it projects would be, and returns 0 when none would
 * (the cut is for this node).  1 with the irradiance in *e.  A node that
 * takes every direction has least = n_dirs: a quarter, then all or the
 * cut. */
int bounce_gather(zone_trace *t, const vec3 *dirs, int least, int n_dirs, vec3 x, vec3 n,
                  int level, const bounce_limit *lim, vec3 *e);

#endif
