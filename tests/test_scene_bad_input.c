/* The scene loader on bad input: every class of problem gives one message
 * "FILE:LINE:COLUMN: what is wrong" with the right status and line, and
 * damaged files never crash, hang or leak (the tests run under ASan). */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "zonetrace/scene.h"

/* Line 1-2 open the scene list, line 3 holds the item under test, the
 * camera is on line 5. */
#define HEAD "{\n\"scene\": [\n"
#define CAMERA_VALUE "{\"viewpoint\": [0, 0, 20], " \
    "\"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], " \
    "\"gridresolution\": [8, 8]}"
#define TAIL "\n],\n\"camera\": " CAMERA_VALUE "\n}\n"
#define ITEM(text) HEAD text TAIL
#define WITH_CAMERA(text) "{\n\"scene\": [],\n\"camera\": " text "\n}\n"
#define CHARACTER(d, m, r, t) "{\"diffuse\": " d ", \"metallic\": " m \
    ", \"reflecting\": " r ", \"refractive\": " t "}"
#define WITH_MATERIAL(text) ITEM("{\"sphere\": {\"center\": [0, 0, 0], " \
    "\"radius\": 1, \"material\": " text "}}")

typedef struct bad_case {
    const char *name;
    const char *text;
    int line;
    int column;        /* 0: not checked */
    const char *word;  /* must appear in the message */
} bad_case;

