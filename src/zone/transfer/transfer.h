/* Diffuse light from surface to point: the irradiance one level's light
 * (a filled sender_tree) delivers at a point.
 *
 * For each receiver a cut through the tree is chosen (cut.h).  An element
 * the cut reaches is taken exactly: Lambert's
 * formula over its polygon (clipped to the receiver's horizon), split into
 * smaller pieces with their own rays while it looks large (size over
 * distance above theta).  No direction is sampled: the result is the same
 * on every run, and eps and theta are the quality knobs. */
#ifndef ZT_ZONE_PHASE_ONE_TRANSFER_H
#define ZT_ZONE_PHASE_ONE_TRANSFER_H

#include <stdint.h>

#include "zone/transfer/cut.h"

typedef struct transfer_ctx {
    const sender_tree *tree;
    const surface_nodes *sn;
    const rscene *rs;
    const float *e;     /* the level's node irradiance (for element corners) */
    double eps;         /* a cluster may err by this share of the total */
    double theta;       /* an element is split while size/distance exceeds it */
    double floor;       /* irradiance below which no more is refined */
    int max_cut;        /* clusters in a cut at most (elements near the
                           receiver are always refined) */
} transfer_ctx;

typedef cut_stats transfer_stats;

/* Irradiance at x (unit normal n) from the tree's light.  receiver is the
 * primitive x lies on (-1: none).  The cut is kept in rec (NULL: not). */
vec3 transfer_irradiance(const transfer_ctx *c, vec3 x, vec3 n, int receiver,
                         transfer_stats *st, cut_record *rec);

/* The same at a receiver near the one whose cut `from` is, starting from
 * that cut and opening at most `more` clusters of its own (cut_resume). */
vec3 transfer_irradiance_near(const transfer_ctx *c, vec3 x, vec3 n, const cut_record *from,
                              int more, transfer_stats *st);

#endif
