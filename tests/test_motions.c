/* Motions files: loading (good files and every class of error, with their
 * positions), evaluation against the closed forms of docs/viewer.md,
 * brownian reproducibility, bounds checks, composition, and the offline
 * animation of the render command. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_support.h"
#include "zonetrace/zonetrace.h"
#include "scene/motions.h"

#define PI 3.14159265358979323846

/* light 0: a point at (1, 2, 3); thing 0: a sphere at (5, 0, 0); thing 1: a
 * triangle with centroid (1/3, 1/3, 0); light 1: a point at (0, 0, 4). */
static const char *scene_text =
    "{\"scene\": [\n"
    "  {\"lightpoint\": {\"point\": [1, 2, 3], \"emission\": [1, 1, 1]}},\n"
    "  {\"sphere\": {\"center\": [5, 0, 0], \"radius\": 1}},\n"
    "  {\"triangle\": {\"points\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}},\n"
    "  {\"lightpoint\": {\"point\": [0, 0, 4], \"emission\": [1, 1, 1]}}\n"
    "],\n"
    "\"camera\": {\"viewpoint\": [0, 0, -10],\n"
    "  \"screen\": [[-1, 1, -9], [1, 1, -9], [-1, -1, -9], [1, -1, -9]],\n"
    "  \"gridresolution\": [8, 8]}}\n";

static zt_scene *load_scene(void)
{
    zt_scene *s = NULL;
    zt_error err;
    zt_status st = zt_scene_load_string(scene_text, strlen(scene_text), "t.json", &s, &err);
    if (st != ZT_OK)
        fprintf(stderr, "%s\n", err.message);
    assert_int_equal(st, ZT_OK);
    return s;
}

static zt_motions *load_motions(const char *text)
{
    zt_motions *m = NULL;
    zt_error err;
    zt_status st = zt_motions_load_string(text, strlen(text), "m.json", &m, &err);
    if (st != ZT_OK)
        fprintf(stderr, "%s\n", err.message);
    assert_int_equal(st, ZT_OK);
    return m;
}

static void position(const zt_scene *s, zt_object_class cls, int index, double out[3])
{
    zt_error err;
    assert_int_equal(zt_scene_object_position(s, cls, index, out, &err), ZT_OK);
}

static void assert_near3(const double a[3], double x, double y, double z, double tol)
{
    if (fabs(a[0] - x) > tol || fabs(a[1] - y) > tol || fabs(a[2] - z) > tol) {
        fprintf(stderr, "got (%.12g, %.12g, %.12g), expected (%.12g, %.12g, %.12g)\n",
                a[0], a[1], a[2], x, y, z);
        fail();
    }
}

/* The position of object (cls, index) at time t under motions text. */
static void position_at(const char *text, double t, uint64_t seed, zt_object_class cls,
                        int index, double out[3])
{
    zt_scene *s0 = load_scene();
    zt_scene *s = zt_scene_clone(s0);
    zt_motions *m = load_motions(text);
    zt_error err;
    assert_int_equal(zt_motions_check(m, s0, &err), ZT_OK);
    zt_status st = zt_motions_apply(m, s0, t, seed, s, &err);
    if (st != ZT_OK)
        fprintf(stderr, "%s\n", err.message);
    assert_int_equal(st, ZT_OK);
    position(s, cls, index, out);
    zt_motions_release(m);
    zt_scene_release(s);
    zt_scene_release(s0);
}

/* ---- loading ---- */

static void test_load_all_types(void **state)
{
    (void)state;
    zt_motions *m = load_motions(
        "{ \"motions\": [\n"
        "  {\"light\": 0, \"type\": \"linear\", \"delta\": [0.2, 0.2, 0], \"stop\": 20},\n"
        "  {\"thing\": 1, \"type\": \"orbiting\", \"axis\": \"y\", \"period\": 20},\n"
        "  {\"type\": \"oscillating\", \"thing\": 0, \"begin\": [0, 0, 0], \"end\": [1, 2, 3], \"period\": 4},\n"
        "  {\"thing\": 0, \"type\": \"brownian\", \"scale\": 1.5},\n"
        "  {\"light\": 1, \"type\": \"linear\", \"delta\": [1, 0, 0]}\n"
        "] }\n");
    assert_int_equal(zt_motions_count(m), 5);
    const zt_motion *a = zt_motions_get(m, 0);
    assert_int_equal(a->type, ZT_MOTION_LINEAR);
    assert_int_equal(a->target_class, ZT_OBJECT_LIGHT);
    assert_int_equal(a->target, 0);
    assert_true(a->delta[0] == 0.2 && a->delta[1] == 0.2 && a->delta[2] == 0);
    assert_true(a->stop == 20);
    assert_int_equal(a->line, 2);
    assert_int_equal(a->column, 13);
    const zt_motion *b = zt_motions_get(m, 1);
    assert_int_equal(b->type, ZT_MOTION_ORBITING);
    assert_int_equal(b->target_class, ZT_OBJECT_THING);
    assert_int_equal(b->target, 1);
    assert_int_equal(b->axis, 1);
    assert_true(b->period == 20);
    const zt_motion *c = zt_motions_get(m, 2);
    assert_int_equal(c->type, ZT_MOTION_OSCILLATING);
    assert_true(c->end[2] == 3 && c->period == 4);
    const zt_motion *d = zt_motions_get(m, 3);
    assert_int_equal(d->type, ZT_MOTION_BROWNIAN);
    assert_true(d->scale == 1.5);
    const zt_motion *e = zt_motions_get(m, 4);
    assert_true(e->stop < 0); /* unlimited by default */
    assert_null(zt_motions_get(m, 5));
    assert_null(zt_motions_get(m, -1));
    zt_motions_release(m);

    /* an empty list and both cases of the axes */
    m = load_motions("{\"motions\": []}");
    assert_int_equal(zt_motions_count(m), 0);
    zt_motions_release(m);
    const char *axes[] = {"x", "X", "y", "Y", "z", "Z"};
    for (int i = 0; i < 6; i++) {
        char text[200];
        snprintf(text, sizeof text, "{\"motions\": [{\"thing\": 0, \"type\": \"orbiting\", "
                 "\"axis\": \"%s\", \"period\": 1}]}", axes[i]);
        m = load_motions(text);
        assert_int_equal(zt_motions_get(m, 0)->axis, i / 2);
        zt_motions_release(m);
    }
    /* a byte-order mark is allowed */
    m = load_motions("\xEF\xBB\xBF{\"motions\": []}");
    zt_motions_release(m);
}

static void test_load_shipped(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    if (!shared)
        skip();
    const char *names[][3] = {
        {"retra", "dancingLights", "3"}, {"retra", "demo_early", "5"},
        {"silence", "dancingLights", "3"}, {"silence", "demo_early", "5"},
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char mpath[600], spath[600];
        snprintf(mpath, sizeof mpath, "%s/scenes/%s/%s_motions.json", shared, names[i][0], names[i][1]);
        snprintf(spath, sizeof spath, "%s/scenes/%s/%s.json", shared, names[i][0], names[i][1]);
        zt_motions *m = NULL;
        zt_scene *s = NULL;
        zt_error err;
        zt_status st = zt_motions_load_file(mpath, &m, &err);
        if (st != ZT_OK)
            fprintf(stderr, "%s\n", err.message);
        assert_int_equal(st, ZT_OK);
        assert_int_equal(zt_motions_count(m), atoi(names[i][2]));
        assert_int_equal(zt_scene_load_file(spath, &s, &err), ZT_OK);
        st = zt_motions_check(m, s, &err);
        if (st != ZT_OK)
            fprintf(stderr, "%s\n", err.message);
        assert_int_equal(st, ZT_OK);
        zt_scene *out = zt_scene_clone(s);
        assert_int_equal(zt_motions_apply(m, s, 7.5, 1, out, &err), ZT_OK);
        zt_scene_release(out);
        zt_scene_release(s);
        zt_motions_release(m);
    }
    /* demo_early's first motion: light 1, linear [0.2, 0.2, 0], stop 20 */
    char mpath[600];
    snprintf(mpath, sizeof mpath, "%s/scenes/retra/demo_early_motions.json", shared);
    zt_motions *m = NULL;
    zt_error err;
    assert_int_equal(zt_motions_load_file(mpath, &m, &err), ZT_OK);
    const zt_motion *a = zt_motions_get(m, 0);
    assert_int_equal(a->type, ZT_MOTION_LINEAR);
    assert_int_equal(a->target_class, ZT_OBJECT_LIGHT);
    assert_int_equal(a->target, 1);
    assert_true(a->stop == 20);
    assert_int_equal(zt_motions_get(m, 4)->type, ZT_MOTION_BROWNIAN);
    zt_motions_release(m);
}

