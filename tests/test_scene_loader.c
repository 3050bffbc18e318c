/* The scene loader on good input: the project's scenes, field values,
 * defaults, plane normalisation, and the equivalence of the legacy group
 * syntax, its canonical form and any key order. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/scene.h"
#include "zonetrace/scene.h"

#define CAMERA "\"camera\": {\"viewpoint\": [0, 0, 20], " \
    "\"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], " \
    "\"gridresolution\": [64, 48]}"
#define DIFFUSE_WHITE "{\"character\": {\"diffuse\": 1, \"metallic\": 0, " \
    "\"reflecting\": 0, \"refractive\": 0}, \"color\": [1, 1, 1]}"
#define GLASS "{\"character\": {\"diffuse\": 0, \"metallic\": 0, " \
    "\"reflecting\": 0, \"refractive\": 1}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5}"

static zt_scene *load_text(const char *text)
{
    zt_scene *s = NULL;
    zt_error err = {0};
    zt_status st = zt_scene_load_string(text, strlen(text), "test.json", &s, &err);
    if (st != ZT_OK)
        fail_msg("unexpected failure: %s", err.message);
    assert_non_null(s);
    return s;
}

static zt_scene *load_project_scene(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s", ZT_SOURCE_DIR, name);
    zt_scene *s = NULL;
    zt_error err = {0};
    if (zt_scene_load_file(path, &s, &err) != ZT_OK)
        fail_msg("%s", err.message);
    return s;
}

static void assert_near(double a, double b)
{
    if (fabs(a - b) > 1e-12 * fmax(1, fabs(b)))
        fail_msg("%.17g != %.17g", a, b);
}

static void assert_vec(vec3 v, double x, double y, double z)
{
    assert_near(v.x, x);
    assert_near(v.y, y);
    assert_near(v.z, z);
}

static void assert_same_vec(vec3 a, vec3 b)
{
    assert_memory_equal(&a, &b, sizeof a);
}

/* Objects and parts equal in everything but the line they came from
 * (field by field: struct padding is not part of the value). */
static void assert_same_scene(const zt_scene *a, const zt_scene *b)
{
    assert_int_equal(a->object_count, b->object_count);
    assert_int_equal(a->part_count, b->part_count);
    assert_int_equal(a->has_sky, b->has_sky);
    assert_same_vec(a->sky, b->sky);
    assert_memory_equal(&a->camera, &b->camera, sizeof a->camera);
    for (int i = 0; i < a->object_count; i++) {
        const object *oa = &a->objects[i], *ob = &b->objects[i];
        assert_int_equal(oa->is_light, ob->is_light);
        assert_int_equal(oa->index, ob->index);
        assert_int_equal(oa->background, ob->background);
        assert_int_equal(oa->backculled, ob->backculled);
        assert_memory_equal(oa->mat.weight, ob->mat.weight, sizeof oa->mat.weight);
        assert_same_vec(oa->mat.color, ob->mat.color);
        assert_memory_equal(&oa->mat.ior, &ob->mat.ior, sizeof(double));
        assert_same_vec(oa->emission, ob->emission);
        assert_int_equal(oa->first_part, ob->first_part);
        assert_int_equal(oa->part_count, ob->part_count);
    }
    for (int i = 0; i < a->part_count; i++) {
        const part *pa = &a->parts[i], *pb = &b->parts[i];
        assert_int_equal(pa->shape, pb->shape);
        assert_int_equal(pa->object, pb->object);
        for (int k = 0; k < 3; k++)
            assert_same_vec(pa->p[k], pb->p[k]);
        assert_memory_equal(&pa->radius, &pb->radius, sizeof(double));
        assert_same_vec(pa->normal, pb->normal);
        assert_memory_equal(&pa->offset, &pb->offset, sizeof(double));
    }
}

static void check_info(const zt_scene *s, int lights, int light_parts,
                       int things, int thing_parts)
{
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    assert_int_equal(info.lights, lights);
    assert_int_equal(info.light_parts, light_parts);
    assert_int_equal(info.things, things);
    assert_int_equal(info.thing_parts, thing_parts);
}

