/* The scene loader on arbitrary text: JSON and the original programs'
 * group syntax, every item kind, and the scene side of meshes (a model
 * named by a fuzzed scene is read from the working directory, if there). */
#include <stdlib.h>

#include "fuzz.h"
#include "zonetrace/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    zt_scene *scene = NULL;
    zt_error err;
    zt_error_clear(&err);
    if (zt_scene_load_string((const char *)data, size, "fuzz.json", &scene, &err) == ZT_OK) {
        zt_scene_info info;
        zt_scene_get_info(scene, &info);
        zt_scene *copy = zt_scene_clone(scene);
        zt_scene_release(copy);
    } else if (!err.message[0]) {
        abort(); /* every failure must say why */
    }
    zt_scene_release(scene);
    return 0;
}
