/* A cut through a sender tree (sender_tree.h) for one receiver, as
 * Lightcuts (Walter et al. 2005) chooses lights: start at the root; while
 * some cluster's bound on what it can contribute exceeds eps times the
 * total found so far, replace the worst by its children.  A cluster in the
 * cut sends its flux from its centroid with the cosines of its vector
 * flux, if a ray from the receiver reaches the centroid; the elements a
 * cut reaches are taken by the caller's leaf function (exactly).  Sums and
 * choices follow a fixed order: the same result on every run. */
#ifndef ZT_ZONE_TRANSFER_CUT_H
#define ZT_ZONE_TRANSFER_CUT_H

#include <stdint.h>

#include "zone/transfer/sender_tree.h"

typedef struct cut_stats {
    uint64_t rays;
    uint64_t clusters;  /* clusters and elements evaluated */
    uint64_t capped;    /* cuts stopped by max_cut, not by eps */
} cut_stats;

/* Adds element i's exact contribution at (x, n) to acc. */
typedef void (*cut_leaf_fn)(void *user, int i, vec3 x, vec3 n, double acc[3], cut_stats *st);

typedef struct cut_params {
    double eps;         /* a cluster may err by this share of the total */
    double floor;       /* irradiance below which no more is refined */
    int max_cut;        /* clusters opened at most (clusters that cannot
                           be estimated, near the receiver, are always
                           opened) */
    cut_leaf_fn leaf;
    void *user;
} cut_params;

/* Irradiance at x (unit normal n, rays leave from xo) from the tree's
 * filled light. */
vec3 cut_gather(const sender_tree *t, const rscene *rs, vec3 x, vec3 n, vec3f xo,
                const cut_params *p, cut_stats *st);

/* Whether the straight path from xo to `to` is open (a ray, counted). */
int cut_visible(const rscene *rs, vec3f xo, vec3 to, int background, cut_stats *st);

#endif