static void test_cornell(void **state)
{
    (void)state;
    zt_scene *s = load_project_scene("cornell.json");
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    check_info(s, 1, 2, 7, 25);
    assert_int_equal(info.planes, 5);
    assert_int_equal(info.triangles, 22);
    assert_int_equal(info.has_sky, 0);

    zt_camera cam = zt_scene_get_camera(s);
    assert_int_equal(cam.width, 512);
    assert_int_equal(cam.height, 512);
    assert_near(cam.viewpoint[2], -800);
    assert_near(cam.screen[0][0], 556);
    assert_near(cam.screen[0][1], 548.8);

    object *light = scene_find_object(s, ZT_OBJECT_LIGHT, 0);
    assert_non_null(light);
    assert_int_equal(light->part_count, 2);
    assert_vec(light->emission, 1177.6, 998.4, 512.0);
    assert_true(light->backculled);
    assert_false(light->background);
    /* The light faces down into the box. */
    const part *lt = &s->parts[light->first_part];
    vec3 n = v3_cross(v3_sub(lt->p[1], lt->p[0]), v3_sub(lt->p[2], lt->p[0]));
    assert_true(n.y < 0);

    object *red = scene_find_object(s, ZT_OBJECT_THING, 4);
    assert_vec(red->mat.color, 0.64, 0.063, 0.061);
    assert_true(red->background);
    const part *wall = &s->parts[red->first_part];
    assert_int_equal(wall->shape, SHAPE_PLANE);
    assert_vec(wall->normal, -1, 0, 0);
    assert_near(wall->offset, -556);

    object *tall = scene_find_object(s, ZT_OBJECT_THING, 6);
    assert_int_equal(tall->part_count, 10);
    assert_false(tall->background);
    assert_near(tall->mat.weight[LOBE_DIFFUSE], 1);
    assert_near(tall->mat.ior, 1);
    zt_scene_release(s);
}

static void test_materials_and_pointlights(void **state)
{
    (void)state;
    zt_scene *s = load_project_scene("materials.json");
    check_info(s, 1, 1, 9, 16);
    const object *glass = scene_find_object(s, ZT_OBJECT_THING, 1);
    assert_near(glass->mat.weight[LOBE_REFRACTIVE], 1);
    assert_near(glass->mat.ior, 1.5);
    assert_false(glass->backculled);
    const object *metal = scene_find_object(s, ZT_OBJECT_THING, 2);
    assert_int_equal(metal->part_count, 8);
    assert_near(metal->mat.weight[LOBE_METALLIC], 0.9);
    zt_scene_release(s);

    s = load_project_scene("pointlights.json");
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    check_info(s, 3, 3, 9, 9);
    assert_int_equal(info.points, 3);
    zt_scene_release(s);
}

static void test_plane_normalised(void **state)
{
    (void)state;
    zt_scene *s = load_text("{\"scene\": ["
        "{\"plane\": {\"normal\": [0, 0, 2], \"offset\": 4}},"
        "{\"lightplane\": {\"normal\": [3, 4, 0], \"offset\": -10}}], " CAMERA "}");
    const part *p = &s->parts[0];
    assert_vec(p->normal, 0, 0, 1);
    assert_near(p->offset, 2);
    p = &s->parts[1];
    assert_vec(p->normal, 0.6, 0.8, 0);
    assert_near(p->offset, -2);
    zt_scene_release(s);
}

