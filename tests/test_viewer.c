/* The interactive viewer, driven by replay scripts in a virtual X server
 * (xvfb-run): its screenshots must show the scene, change when the camera
 * moves, darken when the light is switched off, show the HUD, and follow
 * the motions of the original dancingLights scene and a camera path.
 * Skipped (with a message) when xvfb-run is missing or the viewer is not
 * built. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "test_support.h"
#include "zonetrace/zonetrace.h"

static int have_viewer(void)
{
    if (system("command -v xvfb-run >/dev/null 2>&1") != 0) {
        fprintf(stderr, "note: xvfb-run is missing; the viewer tests are skipped "
                        "(scripts/install-deps.sh installs it)\n");
        return 0;
    }
    char *err = NULL;
    int rc = test_run_cli("view --help >/dev/null", &err);
    free(err);
    if (rc != 0) {
        fprintf(stderr, "note: this build has no viewer; the viewer tests are skipped\n");
        return 0;
    }
    return 1;
}

/* Runs "zonetrace view ARGS" in a virtual X server, in directory dir
 * (NULL: the test's directory); returns its exit status, with stderr in
 * *err_out. */
static int run_view(const char *dir, const char *args, char **err_out)
{
    const char *errpath = test_tmp_path("view_stderr.txt");
    char errcopy[512];
    snprintf(errcopy, sizeof errcopy, "%s", errpath);
    char cmd[8192];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && xvfb-run -a -s '-screen 0 640x480x24 -nolisten tcp' "
             "'%s' view %s 2>'%s' </dev/null",
             dir ? dir : test_tmp_dir(), ZT_CLI_PATH, args, errcopy);
    int status = system(cmd);
    char *err = test_read_file(errcopy, NULL);
    if (err_out)
        *err_out = err;
    else
        free(err);
    if (status == -1 || !WIFEXITED(status))
        return -1;
    return WEXITSTATUS(status);
}

static zt_image *read_shot(const char *name)
{
    zt_image *img = NULL;
    zt_error err;
    zt_status st = zt_image_read(test_tmp_path(name), &img, &err);
    if (st != ZT_OK)
        fprintf(stderr, "%s\n", err.message);
    assert_int_equal(st, ZT_OK);
    return img;
}

typedef struct stats {
    double mean, var;
    double rgb[3];
} stats;

/* Mean and variance of the luminance-like average of the channels, and
 * the channel means, over the rectangle [x0, x1) x [y0, y1) in fractions
 * of the size. */
static stats region(const zt_image *img, double x0, double x1, double y0, double y1)
{
    stats s;
    memset(&s, 0, sizeof s);
    int xa = (int)(x0 * img->width), xb = (int)(x1 * img->width);
    int ya = (int)(y0 * img->height), yb = (int)(y1 * img->height);
    double n = 0, sum = 0, sum2 = 0;
    for (int y = ya; y < yb; y++)
        for (int x = xa; x < xb; x++) {
            const float *p = zt_image_pixel(img, x, y);
            double v = (p[0] + p[1] + p[2]) / 3.0;
            sum += v;
            sum2 += v * v;
            for (int k = 0; k < 3; k++)
                s.rgb[k] += p[k];
            n++;
        }
    s.mean = sum / n;
    s.var = sum2 / n - s.mean * s.mean;
    for (int k = 0; k < 3; k++)
        s.rgb[k] /= n;
    return s;
}

static double mean_abs_diff(const zt_image *a, const zt_image *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    size_t n = (size_t)a->width * (size_t)a->height * 3;
    double d = 0;
    for (size_t i = 0; i < n; i++)
        d += fabs(a->pixels[i] - b->pixels[i]);
    return d / (double)n;
}

/* Pixels of the HUD's yellow (1, 1, 0.4) in the top-left corner. */
static int yellow_pixels(const zt_image *img)
{
    int count = 0;
    for (int y = 0; y < img->height / 3; y++)
        for (int x = 0; x < img->width / 2; x++) {
            const float *p = zt_image_pixel(img, x, y);
            if (p[0] > 0.9f && p[1] > 0.9f && p[2] > 0.08f && p[2] < 0.45f)
                count++;
        }
    return count;
}

