/* Long renders: a render stopped and resumed any number of times gives the
 * bits of one that never stopped; time limits end renders early with what
 * they reached; checkpoints from elsewhere are refused; renders too large
 * for the memory limit are refused before the work. */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "zonetrace/zonetrace.h"

/* The Cornell box of the repository, whose indirect light makes every
 * sample different. */
static zt_scene *cornell(int size)
{
    zt_scene *s = NULL;
    zt_error err = {0};
    if (zt_scene_load_file(ZT_SOURCE_DIR "/scenes/cornell.json", &s, &err) != ZT_OK)
        fail_msg("%s", err.message);
    zt_camera c = zt_scene_get_camera(s);
    assert_int_equal(zt_camera_set_resolution(&c, size, size, &err), ZT_OK);
    zt_scene_set_camera(s, &c);
    return s;
}

/* A progress callback that raises the stop flag once the render is some
 * way into its work. */
typedef struct stopper {
    volatile sig_atomic_t flag;
    double at;
} stopper;

static int stop_soon(void *user, const char *stage, double done, double total)
{
    (void)stage;
    stopper *s = user;
    if (done >= s->at * total)
        s->flag = 1;
    return 0;
}

static zt_render_options path_options(int spp, const char *checkpoint)
{
    zt_render_options o = zt_render_options_default();
    o.spp = spp;
    o.depth = 4;
    o.seed = 7;
    o.checkpoint_file = checkpoint;
    return o;
}

/* Library: stopped twice (the flag raised from the progress callback, as a
 * signal handler would) and resumed, the image is the uninterrupted one.
 * Passes last about half a second, so a render of a few seconds has
 * several to stop between. */
static void test_stop_and_resume_same_bits(void **state)
{
    (void)state;
    zt_scene *s = cornell(32);
    zt_error err = {0};
    const char *ck = test_tmp_path("lib.ckpt");
    zt_render_options o = path_options(3000, NULL);
    zt_image *full = NULL, *img = NULL;
    zt_render_stats st;
    assert_int_equal(zt_render(s, &o, &full, &st, &err), ZT_OK);
    assert_int_equal(st.spp_done, 3000);
    assert_int_equal(st.stopped, ZT_STOP_NONE);

    stopper sp = {0, 0.2};
    o = path_options(3000, ck);
    o.progress = stop_soon;
    o.progress_user = &sp;
    o.stop = &sp.flag;
    int reached = 0;
    for (int run = 0; run < 2; run++) {
        sp.flag = 0;
        o.resume = run > 0;
        assert_int_equal(zt_render(s, &o, &img, &st, &err), ZT_OK);
        assert_int_equal(st.spp_resumed, reached);
        /* Stopped after the pass under way: more than before, not all. */
        assert_int_equal(st.stopped, ZT_STOP_INTERRUPT);
        assert_true(st.spp_done > reached && st.spp_done < 3000);
        reached = st.spp_done;
        zt_image_release(img);
    }
    o.progress = NULL;
    o.stop = NULL;
    assert_int_equal(zt_render(s, &o, &img, &st, &err), ZT_OK);
    assert_int_equal(st.spp_resumed, reached);
    assert_int_equal(st.spp_done, 3000);
    test_assert_same_image(full, img, "resumed vs uninterrupted");
    zt_image_release(img);

    /* The finished checkpoint goes on to a higher count, still the same
     * bits as one render of that count. */
    o.spp = 3300;
    o.resume = 1;
    assert_int_equal(zt_render(s, &o, &img, &st, &err), ZT_OK);
    assert_int_equal(st.spp_resumed, 3000);
    zt_image *more = NULL;
    zt_render_options plain = path_options(3300, NULL);
    assert_int_equal(zt_render(s, &plain, &more, &st, &err), ZT_OK);
    test_assert_same_image(more, img, "resumed to more samples");
    zt_image_release(more);
    zt_image_release(img);
    zt_image_release(full);
    zt_scene_release(s);
}

/* Checkpoints that are not this render's are refused with the file's name
 * and the reason. */