static const bad_case cases[] = {
    /* syntax */
    {"truncated", HEAD "{\"sphere\": {\"center\": [0, 0, 0],", 3, 0, "syntax error"},
    {"truncated_string", HEAD "{\"sphere\": {\"cen", 3, 0, "syntax error"},
    {"missing_comma", ITEM("{\"sphere\": {\"center\": [0, 0 0], \"radius\": 1}}"), 3, 29, "syntax error"},
    {"trailing_comma", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1,}}"), 3, 0, "syntax error"},
    {"garbage_after", ITEM("{\"lightpoint\": {\"point\": [0, 0, 0]}}") "}\n", 7, 1, "end of file expected"},
    {"empty_file", "", 1, 1, "syntax error"},
    {"bad_utf8", ITEM("{\"sphere\": {\"cent\xff\": [0, 0, 0], \"radius\": 1}}"), 3, 0, "syntax error"},
    {"nan_literal", ITEM("{\"sphere\": {\"center\": [0, NaN, 0], \"radius\": 1}}"), 3, 27, "invalid token"},
    {"infinity", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1e999}}"), 3, 44, "overflow"},
    {"huge_integer", ITEM("{\"sphere\": {\"center\": [0, 0, 99999999999999999999], \"radius\": 1}}"), 3, 30, "too big"},
    {"too_deep", HEAD "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["
                      "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["
                      TAIL, 3, 0, "nesting too deep"},
    {"duplicate_key", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"radius\": 2}}"), 3, 47, "duplicate"},
    {"object_after_top_level", HEAD "{\"lightpoint\": {\"point\": [0, 0, 0]}}" TAIL "{}", 7, 0, "end of file expected"},
    {"duplicate_camera", "{\n\"scene\": [],\n\"camera\": " CAMERA_VALUE ",\n\"camera\": " CAMERA_VALUE "\n}\n",
     4, 1, "duplicate"},
    /* types */
    {"string_for_number", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": \"big\"}}"), 3, 44, "expected a number"},
    {"triple_of_two", ITEM("{\"sphere\": {\"center\": [0, 0], \"radius\": 1}}"), 3, 23, "expected 3 numbers"},
    {"triple_of_four", ITEM("{\"sphere\": {\"center\": [0, 0, 0, 0], \"radius\": 1}}"), 3, 23, "found 4"},
    {"triple_not_array", ITEM("{\"sphere\": {\"center\": 5, \"radius\": 1}}"), 3, 23, "wrong type"},
    {"bool_as_number", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"background\": 1}}"), 3, 61, "true or false"},
    {"points_of_two", ITEM("{\"triangle\": {\"points\": [[0, 0, 0], [1, 0, 0]]}}"), 3, 25, "expected 3 points"},
    {"scene_not_list", "{\n\"scene\": {},\n\"camera\": " CAMERA_VALUE "\n}\n", 2, 10, "must be a list"},
    {"item_not_object", ITEM("[1, 2]"), 3, 1, "must be an object"},
    {"body_not_object", ITEM("{\"sphere\": [1, 2]}"), 3, 12, "must be an object"},
    {"top_level_array", "\n[1, 2]\n", 2, 1, "top level must be an object"},
    {"top_level_number", "42", 1, 1, "top level must be an object"},
    /* keys */
    {"unknown_key", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"wobble\": 2}}"), 3, 47, "unknown key \"wobble\""},
    {"unknown_item", ITEM("{\"cube\": {\"size\": 1}}"), 3, 2, "unknown scene item \"cube\""},
    {"two_keys_in_item", ITEM("{\"lightpoint\": {\"point\": [0, 0, 0]}, \"sphere\": {}}"), 3, 38, "second key"},
    {"empty_item", ITEM("{}"), 3, 1, "empty scene item"},
    {"unknown_top_key", "{\n\"scene\": [],\n\"camara\": " CAMERA_VALUE "\n}\n", 3, 1, "unknown key \"camara\""},
    {"unknown_camera_key", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"fov\": 90}"), 3, 37, "unknown key \"fov\""},
    {"material_on_light", ITEM("{\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"material\": {}}}"), 3, 52, "unknown key \"material\""},
    {"emission_on_thing", ITEM("{\"thing\": [ \"emission\": [1, 1, 1], {\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1}} ]}"),
     3, 13, "unknown key \"emission\""},
    {"missing_radius", ITEM("{\"sphere\": {\"center\": [0, 0, 0]}}"), 3, 12, "missing \"radius\""},
    {"missing_point", ITEM("{\"lightpoint\": {\"emission\": [1, 1, 1]}}"), 3, 16, "missing \"point\""},
    {"missing_camera", "{\n\"scene\": []\n}\n", 1, 1, "missing \"camera\""},
    {"missing_scene", "{\n\"camera\": " CAMERA_VALUE "\n}\n", 1, 1, "missing \"scene\""},
    {"camera_in_scene", ITEM("{\"camera\": " CAMERA_VALUE "}"), 3, 2, "misplaced camera"},
    {"second_sky", ITEM("{\"sky\": {\"color\": [0, 0, 0]}},\n{\"sky\": {\"color\": [1, 1, 1]}}"), 4, 1, "second sky"},
    {"sky_missing_color", ITEM("{\"sky\": {}}"), 3, 9, "missing \"color\""},
    /* daylight */
    {"second_sun", ITEM("{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [1, 1, 1]}},\n{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [1, 1, 1]}}"), 4, 1, "second sun"},
    {"sun_zero_direction", ITEM("{\"sun\": {\"direction\": [0, 0, 0], \"irradiance\": [1, 1, 1]}}"), 3, 23, "zero direction"},
    {"sun_angle_zero", ITEM("{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [1, 1, 1], \"angle\": 0}}"), 3, 68, "angle"},
    {"sun_angle_90", ITEM("{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [1, 1, 1], \"angle\": 90}}"), 3, 68, "at most 10"},
    {"sun_missing_irradiance", ITEM("{\"sun\": {\"direction\": [0, 1, 0]}}"), 3, 9, "missing \"irradiance\""},
    {"sun_missing_direction", ITEM("{\"sun\": {\"irradiance\": [1, 1, 1]}}"), 3, 9, "missing \"direction\""},
    {"sun_negative_irradiance", ITEM("{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [1, -1, 1]}}"), 3, 52, "negative radiance"},
    {"sun_direction_and_place", ITEM("{\"sun\": {\"direction\": [0, 1, 0], \"irradiance\": [1, 1, 1], \"place\": {}}}"), 3, 68, "not both"},
    {"sun_bad_date", ITEM("{\"sun\": {\"irradiance\": [1, 1, 1], \"place\": {\"latitude\": 49, \"longitude\": 8.4, \"utc_offset\": 2, \"date\": \"2026-02-30\", \"time\": \"15:00\"}}}"), 3, 104, "not a date"},
    {"sun_bad_time", ITEM("{\"sun\": {\"irradiance\": [1, 1, 1], \"place\": {\"latitude\": 49, \"longitude\": 8.4, \"utc_offset\": 2, \"date\": \"2026-06-21\", \"time\": \"25:00\"}}}"), 3, 126, "not a time"},
    {"sun_latitude_range", ITEM("{\"sun\": {\"irradiance\": [1, 1, 1], \"place\": {\"latitude\": 91, \"longitude\": 8.4, \"utc_offset\": 2, \"date\": \"2026-06-21\", \"time\": \"15:00\"}}}"), 3, 57, "latitude"},
    {"sky_color_and_file", ITEM("{\"sky\": {\"color\": [1, 1, 1], \"file\": \"a.exr\"}}"), 3, 38, "cannot be mixed"},
    {"sky_unknown_model", ITEM("{\"sky\": {\"model\": \"hosek\"}}"), 3, 19, "unknown sky model"},
    {"sky_model_without_sun", ITEM("{\"sky\": {\"model\": \"preetham\"}}"), 3, 19, "needs the sun"},
    {"sky_turbidity_range", ITEM("{\"sky\": {\"model\": \"preetham\", \"turbidity\": 20, \"sun_direction\": [0, 1, 0]}}"), 3, 44, "turbidity"},
    {"sky_strength_on_color", ITEM("{\"sky\": {\"color\": [1, 1, 1], \"strength\": 2}}"), 3, 30, "belongs to a sky"},
    {"sky_file_not_string", ITEM("{\"sky\": {\"file\": 3}}"), 3, 18, "non-empty string"},
    {"sun_place_at_night", ITEM("{\"sun\": {\"irradiance\": [1, 1, 1], \"place\": {\"latitude\": 49, \"longitude\": 8.4, \"utc_offset\": 2, \"date\": \"2026-06-21\", \"time\": \"23:30\"}}}"), 3, 44, "below the horizon"},
    {"sun_loose_date", ITEM("{\"sun\": {\"irradiance\": [1, 1, 1], \"place\": {\"latitude\": 49, \"longitude\": 8.4, \"utc_offset\": 2, \"date\": \"2026-6-21\", \"time\": \"15:00\"}}}"), 3, 104, "not a date"},
    {"sun_loose_time", ITEM("{\"sun\": {\"irradiance\": [1, 1, 1], \"place\": {\"latitude\": 49, \"longitude\": 8.4, \"utc_offset\": 2, \"date\": \"2026-06-21\", \"time\": \"9:5\"}}}"), 3, 126, "not a time"},
    /* numbers and ranges */
    {"too_large", ITEM("{\"sphere\": {\"center\": [0, 2e12, 0], \"radius\": 1}}"), 3, 27, "too large"},
    {"too_large_integer", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 10000000000000}}"), 3, 44, "too large"},
    {"zero_radius", ITEM("{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 0}}"), 3, 44, "radius must be positive"},
    {"negative_radius", ITEM("{\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": -2}}"), 3, 49, "radius must be positive"},
    {"degenerate_triangle", ITEM("{\"triangle\": {\"points\": [[0, 0, 0], [1, 1, 1], [3, 3, 3]]}}"), 3, 25, "degenerate triangle"},
    {"repeated_vertex", ITEM("{\"lighttriangle\": {\"points\": [[0, 0, 0], [0, 0, 0], [1, 0, 0]]}}"), 3, 30, "degenerate triangle"},
    {"zero_normal", ITEM("{\"plane\": {\"normal\": [0, 0, 0], \"offset\": 1}}"), 3, 22, "zero-length plane normal"},
    {"weight_above_one", WITH_MATERIAL("{\"character\": " CHARACTER("1.5", "-0.5", "0", "0") ", \"color\": [1, 1, 1]}"), 3, 0, "weight out of range"},
    {"weight_negative", WITH_MATERIAL("{\"character\": " CHARACTER("1", "0", "-0.25", "0.25") ", \"color\": [1, 1, 1]}"), 3, 0, "weight out of range"},
    {"weights_sum", WITH_MATERIAL("{\"character\": " CHARACTER("0.5", "0.25", "0", "0") ", \"color\": [1, 1, 1]}"), 3, 0, "sum to 1"},
    {"weight_missing", WITH_MATERIAL("{\"character\": {\"diffuse\": 1, \"metallic\": 0, \"reflecting\": 0}, \"color\": [1, 1, 1]}"), 3, 0, "missing \"refractive\""},
    {"color_missing", WITH_MATERIAL("{\"character\": " CHARACTER("1", "0", "0", "0") "}"), 3, 0, "missing \"color\""},
    {"color_above_one", WITH_MATERIAL("{\"character\": " CHARACTER("1", "0", "0", "0") ", \"color\": [1, 1.5, 1]}"), 3, 0, "colour out of range"},
    {"color_negative", WITH_MATERIAL("{\"character\": " CHARACTER("1", "0", "0", "0") ", \"color\": [-0.1, 1, 1]}"), 3, 0, "colour out of range"},
    {"ior_zero", WITH_MATERIAL("{\"character\": " CHARACTER("1", "0", "0", "0") ", \"color\": [1, 1, 1], \"refractiveindex\": 0}"), 3, 0, "refractiveindex must be positive"},
    {"ior_negative", WITH_MATERIAL("{\"character\": " CHARACTER("0", "0", "0", "1") ", \"color\": [1, 1, 1], \"refractiveindex\": -1.5}"), 3, 0, "refractiveindex must be positive"},
    {"thin_without_glass", WITH_MATERIAL("{\"character\": " CHARACTER("1", "0", "0", "0") ", \"color\": [1, 1, 1], \"thin\": true}"), 3, 0, "weight is 0"},
    {"roughness_above_1", WITH_MATERIAL("{\"character\": " CHARACTER("0", "1", "0", "0") ", \"color\": [1, 1, 1], \"roughness\": 1.5}"), 3, 0, "roughness must be in [0, 1]"},
    {"specular_above_1", WITH_MATERIAL("{\"character\": " CHARACTER("1", "0", "0", "0") ", \"color\": [1, 1, 1], \"specular\": 2}"), 3, 0, "specular must be in [0, 1]"},
    {"specular_without_diffuse", WITH_MATERIAL("{\"character\": " CHARACTER("0", "1", "0", "0") ", \"color\": [1, 1, 1], \"specular\": 0.5}"), 3, 0, "coat over the diffuse lobe"},
    {"roughness_negative", WITH_MATERIAL("{\"character\": " CHARACTER("0", "1", "0", "0") ", \"color\": [1, 1, 1], \"roughness\": -0.1}"), 3, 0, "roughness must be in [0, 1]"},
    {"roughness_string", WITH_MATERIAL("{\"character\": " CHARACTER("0", "1", "0", "0") ", \"color\": [1, 1, 1], \"roughness\": \"rough\"}"), 3, 0, "number"},
    {"thin_not_bool", WITH_MATERIAL("{\"character\": " CHARACTER("0", "0", "0", "1") ", \"color\": [1, 1, 1], \"thin\": \"yes\"}"), 3, 0, "true or false"},
    {"negative_emission", ITEM("{\"lightpoint\": {\"point\": [0, 0, 0], \"emission\": [1, -1, 1]}}"), 3, 53, "negative radiance"},
    {"negative_sky", ITEM("{\"sky\": {\"color\": [0, 0, -1]}}"), 3, 26, "negative radiance"},
    /* groups */
    {"light_in_thing", ITEM("{\"thing\": [ {\"lightsphere\": {\"center\": [0, 0, 0], \"radius\": 1}} ]}"), 3, 14, "cannot contain light parts"},
    {"thing_in_light", ITEM("{\"light\": {\"parts\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1}}]}}"), 3, 23, "cannot contain thing parts"},
    {"nested_group", ITEM("{\"thing\": [ {\"thing\": [ {\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1}} ]} ]}"), 3, 14, "nested groups"},
    {"empty_group", ITEM("{\"light\": [ \"emission\": [1, 1, 1] ]}"), 3, 11, "empty group"},
    {"legacy_column", ITEM("{\"thing\": [ \"backculled\": true, {\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1}}, \"background\": false, {\"sphere\": {\"center\": [0, 0, 0], \"radius\": -3}} ]}"),
     3, 145, "radius must be positive"},
    /* camera */
    {"camera_missing_screen", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"gridresolution\": [8, 8]}"), 3, 11, "missing \"screen\""},
    {"resolution_zero", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], \"gridresolution\": [0, 8]}"), 3, 120, "out of range"},
    {"resolution_negative", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], \"gridresolution\": [8, -8]}"), 3, 123, "out of range"},
    {"resolution_huge", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], \"gridresolution\": [40000, 8]}"), 3, 120, "out of range"},
    {"resolution_pixels", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], \"gridresolution\": [32768, 16384]}"), 3, 119, "out of range"},
    {"resolution_real", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], \"gridresolution\": [8.5, 8]}"), 3, 120, "expected an integer"},
    {"resolution_one_side", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], \"gridresolution\": [8]}"), 3, 119, "wrong length"},
    {"screen_three_corners", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19]], \"gridresolution\": [8, 8]}"), 3, 47, "expected 4 points"},
    {"screen_collinear", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [3, 1, 19], [1, -1, 19]], \"gridresolution\": [8, 8]}"), 3, 47, "degenerate screen"},
    {"screen_point", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[1, 1, 19], [1, 1, 19], [1, 1, 19], [1, 1, 19]], \"gridresolution\": [8, 8]}"), 3, 47, "degenerate screen"},
    {"screen_not_finite", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 1e400], [1, -1, 19]], \"gridresolution\": [8, 8]}"), 3, 82, "overflow"},
    {"screen_too_far", WITH_CAMERA("{\"viewpoint\": [0, 0, 20], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 3e12], [1, -1, 19]], \"gridresolution\": [8, 8]}"), 3, 82, "too large"},
    {"viewpoint_on_screen", WITH_CAMERA("{\"viewpoint\": [0, 0, 19], \"screen\": [[-1, 1, 19], [1, 1, 19], [-1, -1, 19], [1, -1, 19]], \"gridresolution\": [8, 8]}"), 3, 25, "viewpoint lies on the screen plane"},
};

