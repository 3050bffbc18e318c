/* Every scene shipped with Retra and Silence loads, with the object and
 * part counts of shared/spec/shipped-scenes.md and a few spot values.
 * Skipped when the shared folder is absent. */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/scene.h"
#include "zonetrace/scene.h"

typedef struct expected {
    const char *file;  /* repo/name under shared/scenes */
    int lights, light_parts, things, thing_parts;
    int width, height;
} expected;

static const expected shipped[] = {
    {"retra/caustics.json", 2, 2, 8, 39, 512, 512},
    {"retra/cornell.json", 2, 2, 25, 25, 512, 512},
    {"retra/cornell_puretriangles.json", 2, 2, 10, 10, 512, 512},
    {"retra/cornell_puretriangles_narrowlight.json", 2, 2, 10, 10, 512, 512},
    {"retra/cornell_puretriangles_widelight.json", 2, 2, 10, 10, 512, 512},
    {"retra/dancingLights.json", 3, 3, 7, 7, 512, 512},
    {"retra/demo.json", 2, 2, 8, 15, 512, 512},
    {"retra/demo_early.json", 2, 2, 8, 15, 200, 200},
    {"retra/demo_fullHD.json", 2, 2, 8, 15, 1920, 1080},
    {"retra/funky.json", 2, 2, 10, 10, 512, 512},
    {"retra/hollowglass.json", 1, 1, 7, 8, 512, 512},
    {"retra/largerballs.json", 1, 1, 7, 7, 512, 512},
    {"retra/triangletest.json", 1, 1, 16, 16, 512, 512},
    {"silence/caustics.json", 2, 2, 8, 39, 512, 512},
    {"silence/cornell.json", 2, 2, 25, 25, 512, 512},
    {"silence/cornell_puretriangles.json", 2, 2, 30, 30, 512, 512},
    {"silence/dancingLights.json", 3, 3, 7, 7, 512, 512},
    {"silence/demo.json", 2, 2, 8, 15, 512, 512},
    {"silence/demo_early.json", 2, 2, 8, 15, 200, 200},
    {"silence/demo_fullHD.json", 2, 2, 8, 15, 1920, 1080},
    {"silence/funky.json", 2, 2, 10, 10, 512, 512},
    {"silence/hollowglass.json", 1, 1, 7, 8, 512, 512},
    {"silence/largerballs.json", 1, 1, 7, 7, 512, 512},
    {"silence/triangletest.json", 1, 1, 16, 16, 512, 512},
};

static zt_scene *load_shipped(const char *shared, const char *file)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s", shared, file);
    zt_scene *s = NULL;
    zt_error err = {0};
    if (zt_scene_load_file(path, &s, &err) != ZT_OK)
        fail_msg("%s", err.message);
    return s;
}

static void test_counts(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    if (!shared)
        skip();
    for (size_t i = 0; i < sizeof shipped / sizeof shipped[0]; i++) {
        const expected *e = &shipped[i];
        zt_scene *s = load_shipped(shared, e->file);
        zt_scene_info info;
        zt_scene_get_info(s, &info);
        zt_camera cam = zt_scene_get_camera(s);
        if (info.lights != e->lights || info.light_parts != e->light_parts ||
            info.things != e->things || info.thing_parts != e->thing_parts ||
            cam.width != e->width || cam.height != e->height)
            fail_msg("%s: %d/%d lights, %d/%d things, %dx%d", e->file,
                     info.lights, info.light_parts, info.things,
                     info.thing_parts, cam.width, cam.height);
        zt_scene_release(s);
    }
}

/* No scene file of the originals is left out of the table above. */
static void test_every_file_listed(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    if (!shared)
        skip();
    static const char *const repos[] = {"retra", "silence"};
    for (int r = 0; r < 2; r++) {
        char dir[1024];
        snprintf(dir, sizeof dir, "%s/scenes/%s", shared, repos[r]);
        DIR *d = opendir(dir);
        assert_non_null(d);
        struct dirent *ent;
        while ((ent = readdir(d))) {
            size_t n = strlen(ent->d_name);
            if (n < 5 || strcmp(ent->d_name + n - 5, ".json") != 0 ||
                strstr(ent->d_name, "_motions.json"))
                continue;
            char file[512];
            snprintf(file, sizeof file, "%s/%s", repos[r], ent->d_name);
            int listed = 0;
            for (size_t i = 0; i < sizeof shipped / sizeof shipped[0]; i++)
                listed |= strcmp(shipped[i].file, file) == 0;
            if (!listed)
                fail_msg("%s is not in the table", file);
        }
        closedir(d);
    }
}

static void assert_near(double a, double b)
{
    if (fabs(a - b) > 1e-9 * fmax(1, fabs(b)))
        fail_msg("%.17g != %.17g", a, b);
}

static void test_spot_values(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    if (!shared)
        skip();

    /* Non-unit plane normals are normalised with their offsets. */
    zt_scene *s = load_shipped(shared, "retra/dancingLights.json");
    const object *wall = scene_find_object(s, ZT_OBJECT_THING, 1);
    const part *p = &s->parts[wall->first_part];
    double len = sqrt(1 + 0.16 + 0.04);
    assert_near(p->normal.x, 1 / len);
    assert_near(p->normal.y, 0.4 / len);
    assert_near(p->offset, -10 / len);
    const object *red = scene_find_object(s, ZT_OBJECT_LIGHT, 0);
    assert_near(red->emission.x, 1);
    assert_false(red->background);
    assert_false(red->backculled);
    zt_scene_release(s);

    /* The legacy group of the hollow glass shell. */
    s = load_shipped(shared, "silence/hollowglass.json");
    const object *shell = scene_find_object(s, ZT_OBJECT_THING, 1);
    assert_int_equal(shell->part_count, 2);
    assert_near(shell->mat.weight[LOBE_REFRACTIVE], 1);
    assert_near(shell->mat.ior, 1.4);
    assert_false(shell->backculled);
    assert_near(s->parts[shell->first_part + 1].radius, 3.9);
    zt_scene_release(s);

    /* The only sky, and a background light. */
    s = load_shipped(shared, "retra/triangletest.json");
    assert_int_equal(s->has_sky, 1);
    assert_near(s->sky.y, 0.05);
    zt_scene_release(s);
    s = load_shipped(shared, "retra/largerballs.json");
    assert_true(scene_find_object(s, ZT_OBJECT_LIGHT, 0)->background);
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counts),
        cmocka_unit_test(test_every_file_listed),
        cmocka_unit_test(test_spot_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