typedef struct bad_case {
    const char *text;
    zt_status status;
    const char *expect; /* the start of the message */
    const char *also;   /* text the message must contain */
} bad_case;

/* Loads each case and checks its status, the message's start (the place)
 * and a part of its text. */
static void check_bad_cases(const bad_case *cases, size_t count)
{
    int failures = 0;
    for (size_t i = 0; i < count; i++) {
        const bad_case *c = &cases[i];
        size_t len = strlen(c->text);
        if (strstr(c->also, "NUL"))
            len = 16;
        zt_motions *m = (zt_motions *)1;
        zt_error err;
        zt_status st = zt_motions_load_string(c->text, len, "m.json", &m, &err);
        int ok = st == c->status && m == NULL &&
                 strncmp(err.message, c->expect, strlen(c->expect)) == 0 &&
                 strstr(err.message, c->also) != NULL && err.status == c->status;
        if (!ok) {
            fprintf(stderr, "case %zu: status %d, message \"%s\"; expected %d, \"%s...%s\"\n",
                    i, st, err.message, c->status, c->expect, c->also);
            failures++;
        }
        assert_null(strchr(err.message, '\n'));
    }
    assert_int_equal(failures, 0);
}

static void test_load_errors(void **state)
{
    (void)state;
    static const bad_case cases[] = {
        /* syntax */
        {"{\"motions\": [}", ZT_ERR_PARSE, "m.json:1:14: ", "syntax error"},
        {"{\"motions\": [\n", ZT_ERR_PARSE, "m.json:1:14: ", "syntax error"},
        {"", ZT_ERR_PARSE, "m.json:", "syntax error"},
        {"{\"motions\": [],\n \"motions\": []}", ZT_ERR_PARSE, "m.json:2:", "duplicate"},
        {"{\"motions\": [\0]}", ZT_ERR_PARSE, "m.json:1:14: ", "NUL byte"},
        /* the top level */
        {"[]", ZT_ERR_PARSE, "m.json:1:1: ", "wrong type"},
        {"{}", ZT_ERR_PARSE, "m.json:1:1: ", "missing \"motions\""},
        {"{\"motions\": [],\n  \"extra\": 1}", ZT_ERR_PARSE, "m.json:2:3: ",
         "unknown key \"extra\""},
        {"{\"motions\": {}}", ZT_ERR_PARSE, "m.json:1:13: ", "wrong type"},
        {"{\"motions\": [\n  1]}", ZT_ERR_PARSE, "m.json:2:3: ", "a motion must be an object"},
        /* unknown keys and types */
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"linear\",\n   \"speed\": 3}]}",
         ZT_ERR_PARSE, "m.json:3:4: ", "unknown key \"speed\" in a motion"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"spiral\"}]}", ZT_ERR_PARSE,
         "m.json:2:24: ", "unknown motion type \"spiral\""},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": 3}]}", ZT_ERR_PARSE,
         "m.json:2:24: ", "wrong type"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"Linear\", \"delta\": [1, 0, 0]}]}",
         ZT_ERR_PARSE, "m.json:2:24: ", "unknown motion type"},
        /* axis */
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"w\", \"period\": 2}]}",
         ZT_ERR_PARSE, "m.json:2:44: ", "invalid axis \"w\""},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"xy\", \"period\": 2}]}",
         ZT_ERR_PARSE, "m.json:2:44: ", "invalid axis"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"orbiting\", \"axis\": 0, \"period\": 2}]}",
         ZT_ERR_PARSE, "m.json:2:44: ", "wrong type"},
        /* targets */
        {"{\"motions\": [\n  {\"type\": \"brownian\", \"scale\": 1}]}", ZT_ERR_PARSE,
         "m.json:2:3: ", "missing target"},
        {"{\"motions\": [\n  {\"light\": 0, \"thing\": 1, \"type\": \"brownian\", \"scale\": 1}]}",
         ZT_ERR_PARSE, "m.json:2:16: ", "both \"light\" and \"thing\""},
        {"{\"motions\": [\n  {\"light\": -1, \"type\": \"brownian\", \"scale\": 1}]}",
         ZT_ERR_PARSE, "m.json:2:13: ", "out of range"},
        {"{\"motions\": [\n  {\"light\": 1.5, \"type\": \"brownian\", \"scale\": 1}]}",
         ZT_ERR_PARSE, "m.json:2:13: ", "wrong type"},
        {"{\"motions\": [\n  {\"light\": \"0\", \"type\": \"brownian\", \"scale\": 1}]}",
         ZT_ERR_PARSE, "m.json:2:13: ", "wrong type"},
        /* required fields */
        {"{\"motions\": [\n  {\"thing\": 0}]}", ZT_ERR_PARSE, "m.json:2:3: ",
         "missing \"type\""},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"x\"}]}",
         ZT_ERR_PARSE, "m.json:2:3: ", "missing \"period\" in an orbiting motion"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"orbiting\", \"period\": 3}]}",
         ZT_ERR_PARSE, "m.json:2:3: ", "missing \"axis\" in an orbiting motion"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"linear\"}]}", ZT_ERR_PARSE,
         "m.json:2:3: ", "missing \"delta\" in a linear motion"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"oscillating\", \"begin\": [0, 0, 0], \"period\": 1}]}",
         ZT_ERR_PARSE, "m.json:2:3: ", "missing \"end\" in an oscillating motion"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"brownian\"}]}", ZT_ERR_PARSE,
         "m.json:2:3: ", "missing \"scale\" in a brownian motion"},
        /* keys of another type */
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0], \"period\": 2}]}",
         ZT_ERR_PARSE, "m.json:2:54: ", "\"period\" does not apply to a linear motion"},
        /* values */
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"x\", \"period\": \"20\"}]}",
         ZT_ERR_PARSE, "m.json:2:59: ", "wrong type: expected a number"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"x\", \"period\": 0}]}",
         ZT_ERR_PARSE, "m.json:2:59: ", "period must not be 0"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0]}]}",
         ZT_ERR_PARSE, "m.json:2:43: ", "wrong length"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, \"a\"]}]}",
         ZT_ERR_PARSE, "m.json:2:50: ", "wrong type"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0], \"stop\": true}]}",
         ZT_ERR_PARSE, "m.json:2:62: ", "wrong type"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"brownian\", \"scale\": -1}]}",
         ZT_ERR_PARSE, "m.json:2:45: ", "scale must be 0 or more"},
        {"{\"motions\": [\n  {\"thing\": 0, \"type\": \"brownian\", \"scale\": 1e300}]}",
         ZT_ERR_PARSE, "m.json:2:45: ", "too large"},
    };
    check_bad_cases(cases, sizeof cases / sizeof cases[0]);
}

static void test_load_file_errors(void **state)
{
    (void)state;
    zt_motions *m = NULL;
    zt_error err;
    assert_int_equal(zt_motions_load_file(test_tmp_path("missing.json"), &m, &err), ZT_ERR_READ);
    assert_non_null(strstr(err.message, "cannot open"));
    assert_null(m);
    assert_int_equal(zt_motions_load_file(test_tmp_dir(), &m, &err), ZT_ERR_READ);
    assert_non_null(strstr(err.message, "directory"));
    const char *p = test_write_file("bad_motions.json",
                                    "{\n  \"motions\": [\n    {\"thing\": 0, \"type\": \"nope\"}\n  ]\n}\n");
    assert_int_equal(zt_motions_load_file(p, &m, &err), ZT_ERR_PARSE);
    char expect[600];
    snprintf(expect, sizeof expect, "%s:3:26: unknown motion type \"nope\"", p);
    assert_true(strncmp(err.message, expect, strlen(expect)) == 0);
    assert_int_equal(zt_motions_load_file(NULL, &m, &err), ZT_ERR_ARGUMENT);
}

/* ---- bounds ---- */