/* Returns 1 when err is the expected one-line message, else prints why. */
static int message_ok(const char *path, const zt_error *err, int line,
                      int column, const char *word)
{
    char prefix[1024];
    if (column)
        snprintf(prefix, sizeof prefix, "%s:%d:%d: ", path, line, column);
    else
        snprintf(prefix, sizeof prefix, "%s:%d:", path, line);
    if (strncmp(err->message, prefix, strlen(prefix)) != 0 ||
        !strstr(err->message, word) || strchr(err->message, '\n')) {
        print_error("message \"%s\" is not \"%s ... %s ...\"\n", err->message,
                    prefix, word);
        return 0;
    }
    return 1;
}

static void test_bad_cases(void **state)
{
    (void)state;
    int failures = 0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const bad_case *c = &cases[i];
        char name[128];
        snprintf(name, sizeof name, "%s.json", c->name);
        const char *path = test_write_file(name, c->text);
        zt_scene *scene = (zt_scene *)&scene; /* must be reset to NULL */
        zt_error err = {0};
        zt_status st = zt_scene_load_file(path, &scene, &err);
        if (st != ZT_ERR_PARSE || err.status != ZT_ERR_PARSE || scene) {
            print_error("%s: status %d, message \"%s\"\n", c->name, st, err.message);
            failures++;
            continue;
        }
        failures += !message_ok(path, &err, c->line, c->column, c->word);
    }
    assert_int_equal(failures, 0);
}

