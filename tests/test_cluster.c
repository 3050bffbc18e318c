/* Rendering across processes (docs/cluster.md): `mpirun -n R zonetrace
 * render` writes the same bytes as one process, for R = 1, 2 and 3, with
 * the path tracer (also resumed at another R), the zone tracer (both
 * strategies, a model whose nodes share cuts, and its forest file) and an
 * animation; a process that fails
 * ends the job with the message and status one process would give, never a
 * hang.  (A build without MPI skips this; test_cluster_single tests its
 * refusal under mpirun.) */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "test_support.h"

#ifdef ZT_MPIEXEC
#define JOB_SECONDS "120" /* a job that hangs is killed, and the test fails */

/* Runs "mpiexec -n ranks zonetrace ARGS"; args may hold MPMD parts
 * (" : -n 1 zonetrace ..."), with @ZT@ standing for the program. */
static int run_job(int ranks, const char *args, char **err_out)
{
    char expanded[8192] = "", *o = expanded;
    for (const char *p = args; *p && o < expanded + sizeof expanded - 600; p++) {
        if (!strncmp(p, "@ZT@", 4)) {
            o += sprintf(o, "'%s'", ZT_CLI_PATH);
            p += 3;
        } else {
            *o++ = *p;
        }
    }
    *o = '\0';
    const char *errpath = test_tmp_path("job_stderr.txt");
    char cmd[10000];
    snprintf(cmd, sizeof cmd, "timeout " JOB_SECONDS " '%s' --oversubscribe -n %d '%s' %s "
             "2>'%s' </dev/null", ZT_MPIEXEC, ranks, ZT_CLI_PATH, expanded, errpath);
    int status = system(cmd);
    char *err = test_read_file(errpath, NULL);
    if (err_out)
        *err_out = err;
    else
        free(err);
    if (status == -1 || !WIFEXITED(status))
        return -1;
    assert_int_not_equal(WEXITSTATUS(status), 124); /* timeout: a hang */
    return WEXITSTATUS(status);
}

static const char *cornell(void)
{
    static char path[1024];
    snprintf(path, sizeof path, "%s/scenes/cornell.json", ZT_SOURCE_DIR);
    return path;
}

/* A smooth OBJ sheet of fine squares facing down over a lit floor, a
 * small triangle far away setting the node spacing: its vertex nodes share
 * cuts in groups, whose members the process of their leader computes. */
static const char *sheet_scene(void)
{
    static char path[1024];
    if (path[0])
        return path;
    enum { SQUARES = 30 };
    static char obj[(SQUARES + 1) * (SQUARES + 1) * 40 + SQUARES * SQUARES * 80 + 64];
    size_t len = (size_t)snprintf(obj, sizeof obj, "vn 0 -1 0\n");
    test_obj_sheet(obj, len, sizeof obj, SQUARES, 0.5, 20, 1);
    char objpath[1024], text[2048];
    snprintf(objpath, sizeof objpath, "%s", test_write_file("job_sheet.obj", obj));
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [8, 5, -40], \"lookat\": [8, 12, 8], "
             "\"up\": [0, 1, 0], \"fov\": 50, \"gridresolution\": [8, 8]}, \"scene\": ["
             "{\"light\": {\"emission\": [40, 40, 40], \"backculled\": false, \"parts\": ["
             "{\"lighttriangle\": {\"points\": [[25, 10, 0], [35, 10, 15], [35, 10, 0]]}}]}},"
             "{\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, " TEST_DIFFUSE(0.7) "}},"
             "{\"thing\": {" TEST_DIFFUSE(0.5) ", \"parts\": [{\"triangle\": {\"points\": "
             "[[400, 0, 400], [401, 0, 400], [400, 1, 400]]}}]}},"
             "{\"mesh\": {\"file\": \"%s\", \"smooth\": true, \"backculled\": true, "
             TEST_DIFFUSE(0.5) "}}]}",
             objpath);
    snprintf(path, sizeof path, "%s", test_write_file("job_sheet.json", text));
    return path;
}

/* One process's output of `scene`, then R = 1, 2, 3 processes'
 * (name_R.ext), the same bytes. */