static void test_check_bounds(void **state)
{
    (void)state;
    zt_scene *s0 = load_scene();
    zt_motions *m = load_motions(
        "{\"motions\": [\n"
        "  {\"light\": 1, \"type\": \"linear\", \"delta\": [1, 0, 0]},\n"
        "  {\"thing\": 2, \"type\": \"linear\", \"delta\": [1, 0, 0]}\n"
        "]}");
    zt_error err;
    assert_int_equal(zt_motions_check(m, s0, &err), ZT_ERR_PARSE);
    assert_string_equal(err.message, "m.json:3:13: no thing 2: the scene has 2 things (0 to 1)");
    zt_scene *s = zt_scene_clone(s0);
    assert_int_equal(zt_motions_apply(m, s0, 1.0, 0, s, &err), ZT_ERR_ARGUMENT);
    zt_motions_release(m);

    m = load_motions("{\"motions\": [{\"light\": 2, \"type\": \"brownian\", \"scale\": 1}]}");
    assert_int_equal(zt_motions_check(m, s0, &err), ZT_ERR_PARSE);
    assert_string_equal(err.message, "m.json:1:24: no light 2: the scene has 2 lights (0 to 1)");
    zt_motions_release(m);

    /* a huge index is fine to load and is refused by the check */
    m = load_motions("{\"motions\": [{\"thing\": 2147483647, \"type\": \"brownian\", \"scale\": 1}]}");
    assert_int_equal(zt_motions_check(m, s0, &err), ZT_ERR_PARSE);
    zt_motions_release(m);
    zt_scene_release(s);
    zt_scene_release(s0);
}