static void test_nul_byte(void **state)
{
    (void)state;
    static const char text[] = "{\n\"scene\": [\0],\n\"camera\": {}\n}";
    zt_scene *scene = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_string(text, sizeof text - 1, "nul.json",
                                          &scene, &err), ZT_ERR_PARSE);
    assert_null(scene);
    assert_true(message_ok("nul.json", &err, 2, 11, "NUL byte"));
}

static void expect_read_error(const char *path, const char *word)
{
    zt_scene *scene = NULL;
    zt_error err = {0};
    zt_status st = zt_scene_load_file(path, &scene, &err);
    if (st != ZT_ERR_READ)
        fail_msg("%s: status %d, message \"%s\"", path, st, err.message);
    assert_null(scene);
    assert_non_null(strstr(err.message, path));
    if (!strstr(err.message, word))
        fail_msg("message \"%s\" does not say \"%s\"", err.message, word);
}

static void test_read_errors(void **state)
{
    (void)state;
    expect_read_error(test_tmp_path("no_such_file.json"), "cannot open");
    expect_read_error(test_tmp_dir(), "directory");

    /* A sparse file one byte over the limit is refused before reading it. */
    const char *big = test_write_file("big.json", "{");
    assert_int_equal(truncate(big, (64 << 20) + 1), 0);
    expect_read_error(big, "too large");

    /* The same limit from memory: the text is not read at all. */
    zt_scene *scene = NULL;
    zt_error err = {0};
    assert_int_equal(zt_scene_load_string("{", ((size_t)64 << 20) + 1, "mem.json",
                                          &scene, &err), ZT_ERR_READ);
    assert_non_null(strstr(err.message, "too large"));
}

