/* The motions list inside the library: what zt_motions_load_* builds and
 * zt_motions_apply evaluates (include/zonetrace/motion.h). */
#ifndef ZT_SCENE_MOTIONS_H
#define ZT_SCENE_MOTIONS_H

#include <pthread.h>
#include <stdint.h>

#include "zonetrace/motion.h"
#include "scene/camera_path.h"

/* Brownian motions are random walks of fixed 10 ms steps: evaluating one at
 * time t sums t/10ms steps.  The last sum is kept so that a viewer or an
 * animation, whose times grow, only adds the new steps; the sum is the same
 * as one computed from scratch (same steps, same order). */
typedef struct motion_walk {
    uint64_t seed;
    int64_t steps;      /* steps summed so far (0: none) */
    double sum[3];      /* sum of their unit directions */
} motion_walk;

struct zt_motions {
    char *name;          /* file name for messages */
    zt_motion *items;
    int count;
    motion_walk *walks;  /* one per motion (used by brownian ones) */
    pthread_mutex_t lock; /* guards walks */
    camera_path path;    /* count 0: no camera path */
};

/* The length of one brownian step in seconds. */
#define MOTION_BROWNIAN_STEP 0.01

/* Walks are summed step by step, so they are evaluated up to 10^6 s (about
 * 11.6 days, 10^8 steps, a few seconds of work the first time). */
#define MOTION_BROWNIAN_MAX_TIME 1e6

/* Unit direction of step `step` of brownian motion `index` for seed:
 * uniformly distributed on the sphere. */
void motion_brownian_direction(uint64_t seed, int index, int64_t step,
                               double out[3]);

#endif
