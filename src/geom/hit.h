/* Rays and hits shared by the acceleration structures and the renderers. */
#ifndef ZT_GEOM_HIT_H
#define ZT_GEOM_HIT_H

#include "util/vec3f.h"

typedef struct ray {
    vec3f o, d;    /* d has unit length */
    float tmax;
} ray;

typedef struct hit {
    float t;
    int part;      /* -1: nothing was hit */
} hit;

#endif
