/* The pinhole camera of the scene format: rays start on the screen (a near
 * plane) and point away from the viewpoint. */
#ifndef ZT_CAMERA_CAMERA_H
#define ZT_CAMERA_CAMERA_H

#include "zonetrace/scene.h"
#include "util/vec3f.h"

typedef struct cam {
    vec3f viewpoint;
    vec3f top_left;
    vec3f to_screen; /* top-left minus viewpoint, rounded once from double:
                        the screen may be tiny next to the viewpoint's
                        coordinates (an aimed camera far from the origin) */
    vec3f right;   /* top-right minus top-left: the whole screen width */
    vec3f down;    /* bottom-left minus top-left: the whole screen height */
    int width, height;
} cam;

void cam_init(cam *c, const zt_camera *camera);

/* The ray through image position (px, py), in pixels from the top-left
 * corner of the image (pixel (x, y) covers [x, x+1) x [y, y+1)). */
static inline void cam_ray(const cam *c, float px, float py, vec3f *origin,
                           vec3f *dir)
{
    vec3f rel = f3_add(c->to_screen,
                       f3_add(f3_scale(c->right, px / (float)c->width),
                              f3_scale(c->down, py / (float)c->height)));
    *origin = f3_add(c->viewpoint, rel);
    *dir = f3_normalize(rel);
}

#endif