static void expect_refused(const zt_scene *s, const zt_render_options *o, zt_status want,
                           const char *needle)
{
    zt_image *img = NULL;
    zt_error err = {0};
    zt_status got = zt_render(s, o, &img, NULL, &err);
    if (got != want || !strstr(err.message, needle))
        fprintf(stderr, "status %d (wanted %d): %s\n", got, want, err.message);
    assert_int_equal(got, want);
    assert_non_null(strstr(err.message, needle));
    assert_null(img);
}

static void copy_prefix(const char *from, const char *to, size_t n, int flip_at)
{
    size_t len = 0;
    char *data = test_read_file(from, &len);
    assert_non_null(data);
    if (n > len)
        n = len;
    if (flip_at >= 0)
        data[flip_at] ^= 0x10;
    FILE *f = fopen(to, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
    free(data);
}

static void test_bad_checkpoints(void **state)
{
    (void)state;
    zt_scene *s = cornell(8);
    zt_error err = {0};
    const char *ck = test_tmp_path("good.ckpt");
    zt_render_options o = path_options(16, ck);
    zt_image *img = NULL;
    assert_int_equal(zt_render(s, &o, &img, NULL, &err), ZT_OK);
    zt_image_release(img);
    size_t len = 0;
    free(test_read_file(ck, &len));
    assert_int_equal(len, 32 + 8 * 8 * 3 * 8 + 8);

    o.resume = 1;
    o.spp = 8;
    expect_refused(s, &o, ZT_ERR_PARSE, "more than the 8 asked for");
    o.spp = 32;
    o.seed = 8;
    expect_refused(s, &o, ZT_ERR_PARSE, "made for another render");
    o.seed = 7;
    zt_scene *big = cornell(9);
    expect_refused(big, &o, ZT_ERR_PARSE, "of a 8x8 image");
    zt_scene_release(big);

    const char *bad = test_tmp_path("bad.ckpt");
    o.checkpoint_file = bad;
    copy_prefix(ck, bad, len - 100, -1);
    expect_refused(s, &o, ZT_ERR_PARSE, "truncated");
    copy_prefix(ck, bad, len, 40);
    expect_refused(s, &o, ZT_ERR_PARSE, "checksum");
    copy_prefix(ck, bad, 10, -1);
    expect_refused(s, &o, ZT_ERR_PARSE, "not a zonetrace checkpoint");
    test_write_file("text.ckpt", "{\"scene\": []}\n");
    o.checkpoint_file = test_tmp_path("text.ckpt");
    expect_refused(s, &o, ZT_ERR_PARSE, "text.ckpt");
    o.checkpoint_file = test_tmp_path("missing.ckpt");
    expect_refused(s, &o, ZT_ERR_READ, "missing.ckpt");
    zt_scene_release(s);
}

/* A time limit ends the path tracer after whole passes, with at least one
 * sample; the zone tracer keeps the levels that fit, and the image is the
 * one of the depth it reached. */
static void test_time_limits(void **state)
{
    (void)state;
    zt_scene *s = cornell(16);
    zt_error err = {0};
    zt_render_options o = path_options(1 << 24, NULL);
    o.time_limit = 0.3;
    zt_image *img = NULL;
    zt_render_stats st;
    assert_int_equal(zt_render(s, &o, &img, &st, &err), ZT_OK);
    assert_int_equal(st.stopped, ZT_STOP_TIME);
    assert_true(st.spp_done >= 1 && st.spp_done < (1 << 24));
    assert_int_equal(st.samples, (uint64_t)16 * 16 * st.spp_done);
    zt_image_release(img);

    o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 3;
    o.quality = 0;
    o.time_limit = 1e-6;
    assert_int_equal(zt_render(s, &o, &img, &st, &err), ZT_OK);
    assert_int_equal(st.stopped, ZT_STOP_TIME);
    assert_int_equal(st.depth_done, 1);
    zt_image *direct = NULL;
    o.time_limit = 0;
    o.depth = 1;
    assert_int_equal(zt_render(s, &o, &direct, &st, &err), ZT_OK);
    assert_int_equal(st.stopped, ZT_STOP_NONE);
    assert_int_equal(st.depth_done, 1);
    test_assert_same_image(direct, img, "depth reached vs depth 1");
    zt_image_release(direct);
    zt_image_release(img);

    o.depth = 3;
    o.level = 2;
    o.time_limit = 5;
    expect_refused(s, &o, ZT_ERR_ARGUMENT, "single level");
    zt_scene_release(s);
}

/* What a render reported: each Phase One level's stage, how far it came,
 * and whether Phase Two had begun by then; cancels in stage `cancel_in`
 * once past `cancel_at` of it. */
typedef struct reports {
    char stages[4][32];
    double reached[4];
    int count, phase_two_seen, phase_one_after;
    const char *cancel_in;
    double cancel_at;
} reports;

static int record(void *user, const char *stage, double done, double total)
{
    reports *r = user;
    if (strncmp(stage, "phase one", 9) != 0) {
        r->phase_two_seen = 1;
        return 0;
    }
    r->phase_one_after |= r->phase_two_seen;
    int i = 0;
    while (i < r->count && strcmp(r->stages[i], stage) != 0)
        i++;
    if (i == r->count && r->count < 4)
        snprintf(r->stages[r->count++], sizeof r->stages[0], "%s", stage);
    if (i < 4 && done / total > r->reached[i])
        r->reached[i] = done / total;
    return r->cancel_in && strcmp(stage, r->cancel_in) == 0 && done >= r->cancel_at * total;
}

/* Phase One reports each level it builds as a stage of its own, to the
 * end, before Phase Two begins; cancelled from the callback halfway
 * through a level, the render fails with ZT_ERR_CANCELLED and the next
 * one is whole. */
static void test_phase_one_progress(void **state)
{
    (void)state;
    zt_scene *s = cornell(16);
    zt_error err = {0};
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = 3;
    o.quality = 1;
    reports r = {0};
    o.progress = record;
    o.progress_user = &r;
    zt_image *img = NULL, *again = NULL;
    zt_render_stats st;
    assert_int_equal(zt_render(s, &o, &img, &st, &err), ZT_OK);
    assert_int_equal(r.count, 3);
    const char *want[3] = {"phase one 1/3", "phase one 2/3", "phase one 3/3"};
    for (int i = 0; i < 3; i++) {
        assert_string_equal(r.stages[i], want[i]);
        assert_true(r.reached[i] == 1.0);
    }
    assert_true(r.phase_two_seen);
    assert_false(r.phase_one_after);

    reports c = {.cancel_in = "phase one 2/3", .cancel_at = 0.3};
    o.progress_user = &c;
    zt_image *none = NULL;
    assert_int_equal(zt_render(s, &o, &none, &st, &err), ZT_ERR_CANCELLED);
    assert_null(none);
    assert_non_null(strstr(err.message, "Phase One"));
    assert_int_equal(c.count, 2);
    assert_false(c.phase_two_seen);

    o.progress = NULL;
    assert_int_equal(zt_render(s, &o, &again, &st, &err), ZT_OK);
    test_assert_same_image(img, again, "after a cancelled render");
    zt_image_release(again);
    zt_image_release(img);
    zt_scene_release(s);
}

/* Refused before any work, with the size needed. */
static void test_memory_limits(void **state)
{
    (void)state;
    zt_scene *s = cornell(2000);
    zt_render_options o = zt_render_options_default();
    o.max_memory = 100u << 20;
    expect_refused(s, &o, ZT_ERR_MEMORY, "needs about 183.1 MiB");
    zt_scene_release(s);
    /* A forest of tens of millions of nodes against the machine's memory:
     * refused once its nodes are counted, before they are made. */
    s = cornell(16);
    o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.quality = 16;
    o.max_memory = 1ull << 30;
    expect_refused(s, &o, ZT_ERR_MEMORY, "surface nodes at quality 16");
    zt_scene_release(s);
}

/* The command line: SIGINT twice, resumed, same bytes; a second signal
 * ends it at once with nothing written.  The child's stderr goes to
 * err_path. */
static pid_t spawn_cli(const char *const *argv, const char *err_path)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        FILE *e = freopen(err_path, "w", stderr);
        (void)e;
        execv(ZT_CLI_PATH, (char *const *)argv);
        _exit(127);
    }
    return pid;
}