static void test_apply_arguments(void **state)
{
    (void)state;
    zt_scene *s0 = load_scene();
    zt_scene *s = zt_scene_clone(s0);
    zt_motions *m = load_motions("{\"motions\": [{\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0]}]}");
    zt_error err;
    assert_int_equal(zt_motions_apply(m, s0, -1.0, 0, s, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_motions_apply(m, s0, NAN, 0, s, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_motions_apply(m, s0, INFINITY, 0, s, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_motions_apply(m, s0, 1.0, 0, s0, &err), ZT_ERR_ARGUMENT);
    /* a scene that is not a clone */
    zt_scene *other = NULL;
    const char *text = "{\"scene\": [], \"camera\": {\"viewpoint\": [0, 0, -10], "
                       "\"screen\": [[-1, 1, -9], [1, 1, -9], [-1, -1, -9], [1, -1, -9]], "
                       "\"gridresolution\": [8, 8]}}";
    assert_int_equal(zt_scene_load_string(text, strlen(text), "o.json", &other, &err), ZT_OK);
    assert_int_equal(zt_motions_apply(m, s0, 1.0, 0, other, &err), ZT_ERR_ARGUMENT);
    /* the camera of the output is kept */
    zt_camera cam = zt_scene_get_camera(s);
    cam.viewpoint[0] = 42;
    zt_scene_set_camera(s, &cam);
    assert_int_equal(zt_motions_apply(m, s0, 2.0, 0, s, &err), ZT_OK);
    assert_true(zt_scene_get_camera(s).viewpoint[0] == 42);
    double p[3];
    position(s, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 7, 0, 0, 1e-12);
    position(s0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 5, 0, 0, 0); /* the scene at time 0 is untouched */
    zt_scene_release(other);
    zt_motions_release(m);
    zt_scene_release(s);
    zt_scene_release(s0);
}

/* ---- evaluation ---- */

static void test_linear(void **state)
{
    (void)state;
    const char *free_text = "{\"motions\": [{\"light\": 0, \"type\": \"linear\", \"delta\": [0.5, -1, 2]}]}";
    double p[3];
    for (double t = 0; t <= 100; t += 12.5) {
        position_at(free_text, t, 0, ZT_OBJECT_LIGHT, 0, p);
        assert_near3(p, 1 + 0.5 * t, 2 - t, 3 + 2 * t, 1e-9);
    }
    /* |delta| = 5: stop 10 is reached at t = 2 */
    const char *stop_text = "{\"motions\": [{\"thing\": 0, \"type\": \"linear\", "
                            "\"delta\": [3, 4, 0], \"stop\": 10}]}";
    position_at(stop_text, 1.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 8, 4, 0, 1e-12);
    position_at(stop_text, 2.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 11, 8, 0, 1e-12);
    position_at(stop_text, 50.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 11, 8, 0, 1e-12);
    /* stop 0: never moves; negative stop: unlimited */
    position_at("{\"motions\": [{\"thing\": 0, \"type\": \"linear\", \"delta\": [3, 4, 0], \"stop\": 0}]}",
                9.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 5, 0, 0, 0);
    position_at("{\"motions\": [{\"thing\": 0, \"type\": \"linear\", \"delta\": [3, 4, 0], \"stop\": -1}]}",
                9.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 32, 36, 0, 1e-9);
    /* the other objects do not move */
    position_at(stop_text, 1.0, 0, ZT_OBJECT_LIGHT, 0, p);
    assert_near3(p, 1, 2, 3, 0);
    position_at(stop_text, 1.0, 0, ZT_OBJECT_THING, 1, p);
    assert_near3(p, 1.0 / 3, 1.0 / 3, 0, 1e-12);
}

static void test_orbiting(void **state)
{
    (void)state;
    /* the sphere at (5, 0, 0) about Z with a period of 8 s */
    const char *z = "{\"motions\": [{\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"Z\", \"period\": 8}]}";
    double p[3];
    for (double t = 0; t <= 20; t += 0.7) {
        double a = 2 * PI * t / 8;
        position_at(z, t, 0, ZT_OBJECT_THING, 0, p);
        assert_near3(p, 5 * cos(a), 5 * sin(a), 0, 1e-9);
    }
    position_at(z, 2.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 0, 5, 0, 1e-12); /* a quarter turn, right-hand rule */
    /* the light at (1, 2, 3) about X and about Y */
    const char *x = "{\"motions\": [{\"light\": 0, \"type\": \"orbiting\", \"axis\": \"x\", \"period\": 4}]}";
    position_at(x, 1.0, 0, ZT_OBJECT_LIGHT, 0, p);
    assert_near3(p, 1, -3, 2, 1e-12);
    const char *y = "{\"motions\": [{\"light\": 0, \"type\": \"orbiting\", \"axis\": \"y\", \"period\": 4}]}";
    position_at(y, 1.0, 0, ZT_OBJECT_LIGHT, 0, p);
    assert_near3(p, 3, 2, -1, 1e-12);
    /* a negative period turns the other way */
    const char *neg = "{\"motions\": [{\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"z\", \"period\": -8}]}";
    position_at(neg, 2.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 0, -5, 0, 1e-12);
    /* whole turns come back exactly (even after a long time) */
    position_at(z, 8000.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 5, 0, 0, 1e-9);
}

static void test_oscillating(void **state)
{
    (void)state;
    /* begin..end = (2, -4, 6); the object travels from its place (5, 0, 0)
     * to (7, -4, 6) in half a period and back */
    const char *text = "{\"motions\": [{\"thing\": 0, \"type\": \"oscillating\", "
                       "\"begin\": [1, 1, 1], \"end\": [3, -3, 7], \"period\": 10}]}";
    double p[3];
    for (double t = 0; t <= 30; t += 0.9) {
        double w = (1 - cos(2 * PI * t / 10)) / 2;
        position_at(text, t, 0, ZT_OBJECT_THING, 0, p);
        assert_near3(p, 5 + 2 * w, -4 * w, 6 * w, 1e-9);
    }
    position_at(text, 0.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 5, 0, 0, 0);
    position_at(text, 2.5, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 6, -2, 3, 1e-12); /* half way at a quarter period */
    position_at(text, 5.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 7, -4, 6, 1e-12); /* the full distance at half a period */
    position_at(text, 10.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 5, 0, 0, 1e-12); /* back at a full period */
    /* never beyond the end, whatever the period (the originals' amplitude
     * was period/pi^2 times too large or small) */
    const char *fast = "{\"motions\": [{\"thing\": 0, \"type\": \"oscillating\", "
                       "\"begin\": [0, 0, 0], \"end\": [1, 0, 0], \"period\": 0.5}]}";
    for (double t = 0; t < 2; t += 0.01) {
        position_at(fast, t, 0, ZT_OBJECT_THING, 0, p);
        assert_true(p[0] >= 5 - 1e-12 && p[0] <= 6 + 1e-12);
    }
}

static double dist3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

static void test_brownian(void **state)
{
    (void)state;
    const char *text = "{\"motions\": [{\"thing\": 0, \"type\": \"brownian\", \"scale\": 2}]}";
    const double start[3] = {5, 0, 0};
    double a[3], b[3], c[3];
    /* reproducible from the seed */
    position_at(text, 3.0, 7, ZT_OBJECT_THING, 0, a);
    position_at(text, 3.0, 7, ZT_OBJECT_THING, 0, b);
    assert_near3(a, b[0], b[1], b[2], 0);
    /* different between seeds */
    position_at(text, 3.0, 8, ZT_OBJECT_THING, 0, c);
    assert_true(dist3(a, c) > 1e-6);
    /* at time 0 it has not moved; one 10 ms step is 2 * 0.01 long, half a
     * step half of that (the walk is continuous) */
    position_at(text, 0.0, 7, ZT_OBJECT_THING, 0, a);
    assert_near3(a, 5, 0, 0, 0);
    position_at(text, 0.01, 7, ZT_OBJECT_THING, 0, a);
    assert_true(fabs(dist3(a, start) - 0.02) < 1e-9);
    position_at(text, 0.005, 7, ZT_OBJECT_THING, 0, b);
    assert_true(fabs(dist3(b, start) - 0.01) < 1e-9);
    assert_near3(b, (a[0] + 5) / 2, a[1] / 2, a[2] / 2, 1e-12);
    /* never farther than scale * t; a random walk of n steps of length l
     * ends about l*sqrt(n) away, far less than l*n */
    position_at(text, 100.0, 7, ZT_OBJECT_THING, 0, a);
    double d = dist3(a, start);
    assert_true(d <= 200.0);
    assert_true(d > 0.02 * sqrt(10000) * 0.05 && d < 0.02 * sqrt(10000) * 6);

    /* the same at any evaluation order: forward, backward, skipping */
    zt_scene *s0 = load_scene();
    zt_scene *s = zt_scene_clone(s0);
    zt_motions *m = load_motions(text);
    zt_error err;
    double times[] = {0.37, 1.0, 2.5, 0.2, 2.5, 10.0, 1.0};
    for (size_t i = 0; i < sizeof times / sizeof times[0]; i++) {
        double fresh[3], p[3];
        position_at(text, times[i], 5, ZT_OBJECT_THING, 0, fresh);
        assert_int_equal(zt_motions_apply(m, s0, times[i], 5, s, &err), ZT_OK);
        position(s, ZT_OBJECT_THING, 0, p);
        assert_near3(p, fresh[0], fresh[1], fresh[2], 0);
    }
    /* frame-rate independence: 100 small steps reach the same place */
    double fresh[3], p[3];
    for (int k = 0; k <= 100; k++)
        assert_int_equal(zt_motions_apply(m, s0, k * 0.0314, 9, s, &err), ZT_OK);
    position(s, ZT_OBJECT_THING, 0, p);
    position_at(text, 100 * 0.0314, 9, ZT_OBJECT_THING, 0, fresh);
    assert_near3(p, fresh[0], fresh[1], fresh[2], 0);
    /* beyond the limit of 10^6 s */
    assert_int_equal(zt_motions_apply(m, s0, 2e6, 5, s, &err), ZT_ERR_ARGUMENT);
    assert_non_null(strstr(err.message, "too late"));
    zt_motions_release(m);

    /* two brownian motions with the same seed walk differently */
    position_at("{\"motions\": [{\"thing\": 0, \"type\": \"brownian\", \"scale\": 1},"
                "{\"thing\": 1, \"type\": \"brownian\", \"scale\": 1}]}", 2.0, 3,
                ZT_OBJECT_THING, 0, a);
    position_at("{\"motions\": [{\"thing\": 0, \"type\": \"brownian\", \"scale\": 1},"
                "{\"thing\": 1, \"type\": \"brownian\", \"scale\": 1}]}", 2.0, 3,
                ZT_OBJECT_THING, 1, b);
    double da[3] = {a[0] - 5, a[1], a[2]}, db[3] = {b[0] - 1.0 / 3, b[1] - 1.0 / 3, b[2]};
    assert_true(dist3(da, db) > 1e-6);

    zt_scene_release(s);
    zt_scene_release(s0);

    /* the step directions are unit vectors spread evenly over the sphere:
     * their mean is near 0 and the mean of each squared component near 1/3
     * (the originals' directions leaned toward the cube's diagonals) */
    double mean[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
    const int n = 40000;
    for (int i = 0; i < n; i++) {
        double d[3];
        motion_brownian_direction(11, 0, i, d);
        assert_true(fabs(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1) < 1e-12);
        for (int k = 0; k < 3; k++) {
            mean[k] += d[k] / n;
            sq[k] += d[k] * d[k] / n;
        }
    }
    for (int k = 0; k < 3; k++) {
        assert_true(fabs(mean[k]) < 0.015);
        assert_true(fabs(sq[k] - 1.0 / 3) < 0.01);
    }
}

static void test_composition(void **state)
{
    (void)state;
    double p[3];
    /* two linear motions on one object add up */
    position_at("{\"motions\": ["
                "{\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0]},"
                "{\"thing\": 0, \"type\": \"linear\", \"delta\": [0, 2, 0]}]}",
                3.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 8, 6, 0, 1e-12);
    /* linear then orbiting: the moved sphere is rotated */
    const char *lin_orb = "{\"motions\": ["
                          "{\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0]},"
                          "{\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"z\", \"period\": 8}]}";
    position_at(lin_orb, 2.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 0, 7, 0, 1e-12);
    /* orbiting then linear: the rotated sphere is moved */
    const char *orb_lin = "{\"motions\": ["
                          "{\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"z\", \"period\": 8},"
                          "{\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0]}]}";
    position_at(orb_lin, 2.0, 0, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 2, 5, 0, 1e-12);
    /* two rotations: X then Y (demo_early's thing 0) */
    const char *xy = "{\"motions\": ["
                     "{\"light\": 0, \"type\": \"orbiting\", \"axis\": \"X\", \"period\": 4},"
                     "{\"light\": 0, \"type\": \"orbiting\", \"axis\": \"Y\", \"period\": 4}]}";
    position_at(xy, 1.0, 0, ZT_OBJECT_LIGHT, 0, p);
    /* (1, 2, 3) -> X quarter turn (1, -3, 2) -> Y quarter turn (2, -3, -1) */
    assert_near3(p, 2, -3, -1, 1e-12);
    /* motions of different objects are independent */
    position_at("{\"motions\": ["
                "{\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0]},"
                "{\"light\": 1, \"type\": \"linear\", \"delta\": [0, 0, -1]}]}",
                2.0, 0, ZT_OBJECT_LIGHT, 1, p);
    assert_near3(p, 0, 0, 2, 1e-12);
}

/* ---- camera paths ---- */

static void test_camera_path_load(void **state)
{
    (void)state;
    const char *text =
        "{\"motions\": [\n"
        "  {\"camera\": \"path\", \"keys\": [\n"
        "    {\"time\": 0, \"position\": [0, 0, -10], \"lookat\": [0, 0, 0]},\n"
        "    {\"time\": 1.5, \"position\": [4, 1, -8], \"lookat\": [0, 1, 0], \"up\": [0, 2, 1],\n"
        "     \"fov\": 30}]},\n"
        "  {\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0]}\n"
        "]}\n";
    zt_motions *m = load_motions(text);
    /* the camera path is not one of the motions of objects */
    assert_int_equal(zt_motions_count(m), 1);
    assert_int_equal(zt_motions_get(m, 0)->type, ZT_MOTION_LINEAR);
    assert_int_equal(zt_motions_get(m, 0)->line, 6);
    assert_true(zt_motions_moves_objects(m));
    int n = 0;
    const zt_camera_key *k = zt_motions_camera_path(m, &n);
    assert_int_equal(n, 2);
    assert_non_null(k);
    assert_true(k[0].time == 0 && k[1].time == 1.5);
    assert_near3(k[0].position, 0, 0, -10, 0);
    assert_near3(k[0].lookat, 0, 0, 0, 0);
    assert_near3(k[0].up, 0, 1, 0, 0); /* the scene file's defaults */
    assert_true(k[0].fov == 40);
    assert_near3(k[1].up, 0, 2, 1, 0); /* as written */
    assert_true(k[1].fov == 30);
    assert_int_equal(k[0].line, 3);
    assert_int_equal(k[0].column, 5);
    assert_int_equal(k[1].line, 4);
    zt_motions_release(m);

    /* a camera path alone moves no object; motions alone have no path */
    m = load_motions("{\"motions\": [{\"camera\": \"path\", \"keys\": ["
                     "{\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},"
                     "{\"time\": 1, \"position\": [1, 0, -1], \"lookat\": [0, 0, 0]}]}]}");
    assert_int_equal(zt_motions_count(m), 0);
    assert_false(zt_motions_moves_objects(m));
    assert_non_null(zt_motions_camera_path(m, &n));
    assert_int_equal(n, 2);
    zt_motions_release(m);
    m = load_motions("{\"motions\": [{\"thing\": 0, \"type\": \"brownian\", \"scale\": 1}]}");
    assert_null(zt_motions_camera_path(m, &n));
    assert_int_equal(n, 0);
    assert_true(zt_motions_moves_objects(m));
    zt_motions_release(m);
    m = load_motions("{\"motions\": []}");
    assert_false(zt_motions_moves_objects(m));
    zt_motions_release(m);

    /* a brownian walk is numbered among the motions of objects: a camera
     * path before it leaves it as it was */
    double a[3], b[3];
    position_at("{\"motions\": [{\"thing\": 0, \"type\": \"brownian\", \"scale\": 1}]}", 2.0, 3,
                ZT_OBJECT_THING, 0, a);
    position_at("{\"motions\": [{\"camera\": \"path\", \"keys\": ["
                "{\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},"
                "{\"time\": 1, \"position\": [1, 0, -1], \"lookat\": [0, 0, 0]}]},"
                "{\"thing\": 0, \"type\": \"brownian\", \"scale\": 1}]}", 2.0, 3,
                ZT_OBJECT_THING, 0, b);
    assert_near3(a, b[0], b[1], b[2], 0);
}

static void test_camera_path_errors(void **state)
{
    (void)state;
    static const bad_case cases[] = {
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"lookat\": [0, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:3: ", "missing \"position\" in a camera key"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"position\": [0, 0, -1], \"lookat\": [1, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:3: ", "missing \"time\" in a camera key"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1]}]}]}",
         ZT_ERR_PARSE, "m.json:3:3: ", "missing \"lookat\" in a camera key"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [1, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:12: ", "time 0 is not after the previous key's (0)"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": -1, \"position\": [0, 0, -1], \"lookat\": [1, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:12: ", "strictly increasing time"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [1, 2, 3], \"lookat\": [1, 2, 3]}]}]}",
         ZT_ERR_PARSE, "m.json:3:48: ", "lookat equals position"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"up\": [0, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:66: ", "up must not be zero"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"up\": [0, 0, 5]}]}]}",
         ZT_ERR_PARSE, "m.json:3:66: ", "up is parallel to the view direction"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 5, 0], \"lookat\": [0, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:3: ", "the default up (0, 1, 0) is parallel"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"up\": [0, 1e300, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:70: ", "too large"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"fov\": 0}]}]}",
         ZT_ERR_PARSE, "m.json:3:67: ", "fov out of range: 0"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"fov\": 180}]}]}",
         ZT_ERR_PARSE, "m.json:3:67: ", "fov out of range: 180"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"fov\": -5}]}]}",
         ZT_ERR_PARSE, "m.json:3:67: ", "fov out of range: -5"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"fov\": \"wide\"}]}]}",
         ZT_ERR_PARSE, "m.json:3:67: ", "wrong type"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0], \"lookat\": [0, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:27: ", "wrong length"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"roll\": 3}]}]}",
         ZT_ERR_PARSE, "m.json:3:60: ", "unknown key \"roll\" in a camera key"},
        {"{\"motions\": [{\"camera\": \"path\", \"keys\": [\n  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]},\n  3]}]}",
         ZT_ERR_PARSE, "m.json:3:3: ", "a camera key must be an object"},
        {"{\"motions\": [\n  {\"camera\": \"path\", \"keys\": [\n    {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:2:30: ", "a camera path needs at least two keys, found 1"},
        {"{\"motions\": [\n  {\"camera\": \"path\", \"keys\": []}]}",
         ZT_ERR_PARSE, "m.json:2:30: ", "found 0"},
        {"{\"motions\": [\n  {\"camera\": \"path\"}]}",
         ZT_ERR_PARSE, "m.json:2:3: ", "missing \"keys\" in a camera path"},
        {"{\"motions\": [\n  {\"camera\": \"path\", \"keys\": {}}]}",
         ZT_ERR_PARSE, "m.json:2:30: ", "wrong type: \"keys\" must be a list"},
        {"{\"motions\": [\n  {\"camera\": \"orbit\", \"keys\": []}]}",
         ZT_ERR_PARSE, "m.json:2:14: ", "unknown camera motion \"orbit\": expected \"path\""},
        {"{\"motions\": [\n  {\"camera\": 1, \"keys\": []}]}",
         ZT_ERR_PARSE, "m.json:2:14: ", "wrong type"},
        {"{\"motions\": [\n  {\"camera\": \"path\", \"type\": \"linear\", \"keys\": []}]}",
         ZT_ERR_PARSE, "m.json:2:22: ", "unknown key \"type\" in a camera path"},
        {"{\"motions\": [\n  {\"camera\": \"path\", \"speed\": 2, \"keys\": []}]}",
         ZT_ERR_PARSE, "m.json:2:22: ", "unknown key \"speed\" in a camera path"},
        {"{\"motions\": [\n  {\"camera\": \"path\", \"keys\": [{\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]}, {\"time\": 1, \"position\": [1, 0, -1], \"lookat\": [0, 0, 0]}]},\n  {\"camera\": \"path\", \"keys\": [{\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0]}, {\"time\": 1, \"position\": [1, 0, -1], \"lookat\": [0, 0, 0]}]}]}",
         ZT_ERR_PARSE, "m.json:3:4: ", "a second camera path: a motions file has at most one"},
    };
    check_bad_cases(cases, sizeof cases / sizeof cases[0]);
}

