/* Model files through the "mesh" item: every kind of bad input gets one
 * clear message with the scene file, the item's line and column, the model
 * file and the reason; transforms against hand-computed points; MTL
 * materials; texture texels and their lookup, down to a rendered image. */
#define _POSIX_C_SOURCE 200809L
#include "test_support.h"

#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "material/texture.h"
#include "scene/mesh.h"
#include "scene/scene.h"
#include "zonetrace/image.h"
#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define ASSIMP_MODELS "/usr/share/assimp/models"

/* A scene whose "mesh" item (on line 3, column 3) names `model` with the
 * extra members `extra` (",\"smooth\": false" or ""); written as
 * tmp/scene_name and returned. */
static const char *write_scene(const char *scene_name, const char *model, const char *extra)
{
    char text[4096];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [0, 0, 5], \"lookat\": [0, 0, 0], \"up\": [0, 1, 0],"
             " \"fov\": 40, \"gridresolution\": [16, 8]},\n"
             " \"scene\": [\n"
             "  {\"mesh\": {\"file\": \"%s\"%s}}\n"
             " ]}\n",
             model, extra);
    return test_write_file(scene_name, text);
}

static zt_status load(const char *scene_path, zt_scene **s, zt_error *err)
{
    *s = NULL;
    zt_error_clear(err);
    return zt_scene_load_file(scene_path, s, err);
}

/* Loading must fail with `status`, and the message must hold the scene's
 * name with the item's position, the model file and `reason`. */
static void expect_failure(const char *scene_name, const char *model, zt_status status,
                           const char *reason)
{
    const char *path = write_scene(scene_name, model, "");
    zt_scene *s;
    zt_error err;
    zt_status st = load(path, &s, &err);
    if (st != status || s)
        fail_msg("%s: expected status %d, got %d (%s)", model, status, st, err.message);
    char where[512];
    snprintf(where, sizeof where, "%s:3:3: mesh: ", scene_name);
    if (!strstr(err.message, where) || !strstr(err.message, model) ||
        !strstr(err.message, reason))
        fail_msg("%s: message '%s' lacks '%s', the model or '%s'", model, err.message, where,
                 reason);
}

/* The one mesh of a scene that loaded. */
static const mesh *only_mesh(const zt_scene *s)
{
    assert_int_equal(s->mesh_count, 1);
    return s->meshes[0];
}

static zt_scene *load_ok(const char *scene_path)
{
    zt_scene *s;
    zt_error err;
    if (load(scene_path, &s, &err) != ZT_OK)
        fail_msg("%s does not load: %s", scene_path, err.message);
    return s;
}

/* ---------------------------------------------------------------------- */
/* Bad input */

