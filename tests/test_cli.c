/* The command line's contract: exit codes, messages, no partial output. */
#include "test_support.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "zonetrace/zonetrace.h"

static const char *tiny_scene =
    "{ \"scene\": [\n"
    "  { \"lightpoint\": { \"point\": [0, 4, 0], \"emission\": [10, 10, 10] } },\n"
    "  { \"plane\": { \"normal\": [0, 1, 0], \"offset\": -1,\n"
    "      \"material\": { \"character\": { \"diffuse\": 1, \"metallic\": 0, \"reflecting\": 0, \"refractive\": 0 },\n"
    "                    \"color\": [0.5, 0.5, 0.5] } } }\n"
    "  ],\n"
    "  \"camera\": { \"viewpoint\": [0, 0, 5], \"screen\": [[-1, 1, 4], [1, 1, 4], [-1, -1, 4], [1, -1, 4]],\n"
    "              \"gridresolution\": [8, 8] } }\n";

static void expect(const char *args, int code, const char *needle)
{
    char *err = NULL;
    int got = test_run_cli(args, &err);
    if (got != code || (needle && (!err || !strstr(err, needle))))
        fprintf(stderr, "args: %s\nexit %d (wanted %d)\nstderr: %s\n", args, got, code,
                err ? err : "(none)");
    assert_int_equal(got, code);
    if (needle)
        assert_non_null(strstr(err, needle));
    free(err);
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void test_usage_errors(void **state)
{
    (void)state;
    char scene[512];
    snprintf(scene, sizeof scene, "%s", test_write_file("tiny.json", tiny_scene));
    char args[4096];
    expect("", 1, "usage");
    expect("--bogus", 1, "unknown option");
    snprintf(args, sizeof args, "render '%s' --spp 0", scene);
    expect(args, 1, "--spp");
    snprintf(args, sizeof args, "render '%s' --spp 12abc", scene);
    expect(args, 1, "--spp");
    snprintf(args, sizeof args, "render '%s' --size 0x5", scene);
    expect(args, 1, "--size");
    snprintf(args, sizeof args, "render '%s' --method magic", scene);
    expect(args, 1, "--method");
    snprintf(args, sizeof args, "render '%s' --level 5 --depth 2", scene);
    expect(args, 1, "deeper");
    snprintf(args, sizeof args, "render '%s' --lights-off 3 -o '%s'", scene, test_tmp_path("x.pfm"));
    expect(args, 1, "light 3");
    snprintf(args, sizeof args, "render '%s' -o '%s'", scene, test_tmp_path("x.bmp"));
    expect(args, 1, "format");
    snprintf(args, sizeof args, "render '%s' '%s'", scene, scene);
    expect(args, 1, "one scene");
    expect("render", 1, "no scene");
    expect("render --help", 0, NULL);
    expect("--version", 0, NULL);
}

static void test_input_errors(void **state)
{
    (void)state;
    char args[4096];
    snprintf(args, sizeof args, "render '%s' -o '%s'", test_tmp_path("missing.json"),
             test_tmp_path("o.pfm"));
    expect(args, 2, "missing.json");
    snprintf(args, sizeof args, "render '%s' -o '%s'", test_tmp_dir(), test_tmp_path("o.pfm"));
    expect(args, 2, NULL);
    const char *bad = test_write_file("bad.json", "{ \"scene\": [ { \"sphere\": { \"radius\": -1 } ] }");
    snprintf(args, sizeof args, "render '%s' -o '%s'", bad, test_tmp_path("o.pfm"));
    expect(args, 3, "bad.json:1");
    assert_false(exists(test_tmp_path("o.pfm")));
}

static void test_output_errors(void **state)
{
    (void)state;
    char scene[512];
    snprintf(scene, sizeof scene, "%s", test_write_file("tiny2.json", tiny_scene));
    char args[4096];
    snprintf(args, sizeof args, "render '%s' -o '%s/no/such/dir/x.png'", scene, test_tmp_dir());
    expect(args, 4, "not writable");
    const char *dir = test_tmp_path("dir.png");
    mkdir(dir, 0700);
    snprintf(args, sizeof args, "render '%s' -o '%s'", scene, dir);
    expect(args, 4, "directory");
}

static void test_render_and_compare(void **state)
{
    (void)state;
    char scene[512];
    snprintf(scene, sizeof scene, "%s", test_write_file("tiny3.json", tiny_scene));
    char a[512], b[512];
    snprintf(a, sizeof a, "%s", test_tmp_path("a.pfm"));
    snprintf(b, sizeof b, "%s", test_tmp_path("b.pfm"));
    char args[4096];
    snprintf(args, sizeof args, "render '%s' --spp 4 -o '%s' -q", scene, a);
    expect(args, 0, NULL);
    snprintf(args, sizeof args, "'%s' --spp 4 -o '%s'", scene, b); /* shorthand */
    expect(args, 0, "rays");
    zt_image *ia = NULL, *ib = NULL;
    assert_int_equal(zt_image_read(a, &ia, NULL), ZT_OK);
    assert_int_equal(zt_image_read(b, &ib, NULL), ZT_OK);
    assert_int_equal(ia->width, 8);
    assert_memory_equal(ia->pixels, ib->pixels, 8 * 8 * 3 * sizeof(float));
    zt_image_release(ia);
    zt_image_release(ib);

    /* compare prints "name value" lines; identical images give 0. */
    const char *out = test_tmp_path("compare.txt");
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s' compare '%s' '%s' > '%s'", ZT_CLI_PATH, a, b, out);
    assert_int_equal(system(cmd), 0);
    char *text = test_read_file(out, NULL);
    assert_non_null(strstr(text, "rel_rmse 0\n"));
    assert_non_null(strstr(text, "rmse 0\n"));
    free(text);
    snprintf(args, sizeof args, "compare '%s' '%s'", a, test_tmp_path("nothing.pfm"));
    expect(args, 2, "nothing.pfm");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_usage_errors),
        cmocka_unit_test(test_input_errors),
        cmocka_unit_test(test_output_errors),
        cmocka_unit_test(test_render_and_compare),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