static void test_defaults(void **state)
{
    (void)state;
    zt_scene *s = load_text("{\"scene\": ["
        "{\"sphere\": {\"center\": [1, 2, 3], \"radius\": 0.5}},"
        "{\"lightsphere\": {\"center\": [0, 5, 0], \"radius\": 1}},"
        "{\"lightpoint\": {\"point\": [0, 1, 0]}},"
        "{\"triangle\": {\"points\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "
        "  \"material\": {\"character\": {\"diffuse\": 0.25, \"metallic\": 0.25, "
        "  \"reflecting\": 0.25, \"refractive\": 0.25}, \"color\": [0.5, 0.5, 0.5]}}}"
        "], " CAMERA "}");
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    assert_int_equal(info.has_sky, 0);
    assert_vec(s->sky, 0, 0, 0);
    assert_int_equal(zt_scene_get_camera(s).width, 64);
    assert_int_equal(zt_scene_get_camera(s).height, 48);

    const object *sphere = scene_find_object(s, ZT_OBJECT_THING, 0);
    assert_vec(sphere->mat.color, 0, 0, 0);
    assert_near(sphere->mat.weight[LOBE_DIFFUSE], 1);
    assert_false(sphere->background);
    assert_false(sphere->backculled);
    assert_vec(s->parts[sphere->first_part].p[0], 1, 2, 3);
    assert_near(s->parts[sphere->first_part].radius, 0.5);

    for (int i = 0; i < 2; i++) {
        const object *l = scene_find_object(s, ZT_OBJECT_LIGHT, i);
        assert_vec(l->emission, 0, 0, 0);
        assert_false(l->background);
        assert_false(l->backculled);
    }
    const object *tri = scene_find_object(s, ZT_OBJECT_THING, 1);
    assert_near(tri->mat.ior, 1);
    assert_near(tri->mat.weight[LOBE_REFRACTIVE], 0.25);
    zt_scene_release(s);
}

static void test_sky_and_lines(void **state)
{
    (void)state;
    zt_scene *s = load_text("{\n"
        "\"scene\": [\n"
        "  {\"sky\": {\"color\": [0.2, 0.05, 0.15]}},\n"
        "  {\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1}},\n"
        "  {\"thing\": [\n"
        "    {\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1}},\n"
        "    {\"sphere\": {\"center\": [0, 0, 0], \"radius\": 2}} ]}\n"
        "],\n" CAMERA "}\n");
    assert_int_equal(s->has_sky, 1);
    assert_vec(s->sky, 0.2, 0.05, 0.15);
    assert_int_equal(s->objects[0].line, 4);
    assert_int_equal(s->objects[1].line, 5);
    assert_int_equal(s->parts[0].line, 4);
    assert_int_equal(s->parts[1].line, 6);
    assert_int_equal(s->parts[2].line, 7);
    zt_scene_release(s);
}

/* The originals' group syntax, with settings before and after the parts. */
static const char legacy_groups[] =
    "{\n"
    "  \"scene\": [\n"
    "    { \"thing\": [\n"
    "        \"material\": " DIFFUSE_WHITE ",\n"
    "        \"background\": false,\n"
    "        { \"sphere\": { \"center\": [0, 0, 0], \"radius\": 2, \"background\": true } },\n"
    "        { \"triangle\": { \"points\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]] } },\n"
    "        \"material\": " GLASS ",\n"
    "        { \"plane\": { \"normal\": [0, 2, 0], \"offset\": -2 } },\n"
    "        \"backculled\": true\n"
    "      ]\n"
    "    },\n"
    "    { \"light\" : [ \"emission\": [1, 2, 3],\n"
    "        { \"lighttriangle\": { \"points\": [[0, 5, 0], [0, 5, 1], [1, 5, 0]] } },\n"
    "        { \"lighttriangle\": { \"points\": [[1, 5, 1], [1, 5, 0], [0, 5, 1]] } },\n"
    "        { \"lightsphere\": { \"center\": [0, 5, 0], \"radius\": 0.5, \"backculled\": true } }\n"
    "      ]\n"
    "    }\n"
    "  ],\n"
    "  " CAMERA "\n"
    "}\n";

