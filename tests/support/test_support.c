#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

const char *test_shared_dir(void)
{
    struct stat st;
    if (stat(ZT_SHARED_DIR "/scenes", &st) == 0 && S_ISDIR(st.st_mode))
        return ZT_SHARED_DIR;
    fprintf(stderr, "note: %s is absent; tests that need the original "
                    "programs' files are skipped\n", ZT_SHARED_DIR);
    return NULL;
}

static void remove_tmp_dir(void);
static char tmp_dir[256];

const char *test_tmp_dir(void)
{
    if (!tmp_dir[0]) {
        const char *base = getenv("TMPDIR");
        snprintf(tmp_dir, sizeof tmp_dir, "%s/zt_test_XXXXXX", base ? base : "/tmp");
        if (!mkdtemp(tmp_dir)) {
            perror("mkdtemp");
            abort();
        }
        atexit(remove_tmp_dir);
    }
    return tmp_dir;
}

static void remove_tmp_dir(void)
{
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_dir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", tmp_dir);
}

const char *test_tmp_path(const char *name)
{
    static char bufs[8][512];
    static int next;
    char *b = bufs[next++ % 8];
    snprintf(b, 512, "%s/%s", test_tmp_dir(), name);
    return b;
}

const char *test_write_file(const char *name, const char *text)
{
    const char *path = test_tmp_path(name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(text, 1, strlen(text), f) != strlen(text)) {
        perror(path);
        abort();
    }
    fclose(f);
    return path;
}

size_t test_obj_sheet(char *text, size_t len, size_t cap, int squares, double step, double y,
                      int first)
{
    for (int i = 0; i <= squares; i++)
        for (int j = 0; j <= squares; j++)
            len += (size_t)snprintf(text + len, cap - len, "v %g %g %g\n", step * j, y, step * i);
    for (int i = 0; i < squares; i++)
        for (int j = 0; j < squares; j++) {
            int a = first + i * (squares + 1) + j, b = a + 1, c = a + squares + 1, d = c + 1;
            /* Counter-clockwise seen from -y: facing down. */
            len += (size_t)snprintf(text + len, cap - len,
                                    "f %d//1 %d//1 %d//1\nf %d//1 %d//1 %d//1\n", a, b, d, a, d,
                                    c);
        }
    return len;
}

double test_render_mean(const zt_scene *s, zt_method method, int level, int depth, int spp)
{
    zt_image *im = test_render_level(s, method, level, depth, spp);
    double sum = 0;
    int n = 3 * im->width * im->height;
    for (int i = 0; i < n; i++) {
        assert_true(isfinite(im->pixels[i]));
        sum += im->pixels[i];
    }
    zt_image_release(im);
    return sum / n;
}

void test_copy_file(const char *from, const char *to)
{
    size_t n = 0;
    char *data = test_read_file(from, &n);
    assert_non_null(data);
    FILE *fp = fopen(to, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(data, 1, n, fp), n);
    fclose(fp);
    free(data);
}

char *test_read_file(const char *path, size_t *length)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    size_t got;
    while ((got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
        n += got;
        if (cap - n < 2) {
            cap *= 2;
            buf = realloc(buf, cap);
        }
    }
    fclose(f);
    buf[n] = '\0';
    if (length)
        *length = n;
    return buf;
}

int test_run_cli(const char *args, char **err_out)
{
    const char *errpath = test_tmp_path("cli_stderr.txt");
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "'%s' %s 2>'%s' </dev/null", ZT_CLI_PATH, args, errpath);
    int status = system(cmd);
    if (err_out)
        *err_out = test_read_file(errpath, NULL);
    if (status == -1 || !WIFEXITED(status))
        return -1;
    return WEXITSTATUS(status);
}

zt_scene *test_scene_text(const char *text, const char *name)
{
    zt_scene *s = NULL;
    zt_error err = {0};
    if (zt_scene_load_string(text, strlen(text), name, &s, &err) != ZT_OK)
        fail_msg("scene does not load: %s", err.message);
    return s;
}

zt_image *test_render_level(const zt_scene *s, zt_method method, int level, int depth, int spp)
{
    zt_render_options o = zt_render_options_default();
    o.method = method;
    o.level = level;
    o.depth = depth;
    o.spp = spp;
    zt_image *im = NULL;
    zt_error err = {0};
    if (zt_render(s, &o, &im, NULL, &err) != ZT_OK)
        fail_msg("render: %s", err.message);
    return im;
}

zt_renderer *test_zone_renderer(const zt_scene *s, int depth, int threads, int quality)
{
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_ZONE;
    o.depth = depth;
    o.threads = threads;
    o.quality = quality;
    zt_renderer *r = NULL;
    zt_error err = {0};
    if (zt_renderer_create(s, &o, &r, &err) != ZT_OK)
        fail_msg("zone renderer: %s", err.message);
    return r;
}

void test_assert_same_image(const zt_image *a, const zt_image *b, const char *what)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    size_t n = (size_t)a->width * a->height * 3;
    if (memcmp(a->pixels, b->pixels, n * sizeof(float)) != 0)
        for (size_t i = 0; i < n; i++)
            if (memcmp(&a->pixels[i], &b->pixels[i], sizeof(float)) != 0)
                fail_msg("%s: float %zu differs: %.9g vs %.9g", what, i, a->pixels[i],
                         b->pixels[i]);
}

void test_assert_same_file(const char *a, const char *b)
{
    size_t la = 0, lb = 0;
    char *da = test_read_file(a, &la), *db = test_read_file(b, &lb);
    assert_non_null(da);
    assert_non_null(db);
    assert_int_equal(la, lb);
    assert_memory_equal(da, db, la);
    free(da);
    free(db);
}