/* The camera a scene file's aimed camera with these values gives. */
static zt_camera aimed(const double pos[3], const double at[3], const double up[3], double fov,
                       int w, int h)
{
    zt_camera c;
    zt_error err;
    assert_int_equal(zt_camera_look_at(&c, pos, at, up, fov, w, h, &err), ZT_OK);
    return c;
}

static void assert_same_camera(const zt_camera *a, const zt_camera *b)
{
    if (memcmp(a, b, sizeof *a) != 0) {
        fprintf(stderr, "cameras differ: viewpoint (%.17g, %.17g, %.17g) and (%.17g, %.17g, "
                "%.17g)\n", a->viewpoint[0], a->viewpoint[1], a->viewpoint[2], b->viewpoint[0],
                b->viewpoint[1], b->viewpoint[2]);
        fail();
    }
}

/* Three keys of uneven spacing in time and in space, up and fov changing. */
static const char *three_keys =
    "{\"motions\": [{\"camera\": \"path\", \"keys\": [\n"
    "  {\"time\": 0.5, \"position\": [0, 1, -10], \"lookat\": [0, 0, 0]},\n"
    "  {\"time\": 1.5, \"position\": [4, 2, -8], \"lookat\": [1, 0.5, 0], \"up\": [0.2, 1, 0], \"fov\": 55},\n"
    "  {\"time\": 4, \"position\": [9, 3, 1], \"lookat\": [2, 0, 1], \"up\": [0, 3, 0.5], \"fov\": 35}\n"
    "]}]}\n";

