/* A render split over processes (zt_share): which units of work are this
 * process's, and the exchanges between the processes.  Without a share
 * (or with one rank) every unit is ours and the exchanges do nothing. */
#ifndef ZT_RENDER_SHARE_H
#define ZT_RENDER_SHARE_H

#include <stddef.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

int share_ranks(const zt_render_options *o);
int share_rank(const zt_render_options *o);

/* Whether work unit `unit` (0, 1, 2, ...) is this process's: units are
 * dealt out by a hash of their number, so neighbours, which cost alike,
 * are spread over the processes, and each gets about 1/ranks of them. */
int share_owns(const zt_render_options *o, long long unit);

/* How many of units 0 .. count-1 are this process's. */
long long share_owned(const zt_render_options *o, long long count);

/* zt_share's merge: every byte of buf written by one process (0 on the
 * others) or equal on all becomes what was written, on every process. */
zt_status share_merge(const zt_render_options *o, void *buf, size_t bytes, zt_error *err);

/* Every process's n values, rank by rank, into all[ranks * n]. */
zt_status share_all(const zt_render_options *o, const double *mine, int n, double *all,
                    zt_error *err);

/* x[i] becomes the largest of every process's x[i] (so: a flag any process
 * set), or their sum. */
zt_status share_max(const zt_render_options *o, double *x, int n, zt_error *err);
zt_status share_sum(const zt_render_options *o, double *x, int n, zt_error *err);

/* Fails (on every process alike) unless all processes render the same
 * scene, camera and options: files that differ between nodes would give an
 * image of parts that do not fit. */
zt_status share_check_same(const zt_scene *scene, const zt_render_options *o, zt_error *err);

#endif