static void test_cornell(void **state)
{
    (void)state;
    if (!have_viewer())
        skip();
    /* the script: a still image, a turn, the light off, the HUD, the 'p'
     * key; each screenshot waits until the frame shows the current state
     * with at least the given samples per pixel */
    const char *replay = test_write_file("cornell.replay",
        "# cornell box checks\n"
        "0.2 screenshot base.png 4\n"
        "0.3 key y 0.02          # three 0.1 rad turns to the left\n"
        "0.4 screenshot turned.png 4\n"
        "0.5 key r               # back home\n"
        "0.5 key f1              # light 0 off\n"
        "0.6 screenshot dark.png 2\n"
        "0.7 key f1; 0.7 key u   # light on, HUD on\n"
        "0.8 screenshot hud.png 4\n"
        "0.9 key p\n"
        "1.0 quit\n");
    char replay_path[512];
    snprintf(replay_path, sizeof replay_path, "%s", replay);
    char args[2048], *err = NULL;
    snprintf(args, sizeof args, "'%s/scenes/cornell.json' --size 128x128 --fps 20 "
             "--replay '%s' --exit-after 60", ZT_SOURCE_DIR, replay_path);
    int rc = run_view(NULL, args, &err);
    if (rc != 0)
        fprintf(stderr, "exit %d:\n%s\n", rc, err ? err : "");
    assert_int_equal(rc, 0);
    assert_non_null(strstr(err, "saved base.png"));
    free(err);

    zt_image *base = read_shot("base.png");
    assert_int_equal(base->width, 128);
    assert_int_equal(base->height, 128);
    stats all = region(base, 0, 1, 0, 1);
    fprintf(stderr, "base: mean %.4f, variance %.4f\n", all.mean, all.var);
    assert_true(all.mean > 0.05);
    assert_true(all.var > 0.002);
    /* the red wall on the left, the green one on the right */
    stats left = region(base, 0.02, 0.12, 0.3, 0.7);
    stats right = region(base, 0.88, 0.98, 0.3, 0.7);
    fprintf(stderr, "left wall rgb (%.3f %.3f %.3f), right wall (%.3f %.3f %.3f)\n",
            left.rgb[0], left.rgb[1], left.rgb[2], right.rgb[0], right.rgb[1], right.rgb[2]);
    assert_true(left.rgb[0] > 2 * left.rgb[1] && left.rgb[0] > 2 * left.rgb[2]);
    assert_true(right.rgb[1] > 1.2 * right.rgb[0] && right.rgb[1] > 2 * right.rgb[2]);
    /* no HUD unless asked for */
    assert_true(yellow_pixels(base) < 5);

    zt_image *turned = read_shot("turned.png");
    double d = mean_abs_diff(base, turned);
    fprintf(stderr, "turned: mean difference %.4f\n", d);
    assert_true(d > 0.03);

    zt_image *dark = read_shot("dark.png");
    stats dk = region(dark, 0, 1, 0, 1);
    fprintf(stderr, "light off: mean %.4f\n", dk.mean);
    assert_true(dk.mean < 0.2 * all.mean);

    zt_image *hud = read_shot("hud.png");
    int yellow = yellow_pixels(hud);
    fprintf(stderr, "hud: %d yellow pixels\n", yellow);
    assert_true(yellow > 40);
    /* under the HUD it is the same scene again */
    stats hb = region(hud, 0.5, 1, 0.5, 1), bb = region(base, 0.5, 1, 0.5, 1);
    assert_true(fabs(hb.mean - bb.mean) < 0.25 * bb.mean);

    /* the 'p' key wrote zonetrace-shot-0001.png in the current directory */
    zt_image *shot = read_shot("zonetrace-shot-0001.png");
    assert_int_equal(shot->width, 128);
    zt_image_release(shot);
    zt_image_release(hud);
    zt_image_release(dark);
    zt_image_release(turned);
    zt_image_release(base);
}

static void test_dancing_lights(void **state)
{
    (void)state;
    const char *shared = test_shared_dir();
    if (!shared || !have_viewer())
        skip();
    char args[2048], *err = NULL;
    snprintf(args, sizeof args,
             "'%s/scenes/retra/dancingLights.json' --motions "
             "'%s/scenes/retra/dancingLights_motions.json' --size 96x72 --fps 20 "
             "--hud --script '0.5 screenshot t05.png; 3 screenshot t3.png; 3.1 quit' "
             "--exit-after 60", shared, shared);
    int rc = run_view(NULL, args, &err);
    if (rc != 0)
        fprintf(stderr, "exit %d:\n%s\n", rc, err ? err : "");
    assert_int_equal(rc, 0);
    free(err);
    zt_image *a = read_shot("t05.png"), *b = read_shot("t3.png");
    stats sa = region(a, 0, 1, 0.4, 1);
    assert_true(sa.mean > 0.01);
    /* the three coloured lights orbit a quarter of a turn in 5 s */
    double d = mean_abs_diff(a, b);
    fprintf(stderr, "dancingLights: t=0.5 s vs t=3 s mean difference %.4f\n", d);
    assert_true(d > 0.02);
    zt_image_release(a);
    zt_image_release(b);
}