static void same_at_every_count_of(const char *scene, const char *options, const char *name,
                                   const char *ext)
{
    char args[4096], one[256];
    snprintf(one, sizeof one, "%s_single.%s", name, ext);
    snprintf(args, sizeof args, "render '%s' %s -q -o '%s'", scene, options, test_tmp_path(one));
    assert_int_equal(test_run_cli(args, NULL), 0);
    for (int ranks = 1; ranks <= 3; ranks++) {
        char mine[256], *err = NULL;
        snprintf(mine, sizeof mine, "%s_%d.%s", name, ranks, ext);
        snprintf(args, sizeof args, "render '%s' %s --threads 1 -q -o '%s'", scene, options,
                 test_tmp_path(mine));
        int rc = run_job(ranks, args, &err);
        if (rc != 0)
            fail_msg("%d processes: exit %d: %s", ranks, rc, err ? err : "");
        free(err);
        char a[1024];
        snprintf(a, sizeof a, "%s", test_tmp_path(one));
        test_assert_same_file(a, test_tmp_path(mine));
    }
}

static void same_at_every_count(const char *options, const char *name, const char *ext)
{
    same_at_every_count_of(cornell(), options, name, ext);
}

static void test_path_tracer(void **state)
{
    (void)state;
    same_at_every_count("--size 40x30 --spp 6 --seed 3", "path", "pfm");
}

/* A checkpoint written by 2 processes resumed by 3 gives one process's
 * image. */
static void test_path_resumed(void **state)
{
    (void)state;
    char args[4096], check[1024], one[1024], mine[1024];
    snprintf(check, sizeof check, "%s", test_tmp_path("job.ztcheck"));
    snprintf(one, sizeof one, "%s", test_tmp_path("resume_single.pfm"));
    snprintf(mine, sizeof mine, "%s", test_tmp_path("resume_3.pfm"));
    snprintf(args, sizeof args, "render '%s' --size 40x30 --spp 7 -q -o '%s'", cornell(), one);
    assert_int_equal(test_run_cli(args, NULL), 0);
    snprintf(args, sizeof args, "render '%s' --size 40x30 --spp 3 --checkpoint '%s' -q -o '%s'",
             cornell(), check, test_tmp_path("resume_part.pfm"));
    assert_int_equal(run_job(2, args, NULL), 0);
    snprintf(args, sizeof args, "render '%s' --size 40x30 --spp 7 --resume '%s' -o '%s'",
             cornell(), check, mine);
    char *err = NULL;
    assert_int_equal(run_job(3, args, &err), 0);
    assert_non_null(strstr(err, "resumed from"));
    free(err);
    test_assert_same_file(one, mine);
}

static void test_zone_tracer(void **state)
{
    (void)state;
    same_at_every_count("--method zone --quality 0 --size 40x30", "zone_pixel", "pfm");
    same_at_every_count("--method zone --quality 0 --strategy zone --size 40x30", "zone_zone",
                        "pfm");
}

/* A model whose vertex nodes share cuts: each member is computed by the
 * process of its leader, wherever its own block falls. */
static void test_zone_groups(void **state)
{
    (void)state;
    char args[4096], *err = NULL;
    snprintf(args, sizeof args, "render '%s' --method zone --size 24x16 -v -o '%s'",
             sheet_scene(), test_tmp_path("groups_v.pfm"));
    assert_int_equal(test_run_cli(args, &err), 0);
    const char *at = err ? strstr(err, " started from a neighbour's") : NULL;
    if (!at) {
        size_t n = err ? strlen(err) : 0;
        fail_msg("-v reports no shared cuts; it ends: %s", err ? err + (n > 600 ? n - 600 : 0) : "");
    }
    while (at > err && at[-1] != ' ')
        at--;
    assert_true(atol(at) > 100);
    free(err);
    same_at_every_count_of(sheet_scene(), "--method zone --size 24x16", "zone_groups", "pfm");
}

/* The forest Phase One builds split over processes is the one a single
 * process builds: read back by one process, it renders the same bytes.
 * (The files themselves differ in the time Phase One took.) */
static void test_zone_forest(void **state)
{
    (void)state;
    char args[4096], forest[1024], a[1024], b[1024];
    snprintf(forest, sizeof forest, "%s", test_tmp_path("job.forest"));
    snprintf(a, sizeof a, "%s", test_tmp_path("forest_single.pfm"));
    snprintf(b, sizeof b, "%s", test_tmp_path("forest_loaded.pfm"));
    snprintf(args, sizeof args, "render '%s' --method zone --quality 0 --size 24x16 -q -o '%s'",
             cornell(), a);
    assert_int_equal(test_run_cli(args, NULL), 0);
    snprintf(args, sizeof args, "render '%s' --method zone --quality 0 --size 24x16 "
             "--save-forest '%s' -q -o '%s'", cornell(), forest, test_tmp_path("forest_job.pfm"));
    assert_int_equal(run_job(3, args, NULL), 0);
    test_assert_same_file(a, test_tmp_path("forest_job.pfm"));
    snprintf(args, sizeof args, "render '%s' --method zone --quality 0 --size 24x16 "
             "--load-forest '%s' -q -o '%s'", cornell(), forest, b);
    assert_int_equal(test_run_cli(args, NULL), 0);
    test_assert_same_file(a, b);
}

