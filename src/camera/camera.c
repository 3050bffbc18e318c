#include "camera/camera.h"

static vec3f from_d(const double v[3]) { return f3((float)v[0], (float)v[1], (float)v[2]); }

void cam_init(cam *c, const zt_camera *camera)
{
    c->viewpoint = from_d(camera->viewpoint);
    c->top_left = from_d(camera->screen[0]);
    c->right = f3_sub(from_d(camera->screen[1]), c->top_left);
    c->down = f3_sub(from_d(camera->screen[2]), c->top_left);
    c->width = camera->width;
    c->height = camera->height;
}