static void test_zone_method(void **state)
{
    (void)state;
    if (!have_viewer())
        skip();
    /* the zone tracer, or, where it cannot render, a message and the path
     * tracer; either way a picture and no crash */
    char args[2048], *err = NULL;
    snprintf(args, sizeof args, "'%s/scenes/cornell.json' --size 64x64 --method zone "
             "--depth 1 --script '0.2 screenshot zone.png; 0.3 key m; "
             "0.4 screenshot path.png; 0.5 quit' --exit-after 60", ZT_SOURCE_DIR);
    int rc = run_view(NULL, args, &err);
    if (rc != 0)
        fprintf(stderr, "exit %d:\n%s\n", rc, err ? err : "");
    assert_int_equal(rc, 0);
    if (strstr(err, "zone tracer:"))
        fprintf(stderr, "the zone tracer is not available: %s", strstr(err, "zone tracer:"));
    free(err);
    zt_image *z = read_shot("zone.png"), *p = read_shot("path.png");
    assert_true(region(z, 0, 1, 0, 1).mean > 0.03);
    assert_true(region(p, 0, 1, 0, 1).mean > 0.03);
    zt_image_release(z);
    zt_image_release(p);
}

static void test_zone_fallback(void **state)
{
    (void)state;
    if (!have_viewer())
        skip();
    /* a zone tracer that cannot render (ZT_VIEW_FAIL_ZONE makes it fail as
     * ZT_ERR_UNSUPPORTED would): a message, and the path tracer instead */
    char args[2048], *err = NULL;
    snprintf(args, sizeof args, "'%s/scenes/cornell.json' --size 64x64 --method zone "
             "--hud --script '0.2 screenshot fallback.png 2; 0.3 key m; "
             "0.4 screenshot again.png 2; 0.5 quit' --exit-after 60", ZT_SOURCE_DIR);
    char env_args[2200];
    snprintf(env_args, sizeof env_args, "%s", args);
    setenv("ZT_VIEW_FAIL_ZONE", "1", 1);
    int rc = run_view(NULL, env_args, &err);
    unsetenv("ZT_VIEW_FAIL_ZONE");
    if (rc != 0)
        fprintf(stderr, "exit %d:\n%s\n", rc, err ? err : "");
    assert_int_equal(rc, 0);
    const char *msg = strstr(err, "zone tracer: not available");
    assert_non_null(msg);
    assert_non_null(strstr(msg, "showing the path tracer"));
    /* asked for twice (at the start, and m), reported twice */
    assert_non_null(strstr(msg + 1, "zone tracer: not available"));
    free(err);
    zt_image *a = read_shot("fallback.png"), *b = read_shot("again.png");
    assert_true(region(a, 0, 1, 0.5, 1).mean > 0.05);
    assert_true(yellow_pixels(a) > 20);
    assert_true(region(b, 0, 1, 0.5, 1).mean > 0.05);
    zt_image_release(a);
    zt_image_release(b);
}