/* Limits are agreed: a zone render whose time is up before level 0 ends
 * stops at depth 1 on every process, and writes the depth-1 image; a path
 * render stops at a pass all processes reached. */
static void test_time_limit(void **state)
{
    (void)state;
    char args[4096], *err = NULL;
    snprintf(args, sizeof args, "render '%s' --method zone --quality 4 --depth 1 --size 40x30 "
             "-q -o '%s'", cornell(), test_tmp_path("depth1_single.pfm"));
    assert_int_equal(test_run_cli(args, NULL), 0);
    snprintf(args, sizeof args, "render '%s' --method zone --quality 4 --size 40x30 "
             "--time-limit 0.001 -o '%s'", cornell(), test_tmp_path("depth1_job.pfm"));
    assert_int_equal(run_job(2, args, &err), 0);
    assert_non_null(strstr(err, "reached depth 1 of 3"));
    free(err);
    char a[1024];
    snprintf(a, sizeof a, "%s", test_tmp_path("depth1_single.pfm"));
    test_assert_same_file(a, test_tmp_path("depth1_job.pfm"));
    snprintf(args, sizeof args, "render '%s' --size 64x64 --spp 1000000 --time-limit 1 -o '%s'",
             cornell(), test_tmp_path("limited.pfm"));
    assert_int_equal(run_job(2, args, &err), 0);
    assert_non_null(strstr(err, "stopped by the time limit"));
    free(err);
}

static void test_animation(void **state)
{
    (void)state;
    const char *motions = test_write_file("job_motions.json",
        "{\"motions\": [{\"thing\": 0, \"type\": \"orbiting\", \"axis\": \"y\", \"period\": 4},"
        " {\"light\": 0, \"type\": \"brownian\", \"scale\": 0.2}]}\n");
    char options[2048];
    snprintf(options, sizeof options, "--motions '%s' --frames 5 --fps 2 --size 24x16 --spp 2",
             motions);
    char args[4096];
    snprintf(args, sizeof args, "render '%s' %s -q -o '%s/anim_single_%%d.pfm'", cornell(),
             options, test_tmp_dir());
    assert_int_equal(test_run_cli(args, NULL), 0);
    for (int ranks = 2; ranks <= 3; ranks++) {
        snprintf(args, sizeof args, "render '%s' %s --threads 1 -q -o '%s/anim_%d_%%d.pfm'",
                 cornell(), options, test_tmp_dir(), ranks);
        assert_int_equal(run_job(ranks, args, NULL), 0);
        for (int k = 0; k < 5; k++) {
            char a[1024], b[64];
            snprintf(a, sizeof a, "%s/anim_single_%d.pfm", test_tmp_dir(), k);
            snprintf(b, sizeof b, "anim_%d_%d.pfm", ranks, k);
            test_assert_same_file(a, test_tmp_path(b));
        }
    }
}

/* A camera path alone: each process builds its zone renderer once and
 * renders its frames with it, the same bytes as one process. */
static void test_camera_animation(void **state)
{
    (void)state;
    const char *motions = test_write_file("job_camera.json",
        "{\"motions\": [{\"camera\": \"path\", \"keys\": [\n"
        "  {\"time\": 0, \"position\": [278, 273, -800], \"lookat\": [278, 273, 0], \"fov\": 37},\n"
        "  {\"time\": 1, \"position\": [150, 300, -600], \"lookat\": [300, 200, 300], \"fov\": 45},\n"
        "  {\"time\": 2, \"position\": [400, 200, -500], \"lookat\": [278, 273, 200]}]}]}\n");
    char options[2048];
    snprintf(options, sizeof options, "--motions '%s' --frames 5 --fps 2 --size 24x16 "
             "--method zone --depth 2 --quality 0", motions);
    char args[4096], *err = NULL;
    snprintf(args, sizeof args, "render '%s' %s -o '%s/cam_single_%%d.pfm'", cornell(), options,
             test_tmp_dir());
    assert_int_equal(test_run_cli(args, &err), 0);
    assert_non_null(strstr(err, "forest built once for 5 frames"));
    free(err);
    for (int ranks = 2; ranks <= 3; ranks++) {
        snprintf(args, sizeof args, "render '%s' %s --threads 1 -o '%s/cam_%d_%%d.pfm'",
                 cornell(), options, test_tmp_dir(), ranks);
        assert_int_equal(run_job(ranks, args, &err), 0);
        assert_non_null(strstr(err, "forest built once per process for 5 frames"));
        free(err);
        for (int k = 0; k < 5; k++) {
            char a[1024], b[64];
            snprintf(a, sizeof a, "%s/cam_single_%d.pfm", test_tmp_dir(), k);
            snprintf(b, sizeof b, "cam_%d_%d.pfm", ranks, k);
            test_assert_same_file(a, test_tmp_path(b));
        }
    }
}