static void test_camera_path_keys(void **state)
{
    (void)state;
    zt_scene *s0 = load_scene(); /* its camera: viewpoint and screen, 8 x 8 */
    zt_motions *m = load_motions(three_keys);
    int n;
    const zt_camera_key *k = zt_motions_camera_path(m, &n);
    zt_error err;
    zt_camera c;
    /* at each key's time, exactly the camera of a scene file with that key */
    for (int i = 0; i < n; i++) {
        assert_int_equal(zt_motions_camera(m, s0, k[i].time, &c, &err), ZT_OK);
        zt_camera want = aimed(k[i].position, k[i].lookat, k[i].up, k[i].fov, 8, 8);
        assert_same_camera(&c, &want);
    }
    /* still before the first key and after the last */
    zt_camera first = aimed(k[0].position, k[0].lookat, k[0].up, k[0].fov, 8, 8);
    zt_camera last = aimed(k[2].position, k[2].lookat, k[2].up, k[2].fov, 8, 8);
    for (double t = 0; t < 0.5; t += 0.125) {
        assert_int_equal(zt_motions_camera(m, s0, t, &c, &err), ZT_OK);
        assert_same_camera(&c, &first);
    }
    for (double t = 4; t < 100; t = t * 1.7 + 0.01) {
        assert_int_equal(zt_motions_camera(m, s0, t, &c, &err), ZT_OK);
        assert_same_camera(&c, &last);
    }
    /* between keys the camera moves, on the scene's pixel grid */
    assert_int_equal(zt_motions_camera(m, s0, 1.0, &c, &err), ZT_OK);
    assert_true(memcmp(&c, &first, sizeof c) != 0);
    assert_int_equal(c.width, 8);
    assert_int_equal(c.height, 8);
    assert_int_equal(zt_motions_camera(m, s0, -1.0, &c, &err), ZT_ERR_ARGUMENT);
    assert_int_equal(zt_motions_camera(m, s0, NAN, &c, &err), ZT_ERR_ARGUMENT);

    /* zt_motions_apply sets the camera (the scene's was viewpoint and
     * screen) and still moves the objects */
    zt_motions_release(m);
    char text[1024];
    snprintf(text, sizeof text, "%.*s,\n{\"thing\": 0, \"type\": \"linear\", \"delta\": [1, 0, 0]}]}\n",
             (int)(strlen(three_keys) - 3), three_keys);
    m = load_motions(text);
    zt_scene *s = zt_scene_clone(s0);
    assert_int_equal(zt_motions_apply(m, s0, 4.0, 0, s, &err), ZT_OK);
    c = zt_scene_get_camera(s);
    assert_same_camera(&c, &last);
    double p[3];
    position(s, ZT_OBJECT_THING, 0, p);
    assert_near3(p, 9, 0, 0, 1e-12);
    zt_motions_release(m);

    /* without a path the camera is the scene's */
    m = load_motions("{\"motions\": []}");
    assert_int_equal(zt_motions_camera(m, s0, 3.0, &c, &err), ZT_OK);
    zt_camera own = zt_scene_get_camera(s0);
    assert_same_camera(&c, &own);
    zt_motions_release(m);

    /* up turning from +x to -x passes through zero half way: the camera is
     * degenerate there, and the message points at the earlier key */
    m = load_motions("{\"motions\": [{\"camera\": \"path\", \"keys\": [\n"
                     "  {\"time\": 0, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"up\": [1, 0, 0]},\n"
                     "  {\"time\": 1, \"position\": [0, 0, -1], \"lookat\": [0, 0, 0], \"up\": [-1, 0, 0]}]}]}");
    assert_int_equal(zt_motions_camera(m, s0, 0.25, &c, &err), ZT_OK);
    assert_int_equal(zt_motions_camera(m, s0, 0.5, &c, &err), ZT_ERR_PARSE);
    assert_true(strncmp(err.message, "m.json:2:3: the camera path between this key and the next "
                        "is degenerate at 0.5 s", 66) == 0);
    assert_int_equal(zt_motions_apply(m, s0, 0.5, 0, s, &err), ZT_ERR_PARSE);
    zt_motions_release(m);
    zt_scene_release(s);
    zt_scene_release(s0);
}

typedef struct path_sample {
    double pos[3], at[3], up[3], fov;
} path_sample;

static path_sample sample_at(const zt_motions *m, double t)
{
    path_sample s;
    camera_path_at(&m->path, t, s.pos, s.at, s.up, &s.fov);
    return s;
}

/* Left and right difference quotients of the samples at t with step h. */
static void quotients(const zt_motions *m, double t, double h, double left[8], double right[8])
{
    path_sample a = sample_at(m, t - h), b = sample_at(m, t), c = sample_at(m, t + h);
    for (int i = 0; i < 3; i++) {
        left[i] = (b.pos[i] - a.pos[i]) / h;
        right[i] = (c.pos[i] - b.pos[i]) / h;
        left[3 + i] = (b.at[i] - a.at[i]) / h;
        right[3 + i] = (c.at[i] - b.at[i]) / h;
    }
    /* up's change measured along unit vectors (a key's up is as written) */
    double ua = a.up[1] / sqrt(a.up[0] * a.up[0] + a.up[1] * a.up[1] + a.up[2] * a.up[2]);
    double ub = b.up[1] / sqrt(b.up[0] * b.up[0] + b.up[1] * b.up[1] + b.up[2] * b.up[2]);
    double uc = c.up[1] / sqrt(c.up[0] * c.up[0] + c.up[1] * c.up[1] + c.up[2] * c.up[2]);
    left[6] = (ub - ua) / h;
    right[6] = (uc - ub) / h;
    left[7] = (b.fov - a.fov) / h;
    right[7] = (c.fov - b.fov) / h;
}

static void test_camera_path_smooth(void **state)
{
    (void)state;
    zt_motions *m = load_motions(three_keys);
    int n;
    const zt_camera_key *k = zt_motions_camera_path(m, &n);
    const double h = 1e-6;
    double left[8], right[8];
    /* across the middle key the velocity of everything is continuous, and
     * not trivially (the position and look-at point pass it moving) */
    quotients(m, k[1].time, h, left, right);
    for (int i = 0; i < 8; i++) {
        double scale = fmax(1.0, fabs(left[i]));
        if (fabs(left[i] - right[i]) > 1e-3 * scale) {
            fprintf(stderr, "component %d: %.9g before the key, %.9g after\n", i, left[i], right[i]);
            fail();
        }
    }
    assert_true(sqrt(left[0] * left[0] + left[1] * left[1] + left[2] * left[2]) > 1.0);
    assert_true(sqrt(left[3] * left[3] + left[4] * left[4] + left[5] * left[5]) > 0.1);
    /* at the first and last key the camera comes to rest, so holding
     * still outside them is continuous in velocity too */
    for (int e = 0; e < 2; e++) {
        quotients(m, k[e ? 2 : 0].time, h, left, right);
        for (int i = 0; i < 8; i++)
            assert_true(fabs(left[i]) < 1e-3 && fabs(right[i]) < 1e-3);
    }
    /* between keys: continuous (no jumps over a fine sampling), up of unit
     * length, the fov between its keys' values */
    path_sample prev = sample_at(m, k[0].time);
    for (double t = k[0].time + 1e-3; t < k[2].time; t += 1e-3) {
        path_sample s = sample_at(m, t);
        assert_true(dist3(s.pos, prev.pos) < 0.05 && dist3(s.at, prev.at) < 0.05);
        if (t != k[1].time) {
            double len = sqrt(s.up[0] * s.up[0] + s.up[1] * s.up[1] + s.up[2] * s.up[2]);
            assert_true(fabs(len - 1) < 1e-12);
        }
        int seg = t < k[1].time ? 0 : 1;
        assert_true(s.fov >= fmin(k[seg].fov, k[seg + 1].fov) &&
                    s.fov <= fmax(k[seg].fov, k[seg + 1].fov));
        prev = s;
    }
    zt_motions_release(m);
}

/* The Catmull-Rom segment from p[1] to p[2] at fraction x of its knot
 * interval, with knots spaced |p[i+1] - p[i]|^alpha: Barry and Goldman's
 * pyramid, written out here apart from the library's. */
static void catmull_rom(const double p[4][3], double alpha, double x, double out[3])
{
    double t[4] = {0, 0, 0, 0};
    for (int i = 1; i < 4; i++)
        t[i] = t[i - 1] + pow(dist3(p[i], p[i - 1]), alpha);
    double u = t[1] + x * (t[2] - t[1]);
    for (int c = 0; c < 3; c++) {
        double a1 = ((t[1] - u) * p[0][c] + (u - t[0]) * p[1][c]) / (t[1] - t[0]);
        double a2 = ((t[2] - u) * p[1][c] + (u - t[1]) * p[2][c]) / (t[2] - t[1]);
        double a3 = ((t[3] - u) * p[2][c] + (u - t[2]) * p[3][c]) / (t[3] - t[2]);
        double b1 = ((t[2] - u) * a1 + (u - t[0]) * a2) / (t[2] - t[0]);
        double b2 = ((t[3] - u) * a2 + (u - t[1]) * a3) / (t[3] - t[1]);
        out[c] = ((t[2] - u) * b1 + (u - t[1]) * b2) / (t[2] - t[1]);
    }
}

/* The fraction x in [0, 1] whose curve point is nearest q, and the distance. */
static double nearest_on_curve(const double p[4][3], const double q[3], double *x_out)
{
    const int grid = 2000;
    int best = 0;
    double best_d = INFINITY, c[3];
    for (int i = 0; i <= grid; i++) {
        catmull_rom(p, 0.5, (double)i / grid, c);
        double d = dist3(c, q);
        if (d < best_d) {
            best_d = d;
            best = i;
        }
    }
    /* golden-section search around the best grid point */
    double lo = fmax(0, (best - 1.0) / grid), hi = fmin(1, (best + 1.0) / grid);
    const double g = 0.6180339887498949;
    for (int it = 0; it < 100; it++) {
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), c1[3], c2[3];
        catmull_rom(p, 0.5, x1, c1);
        catmull_rom(p, 0.5, x2, c2);
        if (dist3(c1, q) < dist3(c2, q))
            hi = x2;
        else
            lo = x1;
    }
    *x_out = 0.5 * (lo + hi);
    catmull_rom(p, 0.5, *x_out, c);
    return dist3(c, q);
}

/* Whether the polyline through the points (in the z = 0 plane) crosses
 * itself. */