static void test_camera_path(void **state)
{
    (void)state;
    if (!have_viewer())
        skip();
    /* The Cornell box's camera swings to the left wall and holds still
     * there after 1 s: the view then converges to the one of a path that
     * stands at that camera from the start. */
    const char *key_end = "\"position\": [120, 300, -500], \"lookat\": [300, 200, 300], \"fov\": 45";
    char text[1024], moving[512], still[512];
    snprintf(text, sizeof text, "{\"motions\": [{\"camera\": \"path\", \"keys\": [\n"
             "  {\"time\": 0, \"position\": [278, 273, -800], \"lookat\": [278, 273, 0], "
             "\"fov\": 37},\n  {\"time\": 1, %s}]}]}\n", key_end);
    snprintf(moving, sizeof moving, "%s", test_write_file("view_path.json", text));
    snprintf(text, sizeof text, "{\"motions\": [{\"camera\": \"path\", \"keys\": [\n"
             "  {\"time\": 0, %s},\n  {\"time\": 1, %s}]}]}\n", key_end, key_end);
    snprintf(still, sizeof still, "%s", test_write_file("view_path_still.json", text));
    char args[2048], *err = NULL;
    snprintf(args, sizeof args, "'%s/scenes/cornell.json' --motions '%s' --size 64x64 --fps 20 "
             "--script '0.05 screenshot path_start.png 1; 2.5 screenshot path_end.png 64; "
             "2.6 quit' --exit-after 60", ZT_SOURCE_DIR, moving);
    int rc = run_view(NULL, args, &err);
    if (rc != 0)
        fprintf(stderr, "exit %d:\n%s\n", rc, err ? err : "");
    assert_int_equal(rc, 0);
    free(err);
    snprintf(args, sizeof args, "'%s/scenes/cornell.json' --motions '%s' --size 64x64 --fps 20 "
             "--script '0.5 screenshot path_still.png 64; 0.6 quit' --exit-after 60",
             ZT_SOURCE_DIR, still);
    rc = run_view(NULL, args, &err);
    if (rc != 0)
        fprintf(stderr, "exit %d:\n%s\n", rc, err ? err : "");
    assert_int_equal(rc, 0);
    free(err);
    zt_image *a = read_shot("path_start.png"), *b = read_shot("path_end.png");
    zt_image *c = read_shot("path_still.png");
    double moved = mean_abs_diff(a, c), arrived = mean_abs_diff(b, c);
    fprintf(stderr, "camera path: start %.4f from the end's camera, end %.4f\n", moved, arrived);
    assert_true(moved > 0.05);
    assert_true(arrived < 0.2 * moved);
    zt_image_release(a);
    zt_image_release(b);
    zt_image_release(c);
}

static void test_bad_arguments(void **state)
{
    (void)state;
    char *err = NULL;
    int built = test_run_cli("view --help >/dev/null", &err) == 0;
    free(err);
    if (!built) {
        /* the stub explains itself */
        assert_int_equal(test_run_cli("view x.json", &err), 1);
        assert_non_null(strstr(err, "no viewer"));
        free(err);
        skip();
    }
    /* these fail before a window is opened: no X server needed */
    assert_int_equal(test_run_cli("view", &err), 1);
    assert_non_null(strstr(err, "no scene file"));
    free(err);
    assert_int_equal(test_run_cli("view /nonexistent/scene.json", &err), 2);
    free(err);
    char args[2048];
    snprintf(args, sizeof args, "view '%s/scenes/cornell.json' --fps 0", ZT_SOURCE_DIR);
    assert_int_equal(test_run_cli(args, &err), 1);
    assert_non_null(strstr(err, "--fps"));
    free(err);
    snprintf(args, sizeof args, "view '%s/scenes/cornell.json' --script '1 jump'",
             ZT_SOURCE_DIR);
    assert_int_equal(test_run_cli(args, &err), 1);
    assert_non_null(strstr(err, "--script:1: unknown command 'jump'"));
    free(err);
    snprintf(args, sizeof args, "view '%s/scenes/cornell.json' --script '0.5 quit; 0.5 key nokey'",
             ZT_SOURCE_DIR);
    assert_int_equal(test_run_cli(args, &err), 1);
    assert_non_null(strstr(err, "unknown key 'nokey'"));
    free(err);
    snprintf(args, sizeof args, "view '%s/scenes/cornell.json' --replay /nonexistent.replay",
             ZT_SOURCE_DIR);
    assert_int_equal(test_run_cli(args, &err), 2);
    free(err);
    snprintf(args, sizeof args, "view '%s/scenes/cornell.json' --lights-off 3", ZT_SOURCE_DIR);
    assert_int_equal(test_run_cli(args, &err), 1);
    assert_non_null(strstr(err, "no light 3"));
    free(err);
    char bad[512];
    snprintf(bad, sizeof bad, "%s", test_write_file("bad_view_motions.json",
        "{\"motions\": [\n  {\"thing\": 9, \"type\": \"brownian\", \"scale\": 1}]}\n"));
    snprintf(args, sizeof args, "view '%s/scenes/cornell.json' --motions '%s'",
             ZT_SOURCE_DIR, bad);
    assert_int_equal(test_run_cli(args, &err), 3);
    assert_non_null(strstr(err, "bad_view_motions.json:2:13: no thing 9"));
    free(err);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_cornell),
        cmocka_unit_test(test_dancing_lights),
        cmocka_unit_test(test_zone_method),
        cmocka_unit_test(test_zone_fallback),
        cmocka_unit_test(test_camera_path),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
