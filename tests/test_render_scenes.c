/* Every scene we ship, and every scene of the original programs, renders
 * to a finite, non-black image with the path tracer (small and quick). */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zonetrace/zonetrace.h"

static int render_dir(const char *dir)
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
        if (zt_scene_load_file(path, &s, &err) != ZT_OK)
            fail_msg("%s", err.message);
        zt_camera c = zt_scene_get_camera(s);
        assert_int_equal(zt_camera_set_resolution(&c, 24, 24, NULL), ZT_OK);
        zt_scene_set_camera(s, &c);
        zt_render_options o = zt_render_options_default();
        o.spp = 4;
        zt_image *img = NULL;
        if (zt_render(s, &o, &img, NULL, &err) != ZT_OK)
            fail_msg("%s: %s", path, err.message);
        double sum = 0;
        for (int i = 0; i < 24 * 24 * 3; i++) {
            if (!isfinite(img->pixels[i]) || img->pixels[i] < 0)
                fail_msg("%s: pixel value %g", path, img->pixels[i]);
            sum += img->pixels[i];
        }
        printf("  %-40s mean %.4g\n", e->d_name, sum / (24 * 24 * 3));
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
    assert_true(render_dir(ZT_SOURCE_DIR "/scenes") >= 3);
}

static void test_original_scenes(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    if (!shared)
        skip();
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/scenes/retra", shared);
    assert_int_equal(render_dir(dir), 13);
    snprintf(dir, sizeof dir, "%s/scenes/silence", shared);
    assert_int_equal(render_dir(dir), 11);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_project_scenes),
        cmocka_unit_test(test_original_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