static int crosses_itself(double (*pts)[3], int n)
{
    for (int i = 0; i + 1 < n; i++)
        for (int j = i + 2; j + 1 < n; j++) {
            double rx = pts[i + 1][0] - pts[i][0], ry = pts[i + 1][1] - pts[i][1];
            double sx = pts[j + 1][0] - pts[j][0], sy = pts[j + 1][1] - pts[j][1];
            double d = rx * sy - ry * sx;
            if (fabs(d) < 1e-18)
                continue;
            double qx = pts[j][0] - pts[i][0], qy = pts[j][1] - pts[i][1];
            double u = (qx * sy - qy * sx) / d, v = (qx * ry - qy * rx) / d;
            if (u > 0 && u < 1 && v > 0 && v < 1)
                return 1;
        }
    return 0;
}

static void test_camera_path_centripetal(void **state)
{
    (void)state;
    /* Two close keys between two far ones bent back: the uniform
     * Catmull-Rom curve loops between the close keys, the centripetal one
     * does not (Yuksel, Schaefer and Keyser 2011). */
    const double p[4][3] = {{-2.5, 2.5, 0}, {0, 0, 0}, {1, 0, 0}, {-2, -1.5, 0}};
    enum { N = 200 };
    static double uniform[N][3], path[N][3];
    for (int i = 0; i < N; i++)
        catmull_rom(p, 0.0, (double)i / (N - 1), uniform[i]);
    assert_true(crosses_itself(uniform, N)); /* the configuration does test something */

    char text[1024];
    snprintf(text, sizeof text, "{\"motions\": [{\"camera\": \"path\", \"keys\": ["
             "{\"time\": 0, \"position\": [%g, %g, 0], \"lookat\": [0, 0, 10]},"
             "{\"time\": 2, \"position\": [%g, %g, 0], \"lookat\": [0, 0, 10]},"
             "{\"time\": 3, \"position\": [%g, %g, 0], \"lookat\": [0, 0, 10]},"
             "{\"time\": 7, \"position\": [%g, %g, 0], \"lookat\": [0, 0, 10]}]}]}",
             p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1], p[3][0], p[3][1]);
    zt_motions *m = load_motions(text);
    /* every position between the middle keys lies on the centripetal curve
     * computed here, and moves along it forward only */
    double last_x = -1;
    for (int i = 0; i < N; i++) {
        path_sample s = sample_at(m, 2.0 + (double)i / (N - 1));
        memcpy(path[i], s.pos, sizeof s.pos);
        double x, d = nearest_on_curve(p, s.pos, &x);
        if (d > 1e-9) {
            fprintf(stderr, "sample %d: %.3g off the curve\n", i, d);
            fail();
        }
        assert_true(x >= last_x - 1e-9);
        last_x = x;
        assert_near3(s.at, 0, 0, 10, 0);
    }
    assert_true(last_x > 1 - 1e-9);
    assert_false(crosses_itself(path, N));
    zt_motions_release(m);
}

/* ---- the render command's animation ---- */

static int files_equal(const char *a, const char *b)
{
    size_t la, lb;
    char *x = test_read_file(a, &la), *y = test_read_file(b, &lb);
    int eq = x && y && la == lb && memcmp(x, y, la) == 0;
    free(x);
    free(y);
    return eq;
}

/* The scene the animations render: a lit sphere on a floor, 24 x 24,
 * with the camera given as JSON text. */
static const char *write_lit_sphere(const char *name, const char *camera)
{
    char text[2048];
    snprintf(text, sizeof text,
        "{\"scene\": [\n"
        "  {\"lightsphere\": {\"center\": [0, 3, 0], \"radius\": 0.5, \"emission\": [20, 20, 20]}},\n"
        "  {\"sphere\": {\"center\": [2, 0, 0], \"radius\": 1,\n"
        "    \"material\": {\"character\": {\"diffuse\": 1, \"metallic\": 0, \"reflecting\": 0, \"refractive\": 0},\n"
        "                 \"color\": [0.8, 0.8, 0.8]}}},\n"
        "  {\"plane\": {\"normal\": [0, 1, 0], \"offset\": -1,\n"
        "    \"material\": {\"character\": {\"diffuse\": 1, \"metallic\": 0, \"reflecting\": 0, \"refractive\": 0},\n"
        "                 \"color\": [0.5, 0.5, 0.5]}}}\n"
        "],\n"
        "\"camera\": %s}\n", camera);
    return test_write_file(name, text);
}

static void test_render_animation(void **state)
{
    (void)state;
    char scene[512], motions[512];
    snprintf(scene, sizeof scene, "%s", write_lit_sphere("anim_scene.json",
        "{\"viewpoint\": [0, 1, -10],\n"
        "  \"screen\": [[-2, 3, -6], [2, 3, -6], [-2, -1, -6], [2, -1, -6]],\n"
        "  \"gridresolution\": [24, 24]}"));
    snprintf(motions, sizeof motions, "%s", test_write_file("anim_motions.json",
        "{\"motions\": [{\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"y\", \"period\": 4},\n"
        "              {\"light\": 0, \"type\": \"brownian\", \"scale\": 1}]}\n"));
    char args[2048], *err = NULL;
    /* three frames at 1 fps, twice: the same bytes */
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 3 --fps 1 --spp 2 "
             "--exposure 0 -o '%s/a_%%03d.png'", scene, motions, test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 0);
    assert_non_null(strstr(err, "frame 3/3 (t = 2.000 s)"));
    free(err);
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 3 --fps 1 --spp 2 "
             "--exposure 0 -o '%s/b_%%d.png' -q", scene, motions, test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 0);
    free(err);
    for (int k = 0; k < 3; k++) {
        char a[64], b[64];
        snprintf(a, sizeof a, "a_%03d.png", k);
        snprintf(b, sizeof b, "b_%d.png", k);
        assert_true(files_equal(test_tmp_path(a), test_tmp_path(b)));
    }
    /* the frames differ (the sphere moves a quarter turn a second) */
    assert_false(files_equal(test_tmp_path("a_000.png"), test_tmp_path("a_001.png")));
    /* --time 2 renders frame 2 on its own */
    snprintf(args, sizeof args, "render '%s' --motions '%s' --time 2 --spp 2 "
             "--exposure 0 -o '%s/t2.png' -q", scene, motions, test_tmp_dir());
    int rc = test_run_cli(args, &err);
    if (rc != 0)
        fprintf(stderr, "%s\n%s\n", args, err ? err : "");
    assert_int_equal(rc, 0);
    free(err);
    assert_true(files_equal(test_tmp_path("a_002.png"), test_tmp_path("t2.png")));

    /* errors: no frame number with several frames, a bad pattern, no
     * motions, a motions file that does not fit the scene */
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 2 -o '%s/x.png'",
             scene, motions, test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 1);
    assert_non_null(strstr(err, "has no frame number"));
    free(err);
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 2 -o '%s/x_%%s.png'",
             scene, motions, test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 1);
    free(err);
    snprintf(args, sizeof args, "render '%s' --frames 2 -o '%s/x_%%d.png'", scene,
             test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 1);
    assert_non_null(strstr(err, "need --motions"));
    free(err);
    char far[512];
    snprintf(far, sizeof far, "%s", test_write_file("far_motions.json",
        "{\"motions\": [\n  {\"thing\": 7, \"type\": \"brownian\", \"scale\": 1}]}\n"));
    snprintf(args, sizeof args, "render '%s' --motions '%s' -o '%s/x.png'", scene, far,
             test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 3);
    assert_non_null(strstr(err, "far_motions.json:2:13: no thing 7"));
    free(err);
    snprintf(args, sizeof args, "render '%s' --motions '%s' --fps 0 -o '%s/x.png'", scene,
             motions, test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 1);
    free(err);
}

/* Three keys one second apart; the first takes the default up and fov. */
static const char *const path_keys[3] = {
    "\"position\": [0, 1, -10], \"lookat\": [1, 0, 0]",
    "\"position\": [5, 2, -8], \"lookat\": [2, 0, 0], \"up\": [0.1, 1, 0], \"fov\": 50",
    "\"position\": [8, 3, -2], \"lookat\": [2, 0.5, 0], \"fov\": 35",
};

/* The motions file of that path, with `more` (motions of objects, or "")
 * after it. */
static const char *write_path_motions(const char *name, const char *more)
{
    char text[1024];
    snprintf(text, sizeof text, "{\"motions\": [{\"camera\": \"path\", \"keys\": [\n"
             "  {\"time\": 0, %s},\n  {\"time\": 1, %s},\n  {\"time\": 2, %s}]}%s]}\n",
             path_keys[0], path_keys[1], path_keys[2], more);
    return test_write_file(name, text);
}