static void test_bad_model_files(void **state)
{
    (void)state;
    expect_failure("s_missing.json", "no_such_model.obj", ZT_ERR_READ,
                   "cannot open model file: No such file or directory");
    mkdir(test_tmp_path("folder.obj"), 0755);
    expect_failure("s_dir.json", "folder.obj", ZT_ERR_READ, "it is a directory");
    test_write_file("empty.obj", "");
    expect_failure("s_empty.json", "empty.obj", ZT_ERR_PARSE, "empty file");
    test_write_file("words.xyzq", "not a model\n");
    expect_failure("s_unknown.json", "words.xyzq", ZT_ERR_PARSE, "unknown model format '.xyzq'");
    test_write_file("noext", "v 0 0 0\n");
    expect_failure("s_noext.json", "noext", ZT_ERR_PARSE, "unknown model format");
    test_write_file("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    expect_failure("s_range.json", "range.obj", ZT_ERR_PARSE, "out of range");
    test_write_file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\np 1\np 2\np 3\n");
    expect_failure("s_points.json", "points.obj", ZT_ERR_PARSE, "");
    test_write_file("allnan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nv 1 inf 0\nf 1 2 3\nf 1 2 4\n");
    expect_failure("s_allnan.json", "allnan.obj", ZT_ERR_PARSE, "no triangles left");
    test_write_file("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n");
    expect_failure("s_flat.json", "flat.obj", ZT_ERR_PARSE, "no triangles left (2 were");
    test_write_file("junk.glb", "glTF\x02\x00\x00\x00garbage that is not a binary glTF");
    expect_failure("s_junk.json", "junk.glb", ZT_ERR_PARSE, "the model cannot be read");
    test_write_file("junk.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n");
    expect_failure("s_junkply.json", "junk.ply", ZT_ERR_PARSE, "junk.ply");
    if (geteuid() != 0) {
        test_write_file("locked.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        chmod(test_tmp_path("locked.obj"), 0);
        expect_failure("s_locked.json", "locked.obj", ZT_ERR_READ, "Permission denied");
    } else {
        fprintf(stderr, "note: running as root, the unreadable-file case is skipped\n");
    }
}

/* Within a mesh, triangles with a vertex that is not finite, a repeated
 * vertex or no area are skipped and counted; the rest load. */
static void test_degenerate_counted(void **state)
{
    (void)state;
    test_write_file("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nv 2 0 0\n"
                                 "f 1 2 3\nf 1 2 4\nf 1 1 3\nf 1 2 5\n");
    zt_scene *s = load_ok(write_scene("s_mixed.json", "mixed.obj", ""));
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    assert_int_equal(info.meshes, 1);
    assert_int_equal(info.mesh_triangles, 1);
    assert_int_equal(info.skipped_triangles, 3);
    zt_scene_release(s);
}

/* The broken files of assimp-testmodels: each fails with its reason, or
 * (bad normals) loads with the normals replaced and counted. */
static void test_broken_gltf(void **state)
{
    (void)state;
    if (access(ASSIMP_MODELS "/glTF2", R_OK) != 0) {
        fprintf(stderr, "note: %s is absent (assimp-testmodels): skipped\n", ASSIMP_MODELS);
        skip();
    }
    static const struct {
        const char *file, *reason;
    } broken[] = {
        {"IndexOutOfRange/IndexOutOfRange.gltf", "indices out of range"},
        {"IndexOutOfRange/AllIndicesOutOfRange.gltf", "cannot be read"},
        {"MissingBin/BoxTextured.gltf", "cannot be read"},
        {"SchemaFailures/sceneWrongType.gltf", "cannot be read"},
        {"wrongTypes/badArray.gltf", "cannot be read"},
        {"wrongTypes/badExtension.gltf", "cannot be read"},
        {"wrongTypes/badNumber.gltf", "cannot be read"},
        {"wrongTypes/badObject.gltf", "cannot be read"},
        {"wrongTypes/badString.gltf", "cannot be read"},
        {"wrongTypes/badUint.gltf", "cannot be read"},
        {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "not finite"},
    };
    for (size_t i = 0; i < sizeof broken / sizeof broken[0]; i++) {
        char model[512];
        snprintf(model, sizeof model, "%s/glTF2/%s", ASSIMP_MODELS, broken[i].file);
        expect_failure("s_gltf.json", model, ZT_ERR_PARSE, broken[i].reason);
    }
    zt_scene *s = load_ok(write_scene(
        "s_badnormals.json", ASSIMP_MODELS "/glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb",
        ""));
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    assert_true(info.replaced_normals > 0);
    const mesh *m = only_mesh(s);
    assert_non_null(m->normal);
    for (int v = 0; v < m->vertex_count; v++) {
        const float *n = m->normal + 3 * v;
        double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        assert_true(fabs(l - 1) < 1e-5);
    }
    zt_scene_release(s);
}

/* ---------------------------------------------------------------------- */
/* Transforms */

static const char *const corner_obj = "v 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                      "vn 1 1 1\nvn 1 1 1\nvn 1 1 1\nf 1//1 2//2 3//3\n";

static void expect_point(const mesh *m, int v, double x, double y, double z)
{
    const float *p = m->position + 3 * v;
    if (fabs(p[0] - x) > 1e-6 || fabs(p[1] - y) > 1e-6 || fabs(p[2] - z) > 1e-6)
        fail_msg("vertex %d is (%g, %g, %g), expected (%g, %g, %g)", v, p[0], p[1], p[2], x, y,
                 z);
}

/* The triangle's corners in the order of its indices. */
static void corners(const mesh *m, double p[3][3])
{
    for (int c = 0; c < 3; c++)
        for (int a = 0; a < 3; a++)
            p[c][a] = m->position[3 * m->index[c] + a];
}

/* The triangle's geometric normal from its winding (unit). */
static void winding_normal(const mesh *m, double n[3])
{
    double p[3][3];
    corners(m, p);
    double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int a = 0; a < 3; a++)
        n[a] /= l;
}

static zt_scene *transformed(const char *transform)
{
    test_write_file("corner.obj", corner_obj);
    char extra[512];
    snprintf(extra, sizeof extra, ", \"transform\": %s", transform);
    return load_ok(write_scene("s_transform.json", "corner.obj", extra));
}

static void test_transform_points(void **state)
{
    (void)state;
    /* Scale x by 2: (2,0,0) (0,1,0) (0,0,1); 90 degrees about z, (x, y) ->
     * (-y, x): (0,2,0) (-1,0,0) (0,0,1); then + (1,2,3). */
    zt_scene *s = transformed("{\"scale\": [2, 1, 1], \"rotate\": [[0, 0, 1, 90]], "
                              "\"translate\": [1, 2, 3]}");
    const mesh *m = only_mesh(s);
    assert_int_equal(m->vertex_count, 3);
    expect_point(m, 0, 1, 4, 3);
    expect_point(m, 1, 0, 2, 3);
    expect_point(m, 2, 1, 2, 4);
    /* The normal (1,1,1) goes by the inverse transpose: (1/2, 1, 1), then
     * the rotation: (-1, 1/2, 1), normalised. */
    double l = sqrt(1 + 0.25 + 1);
    for (int v = 0; v < 3; v++) {
        const float *n = m->normal + 3 * v;
        assert_true(fabs(n[0] + 1 / l) < 1e-6 && fabs(n[1] - 0.5 / l) < 1e-6 &&
                    fabs(n[2] - 1 / l) < 1e-6);
    }
    zt_scene_release(s);

    /* Rotations apply in order: z then x.  After z: (0,1,0)... as above
     * without the scale: (0,1,0) (-1,0,0) (0,0,1); 90 about x, (y, z) ->
     * (-z, y): (0,0,1) (-1,0,0) (0,-1,0).  A scalar scale of 2 first. */
    s = transformed("{\"scale\": 2, \"rotate\": [[0, 0, 1, 90], [1, 0, 0, 90]]}");
    m = only_mesh(s);
    expect_point(m, 0, 0, 0, 2);
    expect_point(m, 1, -2, 0, 0);
    expect_point(m, 2, 0, -2, 0);
    zt_scene_release(s);

    /* A mirror keeps the front face on the normals' side: the winding
     * turns, so the geometric normal follows the mirrored normal. */
    s = transformed("{\"scale\": [-1, 1, 1]}");
    m = only_mesh(s);
    double g[3];
    winding_normal(m, g);
    double want[3] = {-1 / sqrt(3), 1 / sqrt(3), 1 / sqrt(3)};
    for (int a = 0; a < 3; a++) {
        assert_true(fabs(g[a] - want[a]) < 1e-6);
        assert_true(fabs(m->normal[a] - want[a]) < 1e-6);
    }
    zt_scene_release(s);

    /* Without a mirror the winding is the file's. */
    s = transformed("{\"translate\": [0, 0, 0]}");
    winding_normal(only_mesh(s), g);
    for (int a = 0; a < 3; a++)
        assert_true(fabs(g[a] - 1 / sqrt(3)) < 1e-6);
    zt_scene_release(s);
}

static void test_transform_errors(void **state)
{
    (void)state;
    test_write_file("corner.obj", corner_obj);
    /* Each message points at `at`, the first place in the line that holds
     * the mistake. */
    static const struct {
        const char *transform, *at, *reason;
    } bad[] = {
        {"{\"scale\": [1, 0, 1]}", "[1, 0", "a factor of 0"},
        {"{\"rotate\": [[0, 0, 0, 90]]}", "[0, 0, 0", "the axis is zero"},
        {"{\"rotate\": [0, 0, 1, 90]}", "0, 0, 1", "a rotation is [ax, ay, az, degrees]"},
        {"{\"shear\": 1}", "\"shear", "unknown key \"shear\""},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char extra[256], where[32];
        snprintf(extra, sizeof extra, ", \"transform\": %s", bad[i].transform);
        const char *line = "  {\"mesh\": {\"file\": \"corner.obj\"";
        snprintf(where, sizeof where, ":3:%d:",
                 (int)(strlen(line) + strlen(", \"transform\": ") +
                       (strstr(bad[i].transform, bad[i].at) - bad[i].transform) + 1));
        zt_scene *s;
        zt_error err;
        zt_status st = load(write_scene("s_badtransform.json", "corner.obj", extra), &s, &err);
        assert_int_equal(st, ZT_ERR_PARSE);
        if (!strstr(err.message, where) || !strstr(err.message, bad[i].reason))
            fail_msg("'%s' gives '%s'", bad[i].transform, err.message);
    }
}

/* ---------------------------------------------------------------------- */
/* Materials */

static void test_mtl_materials(void **state)
{
    (void)state;
    test_write_file("two.mtl", "newmtl glass\nKd 0.2 0.4 0.6\nd 0.25\nNi 1.33\n\n"
                               "newmtl lamp\nKd 0 0 0\nKe 1 2 3\n");
    test_write_file("two.obj", "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                               "usemtl glass\nf 1 2 3\nusemtl lamp\nf 2 4 3\n");
    zt_scene *s = load_ok(write_scene("s_mtl.json", "two.obj", ""));
    const mesh *m = only_mesh(s);
    assert_int_equal(m->slot_count, 2);
    const mesh_slot *glass = NULL, *lamp = NULL;
    for (int i = 0; i < m->slot_count; i++) {
        if (strcmp(m->slots[i].name, "glass") == 0)
            glass = &m->slots[i];
        if (strcmp(m->slots[i].name, "lamp") == 0)
            lamp = &m->slots[i];
    }
    assert_non_null(glass);
    assert_non_null(lamp);
    /* Kd is the colour; dissolve 0.25 leaves 0.75 to glass; Ni its index. */
    assert_true(fabs(glass->mat.color.x - 0.2) < 1e-6 && fabs(glass->mat.color.y - 0.4) < 1e-6 &&
                fabs(glass->mat.color.z - 0.6) < 1e-6);
    assert_true(fabs(glass->mat.weight[LOBE_REFRACTIVE] - 0.75) < 1e-6);
    assert_true(fabs(glass->mat.weight[LOBE_DIFFUSE] - 0.25) < 1e-6);
    assert_true(glass->mat.weight[LOBE_METALLIC] == 0 && glass->mat.weight[LOBE_REFLECTING] == 0);
    assert_true(fabs(glass->mat.ior - 1.33) < 1e-6);
    /* MTL's dissolve is see-through: a pane, untinted (Kd is its surface's). */
    assert_true(glass->mat.thin);
    assert_true(glass->mat.tint.x == 1 && glass->mat.tint.y == 1 && glass->mat.tint.z == 1);
    assert_true(glass->emission.x == 0 && glass->emission.y == 0 && glass->emission.z == 0);
    /* Ke makes the lamp's triangle a light part. */
    assert_true(fabs(lamp->emission.x - 1) < 1e-6 && fabs(lamp->emission.y - 2) < 1e-6 &&
                fabs(lamp->emission.z - 3) < 1e-6);
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    assert_int_equal(info.light_parts, 1);
    assert_int_equal(info.thing_parts, 1);
    zt_scene_release(s);

    /* A material in the scene overrides the file's: one slot, no light. */
    s = load_ok(write_scene("s_mtl_override.json", "two.obj", ", " TEST_DIFFUSE(0.5)));
    m = only_mesh(s);
    assert_int_equal(m->slot_count, 1);
    assert_true(m->slots[0].mat.weight[LOBE_DIFFUSE] == 1 && m->slots[0].mat.color.x == 0.5);
    zt_scene_get_info(s, &info);
    assert_int_equal(info.light_parts, 0);
    zt_scene_release(s);
}


/* Formats without materials (PLY, STL, OFF) and an OBJ without its MTL get
 * the default light grey, not the white or grey Assimp invents for them;
 * a white the file states is kept. */
static void test_invented_materials_grey(void **state)
{
    (void)state;
    test_write_file("bare.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                "property float y\nproperty float z\nelement face 1\n"
                                "property list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    test_write_file("bare.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    test_write_file("white.mtl", "newmtl white\nKd 1 1 1\n");
    test_write_file("white.obj", "mtllib white.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                 "usemtl white\nf 1 2 3\n");
    const char *models[3] = {"bare.ply", "bare.obj", "white.obj"};
    const double want[3] = {0.8, 0.8, 1.0};
    for (int k = 0; k < 3; k++) {
        zt_scene *s = load_ok(write_scene("s_invented.json", models[k], ""));
        const mesh *m = only_mesh(s);
        assert_int_equal(m->slot_count, 1);
        const material *mat = &m->slots[0].mat;
        assert_true(mat->weight[LOBE_DIFFUSE] == 1.0);
        assert_true(fabs(mat->color.x - want[k]) < 1e-6 && fabs(mat->color.y - want[k]) < 1e-6 &&
                    fabs(mat->color.z - want[k]) < 1e-6);
        zt_scene_release(s);
    }
}

/* glTF's non-metals get the clear coat (the layer over their base), scaled
 * by KHR_materials_specular's specularFactor, which Assimp 5.2 does not
 * pass on and the importer reads from the file: 0 in tilt.gltf, none (1)
 * in rough.gltf.  An MTL's Ks is the coat's strength as Blender's OBJ
 * importer reads it (Principled's Specular, F0 = 0.08 mean(Ks), so s = 2
 * mean(Ks), at most 1); without Ks there is none.  Only a coloured Ks
 * (whose tint the white coat leaves out) is reported unused. */
static void test_gltf_specular_layer(void **state)
{
    (void)state;
    enum { N = 6 };
    const char *models[N] = {ZT_SOURCE_DIR "/tests/data/pbr/tilt.gltf",
                             ZT_SOURCE_DIR "/tests/data/pbr/rough.gltf",
                             "white.obj", "ks_quarter.obj", "ks_one.obj", "ks_tinted.obj"};
    const char *ks[N] = {NULL, NULL, NULL, "0.25 0.25 0.25", "1 1 1", "0.1 0.2 0.3"};
    const double want[N] = {0.0, 1.0, 0.0, 0.5, 1.0, 0.4};
    for (int k = 2; k < N; k++) {
        char mtl[64], obj[64], text[256];
        snprintf(mtl, sizeof mtl, "%.*s.mtl", (int)(strlen(models[k]) - 4), models[k]);
        snprintf(obj, sizeof obj, "%s", models[k]);
        snprintf(text, sizeof text, "newmtl white\nKd 1 1 1\n%s%s%s", ks[k] ? "Ks " : "",
                 ks[k] ? ks[k] : "", ks[k] ? "\n" : "");
        test_write_file(mtl, text);
        snprintf(text, sizeof text,
                 "mtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl white\nf 1 2 3\n", mtl);
        test_write_file(obj, text);
    }
    for (int k = 0; k < N; k++) {
        zt_scene *s = load_ok(write_scene("s_layer.json", models[k], ""));
        const mesh *m = only_mesh(s);
        for (int i = 0; i < m->slot_count; i++)
            if (fabs(m->slots[i].mat.specular - want[k]) > 1e-6)
                fail_msg("%s: specular %g, want %g", models[k], m->slots[i].mat.specular,
                         want[k]);
        if (k >= 2) {
            zt_scene_info info;
            zt_scene_get_info(s, &info);
            int tinted = strstr(info.unused, "specular") != NULL;
            if (tinted != (k == N - 1))
                fail_msg("%s: unused \"%s\"", models[k], info.unused);
        }
        zt_scene_release(s);
    }
}

/* ---------------------------------------------------------------------- */
/* Textures */

/* 4 x 2 texels, 8-bit RGB, row 0 at the top. */
static const unsigned char texels[2][4][3] = {
    {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 255}},
    {{16, 64, 128}, {200, 100, 50}, {0, 0, 0}, {128, 128, 128}},
};

static void write_png(const char *path)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_set_IHDR(png, info, 4, 2, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < 2; y++)
        png_write_row(png, (png_const_bytep)texels[y]);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    fclose(f);
}

/* sRGB code to linear, written out here from the sRGB definition. */
static double srgb_linear(int code)
{
    double c = code / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* The expected bilinear value with wrapping, computed independently of
 * texture_lookup: texel centres at ((i + 0.5) / 4, 1 - (j + 0.5) / 2). */
static double expected_texel(double u, double v, int c)
{
    double x = u * 4 - 0.5, y = (1 - v) * 2 - 0.5;
    double fx = floor(x), fy = floor(y);
    double ax = x - fx, ay = y - fy;
    double sum = 0;
    for (int dy = 0; dy < 2; dy++)
        for (int dx = 0; dx < 2; dx++) {
            int i = (((int)fx + dx) % 4 + 4) % 4, j = (((int)fy + dy) % 2 + 2) % 2;
            double w = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
            sum += w * srgb_linear(texels[j][i][c]);
        }
    return sum;
}

/* A 2 x 2 unit quad at z = 0 with texture coordinates 0..1, its material
 * with the texture `png` (may be missing). */
static void write_textured_quad(const char *obj, const char *mtl, const char *png)
{
    char text[512];
    snprintf(text, sizeof text, "newmtl tex\nKd 1 1 1\nmap_Kd %s\n", png);
    test_write_file(mtl, text);
    snprintf(text, sizeof text,
             "mtllib %s\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
             mtl);
    test_write_file(obj, text);
}

static void test_texture_texels_and_lookup(void **state)
{
    (void)state;
    write_png(test_tmp_path("texels.png"));
    write_textured_quad("quad.obj", "quad.mtl", "texels.png");
    zt_scene *s = load_ok(write_scene("s_tex.json", "quad.obj", ""));
    const mesh *m = only_mesh(s);
    assert_int_equal(m->texture_count, 1);
    const mesh_texture *t = &m->textures[0];
    assert_int_equal(t->width, 4);
    assert_int_equal(t->height, 2);
    assert_int_equal(t->wrap, 1);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 4; i++) {
            for (int c = 0; c < 3; c++)
                assert_int_equal(t->rgba[4 * (4 * j + i) + c], texels[j][i][c]);
            assert_int_equal(t->rgba[4 * (4 * j + i) + 3], 255);
        }
    assert_non_null(m->uv);

    /* Lookups at texel centres, between them, and wrapped past u = 1. */
    static const double at[][2] = {{0.125, 0.75}, {0.375, 0.25}, {0.25, 0.5}, {0.9, 0.6},
                                   {1.25, 0.75}, {-0.3, 1.4}, {0.01, 0.99}};
    for (size_t k = 0; k < sizeof at / sizeof at[0]; k++) {
        vec3f got = texture_lookup(t, (float)at[k][0], (float)at[k][1]);
        double g[3] = {got.x, got.y, got.z};
        for (int c = 0; c < 3; c++)
            if (fabs(g[c] - expected_texel(at[k][0], at[k][1], c)) > 1e-5)
                fail_msg("lookup (%g, %g) channel %d: %g, expected %g", at[k][0], at[k][1], c,
                         g[c], expected_texel(at[k][0], at[k][1], c));
    }
    vec3f a = texture_lookup(t, 1.25f, 0.75f), b = texture_lookup(t, 0.25f, 0.75f);
    assert_true(a.x == b.x && a.y == b.y && a.z == b.z);
    zt_scene_release(s);
}

/* The quad seen face on under a white sky: a diffuse surface of albedo
 * rho there has radiance rho, so each pixel is the texture's mean over the
 * pixel, which the test integrates itself. */
static void test_texture_rendered(void **state)
{
    (void)state;
    write_png(test_tmp_path("texels.png"));
    write_textured_quad("quad.obj", "quad.mtl", "texels.png");
    /* The camera at z = d sees [-h a, h a] x [-h, h] at z = 0 with h = d
     * tan(fov / 2), a = 2; the quad spans 1.25 times that. */
    const int w = 32, hgt = 16;
    double half = 1.0 / 1.25, d = half / tan(20.0 * 3.14159265358979323846 / 180.0);
    char text[1024];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [0, 0, %.17g], \"lookat\": [0, 0, 0], "
             "\"up\": [0, 1, 0], \"fov\": 40, \"gridresolution\": [%d, %d]},\n"
             " \"scene\": [\n"
             "  {\"sky\": {\"color\": [1, 1, 1]}},\n"
             "  {\"mesh\": {\"file\": \"quad.obj\", \"transform\": {\"scale\": [2, 1, 1]}}}\n"
             " ]}\n",
             d, w, hgt);
    zt_scene *s = load_ok(test_write_file("s_texrender.json", text));
    zt_render_options o = zt_render_options_default();
    o.method = ZT_METHOD_PATH;
    o.spp = 256;
    o.threads = 2;
    zt_image *img = NULL;
    zt_error err = {0};
    if (zt_render(s, &o, &img, NULL, &err) != ZT_OK)
        fail_msg("render: %s", err.message);
    double worst = 0, se = 0, sum = 0;
    for (int y = 0; y < hgt; y++)
        for (int x = 0; x < w; x++) {
            double want[3] = {0, 0, 0};
            const int n = 16;
            for (int sy = 0; sy < n; sy++)
                for (int sx = 0; sx < n; sx++) {
                    /* The screen point in [-1, 1]^2, then the quad's uv. */
                    double px = (x + (sx + 0.5) / n) / w * 2 - 1;
                    double py = 1 - (y + (sy + 0.5) / n) / hgt * 2;
                    double u = 0.5 + 0.5 * px * half, v = 0.5 + 0.5 * py * half;
                    for (int c = 0; c < 3; c++)
                        want[c] += expected_texel(u, v, c) / (n * n);
                }
            for (int c = 0; c < 3; c++) {
                double got = img->pixels[3 * (y * w + x) + c];
                double e = fabs(got - want[c]);
                worst = fmax(worst, e);
                se += e * e;
                sum += want[c];
            }
        }
    double rel = sqrt(se / (w * hgt * 3)) / (sum / (w * hgt * 3));
    fprintf(stderr, "textured quad: rel RMSE %.2e, worst pixel error %.2e\n", rel, worst);
    /* Only the anti-aliasing jitter is random here (the sky is uniform), and
     * the texture is smooth within a pixel: 256 samples leave ~1e-5. */
    assert_true(rel < 1e-3);
    assert_true(worst < 2e-3);
    zt_image_release(img);
    zt_scene_release(s);
}

static void test_missing_texture_noted(void **state)
{
    (void)state;
    write_textured_quad("quad_missing.obj", "quad_missing.mtl", "not_there.png");
    zt_scene *s = load_ok(write_scene("s_notex.json", "quad_missing.obj", ""));
    zt_scene_info info;
    zt_scene_get_info(s, &info);
    assert_int_equal(info.missing_textures, 1);
    assert_non_null(strstr(info.texture_problem, "not_there.png"));
    const mesh *m = only_mesh(s);
    assert_int_equal(m->texture_count, 0);
    assert_int_equal(m->slots[0].texture, -1);
    zt_scene_release(s);
}

/* Normals made for a file without them: a cube's corners stay corners
 * (every vertex normal of a triangle is the triangle's own), and a prism of
 * 12 sides (30 degrees between neighbouring faces) shades smooth (its
 * side's vertex normals point straight out from the axis). */
static void test_made_normals_keep_corners(void **state)
{
    (void)state;
    test_write_file("cube.obj",
                    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
    zt_scene *s = load_ok(write_scene("s_cube.json", "cube.obj", ""));
    const mesh *m = only_mesh(s);
    assert_non_null(m->normal);
    assert_int_equal(m->triangle_count, 12);
    for (int t = 0; t < m->triangle_count; t++) {
        double p[3][3], e1[3], e2[3], g[3];
        for (int c = 0; c < 3; c++)
            for (int a = 0; a < 3; a++)
                p[c][a] = m->position[3 * m->index[3 * t + c] + a];
        for (int a = 0; a < 3; a++) {
            e1[a] = p[1][a] - p[0][a];
            e2[a] = p[2][a] - p[0][a];
        }
        g[0] = e1[1] * e2[2] - e1[2] * e2[1];
        g[1] = e1[2] * e2[0] - e1[0] * e2[2];
        g[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double l = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        for (int c = 0; c < 3; c++) {
            const float *n = m->normal + 3 * m->index[3 * t + c];
            double dot = (n[0] * g[0] + n[1] * g[1] + n[2] * g[2]) / l;
            if (!(dot > 0.9999))
                fail_msg("triangle %d corner %d: normal (%g, %g, %g) is not its face's", t, c,
                         n[0], n[1], n[2]);
        }
    }
    zt_scene_release(s);

    char text[4096];
    size_t len = 0;
    for (int k = 0; k < 12; k++) {
        double a = 2 * 3.14159265358979 * k / 12;
        len += (size_t)snprintf(text + len, sizeof text - len, "v %.9f 0 %.9f\nv %.9f 1 %.9f\n",
                                cos(a), sin(a), cos(a), sin(a));
    }
    for (int k = 0; k < 12; k++) {
        int b = 2 * k + 1, c = 2 * ((k + 1) % 12) + 1;
        len += (size_t)snprintf(text + len, sizeof text - len, "f %d %d %d %d\n", b, b + 1, c + 1,
                                c);
    }
    test_write_file("prism.obj", text);
    s = load_ok(write_scene("s_prism.json", "prism.obj", ""));
    m = only_mesh(s);
    assert_non_null(m->normal);
    for (int v = 0; v < m->vertex_count; v++) {
        const float *p = m->position + 3 * v, *n = m->normal + 3 * v;
        double r = sqrt(p[0] * p[0] + p[2] * p[2]);
        double dot = fabs(n[0] * p[0] + n[2] * p[2]) / r;
        if (!(dot > 0.9999) || !(fabs(n[1]) < 1e-4))
            fail_msg("prism vertex %d: normal (%g, %g, %g) is not radial", v, n[0], n[1], n[2]);
    }
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_model_files),
        cmocka_unit_test(test_degenerate_counted),
        cmocka_unit_test(test_broken_gltf),
        cmocka_unit_test(test_transform_points),
        cmocka_unit_test(test_transform_errors),
        cmocka_unit_test(test_mtl_materials),
        cmocka_unit_test(test_invented_materials_grey),
        cmocka_unit_test(test_gltf_specular_layer),
        cmocka_unit_test(test_texture_texels_and_lookup),
        cmocka_unit_test(test_texture_rendered),
        cmocka_unit_test(test_missing_texture_noted),
        cmocka_unit_test(test_made_normals_keep_corners),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
