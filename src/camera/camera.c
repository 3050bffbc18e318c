#include "camera/camera.h"

static vec3f from_d(const double v[3]) { return f3((float)v[0], (float)v[1], (float)v[2]); }

void cam_init(cam *c, const zt_camera *camera)
{
    c->viewpoint = from_d(camera->viewpoint);
    c->top_left = from_d(camera->screen[0]);
    double rel[3], right[3], down[3];
    for (int a = 0; a < 3; a++) {
        rel[a] = camera->screen[0][a] - camera->viewpoint[a];
        right[a] = camera->screen[1][a] - camera->screen[0][a];
        down[a] = camera->screen[2][a] - camera->screen[0][a];
    }
    c->to_screen = from_d(rel);
    c->right = from_d(right);
    c->down = from_d(down);
    c->width = camera->width;
    c->height = camera->height;
}
