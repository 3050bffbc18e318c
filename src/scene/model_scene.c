/* A model file alone as a scene: the model as one thing with its own
 * materials, under a white sky, seen by the file's camera or by one that
 * frames the model from three quarters above. */
#include "scene/model_scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/model_import.h"
#include "util/error.h"

#define MODEL_WIDTH 640
#define MODEL_HEIGHT 480
#define MODEL_FOV 40.0

/* The automatic camera: the model's bounding sphere fills the view, seen
 * from the front-right, 30 degrees above (+y is up, as in glTF). */
static zt_status frame_model(const mesh *m, zt_camera *cam, zt_error *err)
{
    vec3 lo, hi;
    mesh_bounds(m, &lo, &hi);
    vec3 c = v3_scale(v3_add(lo, hi), 0.5);
    double r = 0.5 * v3_length(v3_sub(hi, lo));
    if (!(r > 0))
        r = 1;
    double az = 35.0 * 3.14159265358979323846 / 180.0, el = 30.0 * 3.14159265358979323846 / 180.0;
    vec3 dir = v3(sin(az) * cos(el), sin(el), cos(az) * cos(el));
    /* Far enough for the sphere to fit the narrower (vertical) field. */
    double dist = 1.1 * r / sin(0.5 * MODEL_FOV * 3.14159265358979323846 / 180.0);
    double pos[3], at[3], up[3] = {0, 1, 0};
    v3_store(v3_add(c, v3_scale(dir, dist)), pos);
    v3_store(c, at);
    return zt_camera_look_at(cam, pos, at, up, MODEL_FOV, MODEL_WIDTH, MODEL_HEIGHT, err);
}

zt_status scene_from_model(const char *path, zt_scene **out, zt_error *err)
{
    *out = NULL;
    model_import_options opt = {.smooth = 1};
    model_camera mc;
    memset(&mc, 0, sizeof mc);
    mesh *m = NULL;
    zt_status st = model_import(path, &opt, &m, &mc, err);
    if (st != ZT_OK)
        return st;
    snprintf(m->file, sizeof m->file, "%s", path);
    zt_scene *scene = scene_create();
    object o;
    memset(&o, 0, sizeof o);
    o.mat = material_default();
    if (!scene || scene_add_mesh_object(scene, &o, m) < 0) {
        mesh_release(m);
        zt_scene_release(scene);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
    }
    scene->sky = v3(1, 1, 1);
    scene->has_sky = 1;
    zt_camera cam;
    memset(&cam, 0, sizeof cam);
    zt_error cerr;
    zt_error_clear(&cerr);
    st = ZT_ERR_ARGUMENT;
    if (mc.present) {
        double pos[3], at[3], up[3];
        /* The file gives a direction; aim at the model's centre depth so the
         * screen (the near plane) sits well inside the float range. */
        vec3 lo, hi, d = v3_sub(mc.lookat, mc.position);
        mesh_bounds(m, &lo, &hi);
        double dl = v3_length(d), depth = v3_dot(v3_sub(v3_scale(v3_add(lo, hi), 0.5),
                                                        mc.position), d);
        vec3 eye = mc.position;
        if (dl > 0 && depth > 0) {
            /* A camera outside the model that does not see all of it steps
             * back along its line of sight until it does (files often keep
             * a close-up camera); one inside (an interior view) stays. */
            vec3 dir = v3_scale(d, 1.0 / dl);
            double r = 0.5 * v3_length(v3_sub(hi, lo)), aspect = mc.aspect > 0 ? mc.aspect : 1;
            double half = 0.5 * mc.fov * 3.14159265358979323846 / 180.0;
            double half_min = fmin(half, atan(tan(half) * aspect));
            double need = 1.05 * r / sin(half_min);
            int inside = eye.x > lo.x && eye.x < hi.x && eye.y > lo.y && eye.y < hi.y &&
                         eye.z > lo.z && eye.z < hi.z;
            depth /= dl;
            if (!inside && depth < need) {
                eye = v3_sub(eye, v3_scale(dir, need - depth));
                depth = need;
            }
            v3_store(eye, pos);
            v3_store(v3_add(eye, v3_scale(dir, depth)), at);
        } else {
            v3_store(mc.position, pos);
            v3_store(mc.lookat, at);
        }
        v3_store(mc.up, up);
        int h = mc.aspect > 0 ? (int)lround(MODEL_WIDTH / mc.aspect) : MODEL_HEIGHT;
        st = zt_camera_look_at(&cam, pos, at, up, mc.fov, MODEL_WIDTH, h < 1 ? 1 : h, &cerr);
    }
    if (st != ZT_OK)
        st = frame_model(m, &cam, &cerr);
    if (st != ZT_OK) {
        zt_scene_release(scene);
        return zt_fail(err, ZT_ERR_PARSE, "%s: no camera can frame the model: %s", path,
                       cerr.message);
    }
    zt_scene_set_camera(scene, &cam);
    *out = scene;
    return ZT_OK;
}