static int exit_code(int status)
{
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static int file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (int)st.st_size : -1;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* The samples per pixel a checkpoint holds (its header), or -1. */
static long checkpoint_samples(const char *path)
{
    unsigned char b[32];
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    return n == sizeof b ? (long)(b[24] | b[25] << 8 | b[26] << 16 | (unsigned long)b[27] << 24)
                         : -1;
}

/* Polls until cond(arg) or the child ends (then returns its status). */
static int wait_for(pid_t pid, int (*cond)(const void *), const void *arg, int *status)
{
    for (int i = 0; i < 30000; i++) {
        if (cond(arg))
            return 0;
        if (waitpid(pid, status, WNOHANG) == pid)
            return 1;
        sleep_ms(2);
    }
    fail_msg("the render neither progressed nor ended in a minute");
    return 1;
}

typedef struct ck_wait { const char *path; long before; } ck_wait;

static int checkpoint_moved(const void *arg)
{
    const ck_wait *w = arg;
    return checkpoint_samples(w->path) > w->before;
}

static int says_stopping(const void *arg)
{
    char *text = test_read_file((const char *)arg, NULL);
    int yes = text && strstr(text, "stopping after the current pass");
    free(text);
    return yes;
}

/* Runs the render and, once it has saved a checkpoint beyond the one it
 * resumed from, interrupts it (once, or a second time once the first is
 * acknowledged).  Returns the exit status. */
static int interrupted_run(const char *out, const char *ck, int resume, int signals)
{
    const char *argv[] = {ZT_CLI_PATH, "render", ZT_SOURCE_DIR "/scenes/cornell.json",
                          "--size", "48x48", "--spp", "3000", "--depth", "4", "--seed", "3",
                          resume ? "--resume" : "--checkpoint", ck, "--checkpoint-every",
                          "0.001", "-q", "-o", out, NULL};
    char err_path[512];
    snprintf(err_path, sizeof err_path, "%s", test_tmp_path("interrupted_stderr.txt"));
    /* Past the first pass (1 sample, which sizes the others). */
    long before = checkpoint_samples(ck);
    ck_wait w = {ck, before > 1 ? before : 1};
    pid_t pid = spawn_cli(argv, err_path);
    int status = 0;
    if (wait_for(pid, checkpoint_moved, &w, &status))
        return exit_code(status);
    kill(pid, SIGINT);
    if (signals == 2 && !wait_for(pid, says_stopping, err_path, &status))
        kill(pid, SIGINT);
    else if (signals == 2)
        return exit_code(status);
    assert_int_equal(waitpid(pid, &status, 0), pid);
    return exit_code(status);
}

static void test_cli_interrupts(void **state)
{
    (void)state;
    char full[512], part[512], ck[512], cmd[2048];
    snprintf(full, sizeof full, "%s", test_tmp_path("full.pfm"));
    snprintf(part, sizeof part, "%s", test_tmp_path("part.pfm"));
    snprintf(ck, sizeof ck, "%s", test_tmp_path("cli.ckpt"));
    snprintf(cmd, sizeof cmd, "render '%s' --size 48x48 --spp 3000 --depth 4 --seed 3 -q -o '%s'",
             ZT_SOURCE_DIR "/scenes/cornell.json", full);
    assert_int_equal(test_run_cli(cmd, NULL), 0);

    /* Twice: abort, nothing written.  Should the pass under way end in the
     * moment between the two signals, the first one's image is written (exit
     * 8, or the second signal comes while the process exits): then that
     * image must be whole, and the run is tried again.  A second signal that
     * did nothing would give that outcome every time: three in a row fail. */
    char gone[512], gone_ck[512];
    snprintf(gone, sizeof gone, "%s", test_tmp_path("gone.pfm"));
    snprintf(gone_ck, sizeof gone_ck, "%s", test_tmp_path("gone.ckpt"));
    int aborted = 0;
    for (int attempt = 0; attempt < 3 && !aborted; attempt++) {
        remove(gone);
        remove(gone_ck);
        int code = interrupted_run(gone, gone_ck, 0, 2);
        assert_true(code == 8 || code == 128 + SIGINT);
        if (file_size(gone) >= 0) {
            zt_image *img = NULL;
            zt_error err = {0};
            assert_int_equal(zt_image_read(gone, &img, &err), ZT_OK);
            assert_int_equal(img->width, 48);
            zt_image_release(img);
            fprintf(stderr, "note: the pass ended between the two signals (exit %d); again\n",
                    code);
        } else {
            assert_int_equal(code, 128 + SIGINT);
            aborted = 1;
        }
    }
    assert_true(aborted);

    /* Once, twice, then to the end: exit 8 with an image each time, and
     * the same bytes at the end as the render that never stopped. */
    assert_int_equal(interrupted_run(part, ck, 0, 1), 8);
    assert_true(file_size(part) > 0);
    long first = checkpoint_samples(ck);
    assert_true(first > 0 && first < 3000);
    assert_int_equal(interrupted_run(part, ck, 1, 1), 8);
    long second = checkpoint_samples(ck);
    assert_true(second > first && second < 3000);
    snprintf(cmd, sizeof cmd, "render '%s' --size 48x48 --spp 3000 --depth 4 --seed 3 "
             "--resume '%s' -q -o '%s'", ZT_SOURCE_DIR "/scenes/cornell.json", ck, part);
    assert_int_equal(test_run_cli(cmd, NULL), 0);
    assert_int_equal(checkpoint_samples(ck), 3000);
    test_assert_same_file(full, part);
}

/* The options' misuse, and the refusals, as exit codes and messages. */
static void expect_cli(const char *args, int code, const char *needle)
{
    char cmd[2048], *err = NULL;
    snprintf(cmd, sizeof cmd, "render '%s' -o '%s' %s", ZT_SOURCE_DIR "/scenes/cornell.json",
             test_tmp_path("opts.png"), args);
    int got = test_run_cli(cmd, &err);
    if (got != code || !err || !strstr(err, needle))
        fprintf(stderr, "%s: exit %d (wanted %d): %s\n", args, got, code, err ? err : "");
    assert_int_equal(got, code);
    assert_non_null(strstr(err, needle));
    free(err);
}

static void test_cli_options(void **state)
{
    (void)state;
    expect_cli("--method zone --checkpoint c.ckpt", 1, "for the path tracer");
    expect_cli("--resume a.ckpt --checkpoint b.ckpt", 1, "cannot name another file");
    expect_cli("--method zone --level 2 --time-limit 5", 1, "--level");
    expect_cli("--method zone --time-limit 5 --save-forest f.ztf", 1, "saved whole");
    expect_cli("--time-limit 0", 1, "--time-limit");
    expect_cli("--max-memory 12abc", 1, "--max-memory");
    expect_cli("--checkpoint /nonexistent-dir/c.ckpt", 1, "not writable");
    expect_cli("--resume /nonexistent-dir/c.ckpt", 1, "not writable");
    expect_cli("--size 100000x100000", 1, "335 GiB");
    expect_cli("--size 2000x2000 --max-memory 100M", 5, "183.1 MiB");
    expect_cli("--method zone --quality 16 --max-memory 8G", 5, "surface nodes");
    char args[1024];
    snprintf(args, sizeof args, "--size 8x8 --resume '%s'", test_tmp_path("absent.ckpt"));
    expect_cli(args, 2, "cannot open checkpoint");
    expect_cli("--size 8x8 --spp 1000000 --time-limit 0.2", 0, "stopped by the time limit");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stop_and_resume_same_bits),
        cmocka_unit_test(test_bad_checkpoints),
        cmocka_unit_test(test_time_limits),
        cmocka_unit_test(test_phase_one_progress),
        cmocka_unit_test(test_memory_limits),
        cmocka_unit_test(test_cli_interrupts),
        cmocka_unit_test(test_cli_options),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
