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

/* Adds element i's exact contribution at (x, n) to acc.  whole is the
 * cut's estimate of the receiver's total when the element is opened (its
 * luminance; 0 where no estimate is at hand), for a leaf that spends
 * effort by its share. */
typedef void (*cut_leaf_fn)(void *user, int i, vec3 x, vec3 n, double whole, double acc[3],
                            cut_stats *st);

typedef struct cut_params {
    double eps;         /* a cluster may err by this share of the total */
    double floor;       /* irradiance below which no more is refined */
    int max_cut;        /* clusters opened at most (clusters that cannot
                           be estimated, near the receiver, are always
                           opened) */
    cut_leaf_fn leaf;
    void *user;
} cut_params;

/* A finished cut, for a nearby receiver to start from: its clusters with
 * the share of each that the receiver's rays saw (-1 or -2: none cast),
 * and the leaves it took exactly (CUT_EXACT). */
#define CUT_EXACT -3.0f
typedef struct cut_entry {
    int32_t node;
    float seen;
} cut_entry;

typedef struct cut_record {
    cut_entry *e;
    int n, cap;
    int failed;         /* not to be used: incomplete (out of memory), or
                           its owner's cut not made yet; cut_gather clears
                           it */
} cut_record;

/* Irradiance at x (unit normal n, rays leave from xo) from the tree's
 * filled light; the cut is left in rec (NULL: not kept). */
vec3 cut_gather(const sender_tree *t, const rscene *rs, vec3 x, vec3 n, vec3f xo,
                const cut_params *p, cut_stats *st, cut_record *rec);

/* The same at a receiver near the one `from` was made for: its clusters
 * estimated for this receiver, visible as far as that one saw them (rays
 * of its own where that one cast none), its exact leaves taken again here;
 * then refined as cut_gather does, opening at most p->max_cut more. */
vec3 cut_resume(const sender_tree *t, const rscene *rs, vec3 x, vec3 n, vec3f xo,
                const cut_record *from, const cut_params *p, cut_stats *st);

/* How open the straight path from xo to `to` is: 1 or 0, or a pane's
 * transmittance between (a ray, counted). */
double cut_visible(const rscene *rs, vec3f xo, vec3 to, int background, cut_stats *st);

#endif