/* The job ends with code, and its messages hold needle (and `also` when it
 * is not NULL). */
static void expect_failure(int ranks, const char *args, int code, const char *needle,
                           const char *also)
{
    char *err = NULL;
    int rc = run_job(ranks, args, &err);
    if (rc != code || !err || !strstr(err, needle) || (also && !strstr(err, also)))
        fail_msg("expected exit %d and \"%s\"%s%s, got %d:\n%s", code, needle,
                 also ? " and " : "", also ? also : "", rc, err ? err : "");
    free(err);
}

/* Failures on one process only (its own arguments, in MPMD form: as when
 * a node lacks a file or has less memory) end the whole job. */
static void test_failures(void **state)
{
    (void)state;
    char args[4096];
    const char *out = test_tmp_path("fail.pfm");
    /* the scene is missing on process 1 */
    snprintf(args, sizeof args, "render '%s' --size 8x8 --spp 1 -o '%s' : -n 1 @ZT@ render "
             "'%s/nowhere.json' --size 8x8 --spp 1 -o '%s'", cornell(), out, test_tmp_dir(), out);
    expect_failure(1, args, 2, "process 1 of 2", "nowhere.json");
    /* process 2 may not use the memory the render needs: it stops inside
     * the render, where the others wait for it */
    snprintf(args, sizeof args, "render '%s' --size 64x64 --spp 100000 -o '%s' : -n 1 @ZT@ "
             "render '%s' --size 64x64 --spp 100000 --max-memory 1K -o '%s'", cornell(), out,
             cornell(), out);
    expect_failure(2, args, 5, "more than the limit", NULL);
    /* process 1 was given another seed (or read another version of the
     * scene): its rows would not fit the others' */
    snprintf(args, sizeof args, "render '%s' --size 8x8 --spp 1 -o '%s' : -n 1 @ZT@ render "
             "'%s' --size 8x8 --spp 1 --seed 9 -o '%s'", cornell(), out, cornell(), out);
    expect_failure(1, args, 1, "process 1 of 2 has another scene or other options", NULL);
    /* the output cannot be written (rank 0 checks before the work) */
    snprintf(args, sizeof args, "render '%s' --size 8x8 --spp 1 -o '%s/no/such/dir/x.pfm'",
             cornell(), test_tmp_dir());
    expect_failure(2, args, 4, "not writable", NULL);
    /* the same bad option everywhere: one message, exit 1 */
    snprintf(args, sizeof args, "render '%s' --spp 0", cornell());
    char *err = NULL;
    assert_int_equal(run_job(3, args, &err), 1);
    const char *first = strstr(err, "--spp");
    assert_non_null(first);
    assert_null(strstr(first + 1, "zonetrace: --spp")); /* printed once */
    free(err);
}

int main(void)
{
    /* Open MPI refuses root without these, and in containers its shared
     * memory transport cannot use cross-process copies. */
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 1);
    /* Under the sanitizers the processes of a job keep ASan and UBSan but
     * not the leak check: Open MPI's plugins leave allocations behind at
     * exit in code already unloaded, which no suppression can name.  The
     * other tests check the program's own leaks. */
    const char *asan = getenv("ASAN_OPTIONS");
    if (asan) {
        char options[1024];
        snprintf(options, sizeof options, "%s:detect_leaks=0", asan);
        setenv("ASAN_OPTIONS", options, 1);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_path_tracer),
        cmocka_unit_test(test_path_resumed),
        cmocka_unit_test(test_zone_tracer),
        cmocka_unit_test(test_zone_groups),
        cmocka_unit_test(test_zone_forest),
        cmocka_unit_test(test_time_limit),
        cmocka_unit_test(test_animation),
        cmocka_unit_test(test_camera_animation),
        cmocka_unit_test(test_failures),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

#else /* a build without MPI */

int main(void)
{
    /* Its refusal under mpirun is test_cluster_single's. */
    fprintf(stderr, "test_cluster: skipped: this build has no MPI\n");
    return 0;
}
#endif
