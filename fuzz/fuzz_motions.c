/* The motions loader on arbitrary text, then its check against a scene,
 * the motions applied at a few times and the camera path evaluated at
 * its keys and between them. */
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "zonetrace/motion.h"
#include "zonetrace/scene.h"

static const char scene_text[] =
    "{\"scene\": [\n"
    " {\"lightsphere\": {\"center\": [0, 5, 0], \"radius\": 1, \"emission\": [4, 4, 4]}},\n"
    " {\"lightpoint\": {\"point\": [2, 5, 0], \"emission\": [9, 9, 9]}},\n"
    " {\"thing\": {\"parts\": [{\"sphere\": {\"center\": [0, 1, 0], \"radius\": 1}},\n"
    "   {\"triangle\": {\"points\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}}]}},\n"
    " {\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0}}],\n"
    " \"camera\": {\"viewpoint\": [0, 2, -8],\n"
    "   \"screen\": [[-1, 3, -7], [1, 3, -7], [-1, 1, -7], [1, 1, -7]],\n"
    "   \"gridresolution\": [8, 8]}}\n";

static zt_scene *base_scene(void)
{
    static zt_scene *scene;
    if (!scene) {
        zt_error err;
        if (zt_scene_load_string(scene_text, strlen(scene_text), "fuzz_scene.json", &scene,
                                 &err) != ZT_OK)
            abort();
    }
    return scene;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    zt_scene *scene0 = base_scene();
    zt_motions *m = NULL;
    zt_error err;
    zt_error_clear(&err);
    if (zt_motions_load_string((const char *)data, size, "fuzz.json", &m, &err) != ZT_OK) {
        if (!err.message[0])
            abort();
        return 0;
    }
    if (zt_motions_check(m, scene0, &err) == ZT_OK) {
        zt_scene *s = zt_scene_clone(scene0);
        static const double times[] = {0, 0.5, 7.25, 60};
        for (int i = 0; s && i < 4; i++)
            zt_motions_apply(m, scene0, times[i], 1, s, &err);
        zt_scene_release(s);
    }
    int n = 0;
    const zt_camera_key *k = zt_motions_camera_path(m, &n);
    for (int i = 0; i < n && i < 16; i++) {
        zt_camera cam;
        double t[2] = {k[i].time, i + 1 < n ? 0.5 * (k[i].time + k[i + 1].time) : k[i].time + 1};
        for (int j = 0; j < 2; j++) {
            zt_error_clear(&err);
            if (zt_motions_camera(m, scene0, t[j], &cam, &err) != ZT_OK && !err.message[0])
                abort();
        }
    }
    zt_motions_release(m);
    return 0;
}
