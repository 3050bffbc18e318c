/* Helpers shared by the tests: temporary files, the shared/ folder, running
 * the command line program. */
#ifndef ZT_TEST_SUPPORT_H
#define ZT_TEST_SUPPORT_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

/* A scene file's "material" member for a grey diffuse surface: albedo a
 * written as a literal (TEST_DIFFUSE(0.5)), or left to printf as three %g
 * (TEST_DIFFUSE_FMT). */
#define TEST_DIFFUSE_HEAD "\"material\": {\"character\": {\"diffuse\": 1, \"metallic\": 0, " \
    "\"reflecting\": 0, \"refractive\": 0}, \"color\": ["
#define TEST_DIFFUSE(a) TEST_DIFFUSE_HEAD #a ", " #a ", " #a "]}"
#define TEST_DIFFUSE_FMT TEST_DIFFUSE_HEAD "%g, %g, %g]}"

/* The ../shared folder beside the clone, or NULL (with a message on stderr
 * saying the test is skipped) when it is absent. */
const char *test_shared_dir(void);

/* A fresh temporary directory for this test process (created once). */
const char *test_tmp_dir(void);

/* tmp_dir/name in a static rotating buffer. */
const char *test_tmp_path(const char *name);

/* Renders s with one method at level (-1: all up to depth) and spp samples
 * per pixel (path), the other options at their defaults; fails the test
 * with the renderer's message on error. */
zt_image *test_render_level(const zt_scene *s, zt_method method, int level, int depth, int spp);

/* test_render_level's image, its mean over pixels and channels; fails the
 * test on a value that is not finite. */
double test_render_mean(const zt_scene *s, zt_method method, int level, int depth, int spp);

/* Copies file `from` to `to` (a model and its textures into tmp_dir);
 * fails the test when it cannot. */
void test_copy_file(const char *from, const char *to);

/* Writes text to tmp_dir/name and returns that path. */
const char *test_write_file(const char *name, const char *text);

/* Appends to OBJ text (length len, room cap) a sheet of squares x squares
 * squares of side step in the plane at height y, from the origin along x
 * and z, its vertices numbered from `first`, two triangles a square facing
 * down through normal 1 (the caller writes "vn 0 -1 0").  Returns the new
 * length. */
size_t test_obj_sheet(char *text, size_t len, size_t cap, int squares, double step, double y,
                      int first);

/* Runs the zonetrace program with the given arguments (a shell-quoted
 * string), capturing stderr into *err_out (malloc'd, may be NULL) and
 * returning the exit status (or -1 if it died from a signal). */
int test_run_cli(const char *args, char **err_out);

/* Fails the test unless a and b have the same size and the same float
 * bits, naming `what` and the first float that differs. */
void test_assert_same_image(const zt_image *a, const zt_image *b, const char *what);

/* Fails the test unless the two files exist and hold the same bytes. */
void test_assert_same_file(const char *a, const char *b);

/* Reads a whole file (malloc'd, NUL-terminated) or NULL. */
char *test_read_file(const char *path, size_t *length);

/* A scene from JSON text (named `name` in messages); fails the test when
 * it does not load. */
zt_scene *test_scene_text(const char *text, const char *name);

/* A zone renderer (Phase One done) for the scene; fails the test on error. */
zt_renderer *test_zone_renderer(const zt_scene *s, int depth, int threads, int quality);

#endif