/* The same in the canonical strict form. */
static const char canonical_groups[] =
    "{\"scene\": [\n"
    "  {\"thing\": {\"material\": " DIFFUSE_WHITE ", \"background\": false, \"parts\": [\n"
    "    {\"sphere\": {\"center\": [0, 0, 0], \"radius\": 2, \"background\": true}},\n"
    "    {\"triangle\": {\"points\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}},\n"
    "    {\"material\": " GLASS "},\n"
    "    {\"plane\": {\"normal\": [0, 2, 0], \"offset\": -2}}],\n"
    "    \"backculled\": true}},\n"
    "  {\"light\": {\"emission\": [1, 2, 3], \"parts\": [\n"
    "    {\"lighttriangle\": {\"points\": [[0, 5, 0], [0, 5, 1], [1, 5, 0]]}},\n"
    "    {\"lighttriangle\": {\"points\": [[1, 5, 1], [1, 5, 0], [0, 5, 1]]}},\n"
    "    {\"lightsphere\": {\"center\": [0, 5, 0], \"radius\": 0.5, \"backculled\": true}}]}}\n"
    "], " CAMERA "}\n";

static void test_legacy_groups(void **state)
{
    (void)state;
    zt_scene *legacy = load_text(legacy_groups);
    zt_scene *canonical = load_text(canonical_groups);
    check_info(legacy, 1, 3, 1, 3);
    assert_same_scene(legacy, canonical);

    /* Object settings: the last definition in the file wins. */
    const object *thing = scene_find_object(legacy, ZT_OBJECT_THING, 0);
    assert_true(thing->background);
    assert_true(thing->backculled);
    assert_near(thing->mat.weight[LOBE_REFRACTIVE], 1);
    assert_near(thing->mat.ior, 1.5);
    /* Light triangles stay parts of their group and share its emission. */
    const object *light = scene_find_object(legacy, ZT_OBJECT_LIGHT, 0);
    assert_int_equal(light->part_count, 3);
    assert_vec(light->emission, 1, 2, 3);
    assert_true(light->backculled);
    assert_int_equal(legacy->parts[light->first_part].shape, SHAPE_TRIANGLE);
    assert_int_equal(legacy->parts[light->first_part + 2].shape, SHAPE_SPHERE);
    /* Lines survive the rewrite. */
    assert_int_equal(thing->line, 3);
    assert_int_equal(legacy->parts[thing->first_part + 2].line, 9);
    assert_int_equal(light->line, 13);
    zt_scene_release(legacy);
    zt_scene_release(canonical);
}

static void test_key_order(void **state)
{
    (void)state;
    zt_scene *a = load_text("{\"scene\": [{\"sphere\": {\"material\": " GLASS
        ", \"center\": [1, 2, 3], \"radius\": 2, \"backculled\": true}}, "
        "{\"lightpoint\": {\"emission\": [1, 1, 1], \"point\": [0, 3, 0]}}], " CAMERA "}");
    zt_scene *b = load_text("{" CAMERA ", \"scene\": [{\"sphere\": {\"backculled\": true, "
        "\"radius\": 2, \"center\": [1, 2, 3], \"material\": {\"refractiveindex\": 1.5, "
        "\"color\": [1, 1, 1], \"character\": {\"refractive\": 1, \"reflecting\": 0, "
        "\"metallic\": 0, \"diffuse\": 0}}}}, "
        "{\"lightpoint\": {\"point\": [0, 3, 0], \"emission\": [1, 1, 1]}}]}");
    assert_same_scene(a, b);
    zt_scene_release(a);
    zt_scene_release(b);
}

static void test_string_not_terminated(void **state)
{
    (void)state;
    const char *text = "{\"scene\": [], " CAMERA "}garbage";
    size_t length = strlen(text) - strlen("garbage");
    zt_scene *s = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_string(text, length, NULL, &s, &err), ZT_OK);
    check_info(s, 0, 0, 0, 0);
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell),
        cmocka_unit_test(test_materials_and_pointlights),
        cmocka_unit_test(test_plane_normalised),
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_sky_and_lines),
        cmocka_unit_test(test_legacy_groups),
        cmocka_unit_test(test_key_order),
        cmocka_unit_test(test_string_not_terminated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
