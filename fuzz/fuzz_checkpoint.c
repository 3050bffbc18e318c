/* The checkpoint reader on arbitrary files: a path-traced render of
 * fuzz/forest_scene.json at 8 x 8 resumed from the input, with at most 4
 * samples per pixel.  The seed (make_seeds.sh) is that render's checkpoint
 * after 2 samples, so its key matches and the fuzzer reaches the sums. */
#include <stdlib.h>

#include "fuzz.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

/* The small scene at 8 x 8, as the seed was rendered. */
static zt_scene *base_scene(void)
{
    static zt_scene *scene;
    if (!scene) {
        zt_error err;
        scene = zt_scene_clone(fuzz_small_scene());
        if (!scene)
            abort();
        zt_camera cam = zt_scene_get_camera(scene);
        if (zt_camera_set_resolution(&cam, 8, 8, &err) != ZT_OK)
            abort();
        zt_scene_set_camera(scene, &cam);
    }
    return scene;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    zt_render_options o = zt_render_options_default();
    o.spp = 4;
    o.depth = 2;
    o.threads = 1;
    /* The render writes its checkpoint back: into the scratch file. */
    o.checkpoint_file = fuzz_scratch_file(data, size, ".ckpt");
    o.resume = 1;
    zt_image *img = NULL;
    zt_error err;
    zt_error_clear(&err);
    if (zt_render(base_scene(), &o, &img, NULL, &err) == ZT_OK)
        zt_image_release(img);
    else if (!err.message[0])
        abort();
    return 0;
}