/* Loads text[0..length) and checks that it either succeeds or fails cleanly
 * with one message that names the file. */
static void load_damaged(const char *text, size_t length)
{
    zt_scene *scene = NULL;
    zt_error err = {0};
    zt_status st = zt_scene_load_string(text, length, "damaged.json", &scene, &err);
    if (st == ZT_OK) {
        assert_non_null(scene);
        zt_scene_release(scene);
        return;
    }
    assert_int_equal(st, ZT_ERR_PARSE);
    assert_null(scene);
    if (strncmp(err.message, "damaged.json:", 13) != 0)
        fail_msg("at length %zu: bad message \"%s\"", length, err.message);
}

static const char legacy_scene[] =
    "{ \"scene\": [\n"
    "  { \"thing\": [ \"material\": { \"character\": { \"diffuse\": 0.5, \"metallic\": 0.5,\n"
    "        \"reflecting\": 0, \"refractive\": 0 }, \"color\": [0.5, 0.5, 0.5] },\n"
    "      { \"sphere\": { \"center\": [0, 0, 0], \"radius\": 1 } },\n"
    "      \"backculled\": true,\n"
    "      { \"triangle\": { \"points\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]] } } ] },\n"
    "  { \"light\": [ \"emission\": [1, 1, 1], { \"lightplane\": { \"normal\": [0, -2, 0], \"offset\": -8 } } ] },\n"
    "  { \"sky\": { \"color\": [0.1, 0.1, 0.1] } }\n"
    "], \"camera\": " CAMERA_VALUE " }\n";

static void test_truncated_everywhere(void **state)
{
    (void)state;
    for (size_t n = 0; n <= sizeof legacy_scene - 1; n++)
        load_damaged(legacy_scene, n);

    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/materials.json", ZT_SOURCE_DIR);
    size_t length;
    char *text = test_read_file(path, &length);
    assert_non_null(text);
    for (size_t n = 0; n <= length; n++)
        load_damaged(text, n);
    free(text);
}

/* Every byte replaced by each of a few characters that matter to the
 * scanners and to the checks. */
static void test_mutated_everywhere(void **state)
{
    (void)state;
    static const char replacements[] = "{}[]:,\"0-e \\";
    char text[sizeof legacy_scene];
    for (size_t i = 0; i < sizeof legacy_scene - 1; i++) {
        for (const char *r = replacements; *r; r++) {
            memcpy(text, legacy_scene, sizeof text);
            text[i] = *r;
            load_damaged(text, sizeof text - 1);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_cases),
        cmocka_unit_test(test_nul_byte),
        cmocka_unit_test(test_read_errors),
        cmocka_unit_test(test_truncated_everywhere),
        cmocka_unit_test(test_mutated_everywhere),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
