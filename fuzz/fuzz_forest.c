/* The forest file reader on arbitrary files: a zone renderer for the
 * scene fuzz/forest_scene.json made with the forest read from the input,
 * then, when it is accepted, one small image rendered from it.  The seed
 * (scripts in fuzz/run.sh) is that scene's forest at depth 2, quality 0. */
#include <stdlib.h>

#include "fuzz.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    zt_scene *scene = fuzz_small_scene();
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 2;
    o.quality = 0;
    o.threads = 1;
    o.forest_file = fuzz_scratch_file(data, size, ".ztf");
    zt_renderer *r = NULL;
    zt_error err;
    zt_error_clear(&err);
    if (zt_renderer_create(scene, &o, &r, &err) == ZT_OK) {
        zt_image *sum = zt_image_create(8, 8);
        zt_camera cam = zt_scene_get_camera(scene);
        zt_camera_set_resolution(&cam, 8, 8, &err);
        if (sum && zt_renderer_set_camera(r, &cam, &err) == ZT_OK)
            zt_renderer_accumulate(r, 0, 1, sum, NULL, &err);
        zt_image_release(sum);
        zt_renderer_release(r);
    } else if (!err.message[0]) {
        abort();
    }
    return 0;
}
