/* Every scene we ship, and every scene of the original programs, renders
 * to a finite, non-black image with the path tracer and with the zone
 * tracer (small and quick: this is a smoke test, run under the sanitizers
 * too; accuracy is tested elsewhere). */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zonetrace/zonetrace.h"

static int render_dir(const char *dir, zt_method method)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    struct dirent *e;
    int count = 0;
    while ((e = readdir(d))) {
        const char *dot = strrchr(e->d_name, '.');
        if (!dot || strcmp(dot, ".json") || strstr(e->d_name, "motions"))
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        zt_scene *s = NULL;
        zt_error err;
        zt_error_clear(&err);
        if (zt_scene_load_file(path, &s, &err) != ZT_OK) {
            /* The model scenes need Debian's assimp-testmodels. */
            if (err.status == ZT_ERR_READ && strstr(err.message, "/usr/share/assimp")) {
                printf("  %-40s skipped: %s\n", e->d_name, err.message);
                continue;
            }
            fail_msg("%s", err.message);
        }
        zt_scene_info info;
        zt_scene_get_info(s, &info);
        if (method == ZT_METHOD_ZONE && info.mesh_triangles > 20000) {
            /* The zone tracer's Phase One on a 100k-triangle model takes
             * minutes (docs/zone-tracer.md, "Large meshes"): not a smoke
             * test's job. */
            printf("  %-40s zone skipped: %lld mesh triangles\n", e->d_name, info.mesh_triangles);
            zt_scene_release(s);
            continue;
        }
        zt_camera c = zt_scene_get_camera(s);
        int size = method == ZT_METHOD_ZONE ? 16 : 24;
        assert_int_equal(zt_camera_set_resolution(&c, size, size, NULL), ZT_OK);
        zt_scene_set_camera(s, &c);
        zt_render_options o = zt_render_options_default();
        o.spp = 4;
        o.method = method;
        if (method == ZT_METHOD_ZONE) {
            o.depth = 2;
            o.quality = 0;
        }
        zt_image *img = NULL;
        if (zt_render(s, &o, &img, NULL, &err) != ZT_OK)
            fail_msg("%s: %s", path, err.message);
        double sum = 0;
        int n = size * size * 3;
        for (int i = 0; i < n; i++) {
            /* The zone tracer does not clamp extrapolated map reads (so
             * that single lights add up): a little below zero is allowed. */
            float floor_v = method == ZT_METHOD_ZONE ? -1e-2f : 0.0f;
            if (!isfinite(img->pixels[i]) || img->pixels[i] < floor_v)
                fail_msg("%s: pixel value %g", path, img->pixels[i]);
            sum += img->pixels[i];
        }
        printf("  %-40s %s mean %.4g\n", e->d_name, method == ZT_METHOD_ZONE ? "zone" : "path",
               sum / n);
        if (!(sum > 0))
            fail_msg("%s renders black", path);
        zt_image_release(img);
        zt_scene_release(s);
        count++;
    }
    closedir(d);
    return count;
}

static void test_project_scenes(void **state)
{
    (void)state;
    assert_true(render_dir(ZT_SOURCE_DIR "/scenes", ZT_METHOD_PATH) >= 3);
    assert_true(render_dir(ZT_SOURCE_DIR "/scenes", ZT_METHOD_ZONE) >= 3);
}

static void test_original_scenes(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    if (!shared)
        skip();
    char dir[1024];
    for (int m = 0; m < 2; m++) {
        zt_method method = m ? ZT_METHOD_ZONE : ZT_METHOD_PATH;
        snprintf(dir, sizeof dir, "%s/scenes/retra", shared);
        assert_int_equal(render_dir(dir, method), 13);
        snprintf(dir, sizeof dir, "%s/scenes/silence", shared);
        assert_int_equal(render_dir(dir, method), 11);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_project_scenes),
        cmocka_unit_test(test_original_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