/* The number of runs of consecutive lines that start with prefix: one per
 * stage of progress reported with -v. */
static int line_runs(const char *text, const char *prefix)
{
    int runs = 0, in_run = 0;
    size_t n = strlen(prefix);
    for (const char *line = text; line && *line;) {
        int match = strncmp(line, prefix, n) == 0;
        runs += match && !in_run;
        in_run = match;
        line = strchr(line, '\n');
        line = line ? line + 1 : NULL;
    }
    return runs;
}

static void run_ok(const char *args, char **err)
{
    int rc = test_run_cli(args, err);
    if (rc != 0)
        fprintf(stderr, "%s\n%s\n", args, *err ? *err : "");
    assert_int_equal(rc, 0);
}

/* Renders the still scene of key i with extra options to name. */
static void render_still(int i, const char *options, const char *name)
{
    char cam[512], file[64], args[2048], *err = NULL;
    snprintf(cam, sizeof cam, "{%s, \"gridresolution\": [24, 24]}", path_keys[i]);
    snprintf(file, sizeof file, "still_%d.json", i);
    const char *scene = write_lit_sphere(file, cam);
    snprintf(args, sizeof args, "render '%s' %s -q -o '%s'", scene, options, test_tmp_path(name));
    run_ok(args, &err);
    free(err);
}

static void test_render_camera_path(void **state)
{
    (void)state;
    /* the scene's own camera is of the viewpoint and screen form */
    char scene[512], motions[512], moving[512], args[2048], *err = NULL;
    snprintf(scene, sizeof scene, "%s", write_lit_sphere("path_scene.json",
             "{\"viewpoint\": [0, 1, -10], \"screen\": [[-2, 3, -6], [2, 3, -6], [-2, -1, -6], "
             "[2, -1, -6]], \"gridresolution\": [24, 24]}"));
    snprintf(motions, sizeof motions, "%s", write_path_motions("path_motions.json", ""));

    /* zone: frames at the keys' times are the still renders of the keys'
     * cameras, byte for byte, and Phase One ran once for five frames */
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 5 --fps 2 --method zone "
             "-v -o '%s/pz_%%d.pfm'", scene, motions, test_tmp_dir());
    run_ok(args, &err);
    assert_int_equal(line_runs(err, "phase one 1/"), 1);
    assert_non_null(strstr(err, "forest built once for 5 frames"));
    free(err);
    for (int i = 0; i < 3; i++) {
        char still[64], frame[64];
        snprintf(still, sizeof still, "pz_still_%d.pfm", i);
        snprintf(frame, sizeof frame, "pz_%d.pfm", 2 * i);
        render_still(i, "--method zone", still);
        test_assert_same_file(test_tmp_path(frame), test_tmp_path(still));
    }
    assert_false(files_equal(test_tmp_path("pz_0.pfm"), test_tmp_path("pz_1.pfm")));
    assert_false(files_equal(test_tmp_path("pz_1.pfm"), test_tmp_path("pz_2.pfm")));

    /* path tracer: the same, with a sample count whose averages round */
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 3 --fps 1 --spp 3 "
             "-o '%s/pp_%%d.pfm'", scene, motions, test_tmp_dir());
    run_ok(args, &err);
    assert_non_null(strstr(err, "scene prepared once for 3 frames"));
    free(err);
    for (int i = 0; i < 3; i++) {
        char still[64], frame[64];
        snprintf(still, sizeof still, "pp_still_%d.pfm", i);
        snprintf(frame, sizeof frame, "pp_%d.pfm", i);
        render_still(i, "--spp 3", still);
        test_assert_same_file(test_tmp_path(frame), test_tmp_path(still));
    }

    /* when a light moves too, every frame builds its forest; the path still
     * sets the camera (at time 0 the light has not moved yet) */
    snprintf(moving, sizeof moving, "%s", write_path_motions("path_moving.json",
             ",\n  {\"light\": 0, \"type\": \"linear\", \"delta\": [0, 0.5, 0]}"));
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 3 --fps 1 --method zone "
             "-v -o '%s/pm_%%d.pfm'", scene, moving, test_tmp_dir());
    run_ok(args, &err);
    assert_int_equal(line_runs(err, "phase one 1/"), 3);
    assert_non_null(strstr(err, "forest built for every frame (lights or things move)"));
    free(err);
    test_assert_same_file(test_tmp_path("pm_0.pfm"), test_tmp_path("pz_still_0.pfm"));
    assert_false(files_equal(test_tmp_path("pm_2.pfm"), test_tmp_path("pz_still_2.pfm")));

    /* a path that degenerates between keys is refused before any frame */
    const char *bad = test_write_file("path_degenerate.json",
        "{\"motions\": [{\"camera\": \"path\", \"keys\": [\n"
        "  {\"time\": 0, \"position\": [0, 1, -10], \"lookat\": [0, 0, 0], \"up\": [1, 0, 0]},\n"
        "  {\"time\": 1, \"position\": [0, 1, -10], \"lookat\": [0, 0, 0], \"up\": [-1, 0, 0]}]}]}\n");
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames 3 --fps 4 -o '%s/pd_%%d.pfm'",
             scene, bad, test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 3);
    assert_non_null(strstr(err, "path_degenerate.json:2:3: the camera path between this key and "
                            "the next is degenerate at 0.5 s"));
    free(err);
    FILE *f = fopen(test_tmp_path("pd_0.pfm"), "rb");
    assert_null(f);
}

static double compare_mean_abs(const zt_image *a, const zt_image *b)
{
    size_t n = 3 * (size_t)a->width * (size_t)a->height;
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += fabs((double)a->pixels[i] - (double)b->pixels[i]);
    return sum / (double)n;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void test_render_camera_path_smooth(void **state)
{
    (void)state;
    char scene[512], motions[512], args[2048], *err = NULL;
    snprintf(scene, sizeof scene, "%s", write_lit_sphere("smooth_scene.json",
             "{\"position\": [0, 1, -10], \"lookat\": [0, 0, 0], \"gridresolution\": [24, 24]}"));
    snprintf(motions, sizeof motions, "%s", write_path_motions("smooth_motions.json", ""));
    enum { FRAMES = 9 };
    snprintf(args, sizeof args, "render '%s' --motions '%s' --frames %d --fps 4 --method zone "
             "-q -o '%s/ps_%%d.pfm'", scene, motions, FRAMES, test_tmp_dir());
    run_ok(args, &err);
    free(err);
    zt_image *img[FRAMES];
    for (int k = 0; k < FRAMES; k++) {
        char name[64];
        zt_error e;
        snprintf(name, sizeof name, "ps_%d.pfm", k);
        assert_int_equal(zt_image_read(test_tmp_path(name), &img[k], &e), ZT_OK);
    }
    /* consecutive frames all differ, and none by more than twice the
     * median difference: no jumps, at the keys (frames 4 and 8) or
     * elsewhere */
    double d[FRAMES - 1], sorted[FRAMES - 1];
    for (int k = 0; k + 1 < FRAMES; k++)
        sorted[k] = d[k] = compare_mean_abs(img[k], img[k + 1]);
    qsort(sorted, FRAMES - 1, sizeof sorted[0], cmp_double);
    double median = 0.5 * (sorted[(FRAMES - 1) / 2 - 1] + sorted[(FRAMES - 1) / 2]);
    for (int k = 0; k + 1 < FRAMES; k++) {
        if (!(d[k] > 0 && d[k] <= 2 * median)) {
            fprintf(stderr, "frames %d and %d differ by %.4g, the median is %.4g\n", k, k + 1,
                    d[k], median);
            fail();
        }
    }
    for (int k = 0; k < FRAMES; k++)
        zt_image_release(img[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_load_all_types),
        cmocka_unit_test(test_load_shipped),
        cmocka_unit_test(test_load_errors),
        cmocka_unit_test(test_load_file_errors),
        cmocka_unit_test(test_check_bounds),
        cmocka_unit_test(test_apply_arguments),
        cmocka_unit_test(test_linear),
        cmocka_unit_test(test_orbiting),
        cmocka_unit_test(test_oscillating),
        cmocka_unit_test(test_brownian),
        cmocka_unit_test(test_composition),
        cmocka_unit_test(test_render_animation),
        cmocka_unit_test(test_camera_path_load),
        cmocka_unit_test(test_camera_path_errors),
        cmocka_unit_test(test_camera_path_keys),
        cmocka_unit_test(test_camera_path_smooth),
        cmocka_unit_test(test_camera_path_centripetal),
        cmocka_unit_test(test_render_camera_path),
        cmocka_unit_test(test_render_camera_path_smooth),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
