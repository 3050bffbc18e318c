/* Model files' roughness, metal and normal maps, in both renderers,
 * against formulas written out here (in double, from the texel codes that
 * tests/data/make_pbr_models.sh writes):
 *
 * - a metal square whose metallic-roughness texture makes its left half
 *   rough (128/255) and its right half smooth, under a sun: the left half
 *   shows the sun through the GGX lobe (with Schlick's Fresnel and the
 *   metal's energy compensation), the right half the sun's disc mirrored,
 *   times Schlick's Fresnel;
 * - a white diffuse square whose normal map tilts the normal of its left
 *   half by 30 degrees: under the sun its halves read E/pi times the cosine
 *   of the sun to their mapped normals, with tangents made by the reader or
 *   given by the file (and a normal scale), and under a rotation and a
 *   mirror of the model;
 * - maps of another size than the base texture are used; maps that
 *   cannot be decoded are left out, counted and named, and the render
 *   stays finite. */
#include "test_support.h"
#include "d3.h"
#include "ggx_reference.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846
#define MODELS ZT_SOURCE_DIR "/tests/data/pbr/"


/* The code make_pbr_gltf.py writes for a component c in [-1, 1], and the
 * value a reader takes from it. */
static double code_value(double c)
{
    return 2 * lround(255 * (c + 1) / 2) / 255.0 - 1;
}

static const char *const method_name[] = {"path", "zone"};
static const zt_method methods[] = {ZT_METHOD_PATH, ZT_METHOD_ZONE};

/* The mean of the image of a narrow view (0.5 degrees) at point q from
 * direction wo (unit, 3 units away), the model `file` placed by
 * `transform` (JSON, or ""), under a sun of irradiance 100 and angle
 * `angle` degrees around s, nothing else: light of level 1 alone. */
static double view_mean(zt_method method, const char *file, const char *transform, d3 q, d3 wo,
                        d3 s, double angle, int spp)
{
    char text[2048];
    d3 eye = add(q, scale(wo, 3));
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, %.17g], \"irradiance\": "
             "[100, 100, 100], \"angle\": %.17g}}, {\"mesh\": {\"file\": \"%s\"%s%s}}], "
             "\"camera\": {\"position\": [%.17g, %.17g, %.17g], \"lookat\": [%.17g, %.17g, "
             "%.17g], \"fov\": 0.5, \"gridresolution\": [8, 8]}}",
             s.x, s.y, s.z, angle, file, transform[0] ? ", \"transform\": " : "", transform,
             eye.x, eye.y, eye.z, q.x, q.y, q.z);
    zt_scene *sc = test_scene_text(text, "model_maps");
    double mean = test_render_mean(sc, method, 1, 1, spp);
    zt_scene_release(sc);
    return mean;
}

/* ---- The rough and smooth halves of a metal. */

/* The metal's reflectance at normal incidence: glTF's is the base colour,
 * white here. */
static double r0_metal(void)
{
    return 1.0;
}

static double schlick(double c)
{
    double m = 1 - c;
    return r0_metal() + (1 - r0_metal()) * m * m * m * m * m;
}

/* GGX with alpha a, in a frame whose z is the normal. */
static double ggx_d(d3 h, double a) { return ggx_ref_d(h.z, a); }
static double lambda(d3 w, double a) { return ggx_ref_lambda(w.z, a); }

/* f cos_i of the rough reflector from wo to wi, with Fresnel F(wo.h) or
 * (fresnel 0) without. */
static double lobe(d3 wo, d3 wi, double a, int fresnel)
{
    if (wi.z <= 0)
        return 0;
    d3 h = unit(add(wo, wi));
    double g2 = 1 / (1 + lambda(wo, a) + lambda(wi, a));
    return (fresnel ? schlick(dot(wo, h)) : 1) * ggx_d(h, a) * g2 / (4 * wo.z);
}

/* The white lobe's albedo at wo (midpoint rule over the hemisphere). */
static double albedo(d3 wo, double a)
{
    const int nt = 2000, np = 400;
    double sum = 0;
    for (int i = 0; i < nt; i++) {
        double z = (i + 0.5) / nt, r = sqrt(1 - z * z);
        for (int j = 0; j < np; j++) {
            double p = 2 * PI * (j + 0.5) / np;
            sum += lobe(wo, mk(r * cos(p), r * sin(p), z), a, 0);
        }
    }
    return sum * (1.0 / nt) * (2 * PI / np);
}

/* Radiance toward wo from a sun disc of half-angle th around s, irradiance
 * e, through the metal's compensated lobe: the mean over the disc, times
 * c = 1 + R0 (1 - E) / E (docs/light-transport.md). */
static double sun_through_metal(d3 wo, d3 s, double th, double e, double a)
{
    d3 u = unit(fabs(s.x) < 0.9 ? mk(s.z, 0, -s.x) : mk(0, s.z, -s.y));
    d3 v = cross(s, u);
    const int nr = 200, np = 200;
    double sum = 0, ct_min = cos(th);
    for (int i = 0; i < nr; i++) {
        double ct = 1 - (1 - ct_min) * (i + 0.5) / nr, st = sqrt(1 - ct * ct);
        for (int j = 0; j < np; j++) {
            double p = 2 * PI * (j + 0.5) / np;
            d3 wi = add(scale(s, ct), add(scale(u, st * cos(p)), scale(v, st * sin(p))));
            sum += lobe(wo, wi, a, 1);
        }
    }
    double solid = 2 * PI * (1 - ct_min);
    double radiance = e / (PI * sin(th) * sin(th));
    double ea = albedo(wo, a);
    return radiance * sum * solid / (nr * np) * (1 + r0_metal() * (1 - ea) / ea);
}

static void test_rough_and_smooth_halves(void **state)
{
    (void)state;
    /* The square lies in y = 0, +x along u: x = -0.5 is the rough half
     * (u = 0.25), x = +0.5 the smooth one. */
    double r = 128 / 255.0, th = 5.0 / 2 * PI / 180;
    d3 s = unit(mk(0.3, 0.8, 0.2)), wo = unit(mk(-0.3, 0.7, -0.1));
    /* The plane's frame: z is the world's y. */
    double want_rough = sun_through_metal(mk(wo.x, wo.z, wo.y), mk(s.x, s.z, s.y), th, 100, r * r);
    /* Seen along the mirror direction, the smooth half shows the disc. */
    d3 wm = mk(-s.x, s.y, -s.z);
    double want_smooth = 100 / (PI * sin(th) * sin(th)) * schlick(s.y);
    for (int mi = 0; mi < 2; mi++) {
        double got_rough = view_mean(methods[mi], MODELS "rough.gltf", "", mk(-0.5, 0, 0), wo, s,
                                     5, 256);
        double got_smooth = view_mean(methods[mi], MODELS "rough.gltf", "", mk(0.5, 0, 0), wm, s,
                                      5, 16);
        print_message("%s: metal, rough half (roughness 128/255): %.7g, formula %.7g (%+.3f%%)\n",
                      method_name[mi], got_rough, want_rough, 100 * (got_rough / want_rough - 1));
        print_message("%s: metal, smooth half, the sun mirrored: %.5g, formula %.5g (%+.4f%%)\n",
                      method_name[mi], got_smooth, want_smooth,
                      100 * (got_smooth / want_smooth - 1));
        assert_true(fabs(got_rough / want_rough - 1) < 0.01);
        assert_true(fabs(got_smooth / want_smooth - 1) < 0.001);
        /* The rough half does not show the mirrored disc, nor the smooth
         * half the lobe's glow. */
        double rough_mirrored = view_mean(methods[mi], MODELS "rough.gltf", "", mk(-0.5, 0, 0),
                                          wm, s, 5, 64);
        double smooth_off = view_mean(methods[mi], MODELS "rough.gltf", "", mk(0.5, 0, 0), wo, s,
                                      5, 16);
        print_message("%s: rough half along the mirror direction %.5g (the disc: %.5g); smooth "
                      "half off it %.3g\n",
                      method_name[mi], rough_mirrored, want_smooth, smooth_off);
        assert_true(rough_mirrored < 0.2 * want_smooth);
        assert_true(smooth_off == 0);
    }
}

/* ---- The tilted normals of a diffuse square. */

/* The model's mapped normal (model space: tangent +x, bitangent -z,
 * normal +y) for a texel coding (sin t, 0, cos t), times the scale in x
 * and y. */
static d3 mapped_normal(double tilt_deg, double nscale)
{
    double t = tilt_deg * PI / 180;
    double x = code_value(sin(t)) * nscale, y = code_value(0) * nscale, z = code_value(cos(t));
    return unit(add(add(scale(mk(1, 0, 0), x), scale(mk(0, 0, -1), y)), scale(mk(0, 1, 0), z)));
}

/* a p, a row-major 3x3. */
static d3 apply(const double a[9], d3 p)
{
    return mk(a[0] * p.x + a[1] * p.y + a[2] * p.z, a[3] * p.x + a[4] * p.y + a[5] * p.z,
              a[6] * p.x + a[7] * p.y + a[8] * p.z);
}

static void test_tilted_normals(void **state)
{
    (void)state;
    /* Transforms of the model: none, a quarter turn about y, a mirror in
     * x.  All three are orthogonal: normals go by the same matrix. */
    const char *transform[3] = {"", "{\"rotate\": [[0, 1, 0, 90]]}", "{\"scale\": [-1, 1, 1]}"};
    const double a[3][9] = {{1, 0, 0, 0, 1, 0, 0, 0, 1},
                            {0, 0, 1, 0, 1, 0, -1, 0, 0},
                            {-1, 0, 0, 0, 1, 0, 0, 0, 1}};
    const struct {
        const char *file;
        double nscale;
    } model[2] = {{MODELS "tilt.gltf", 1.0}, {MODELS "tilt_tangents.gltf", 0.5}};
    /* A sun of 0.53 degrees: the mean cosine over its disc is the
     * centre's times (1 + cos th) / 2. */
    double th = 0.53 / 2 * PI / 180, disc = (1 + cos(th)) / 2;
    d3 s = unit(mk(0.5, 0.7, 0.3)), wo = unit(mk(-0.2, 0.9, 0.35));
    for (int mi = 0; mi < 2; mi++)
        for (int f = 0; f < 2; f++)
            for (int k = 0; k < 3; k++) {
                if (f == 1 && k > 0)
                    continue; /* the file's tangents: untransformed */
                double got[2], want[2];
                for (int half = 0; half < 2; half++) {
                    d3 n = apply(a[k], mapped_normal(half == 0 ? 30 : 0, model[f].nscale));
                    d3 q = apply(a[k], mk(half == 0 ? -0.5 : 0.5, 0, 0));
                    want[half] = 100 / PI * dot(n, s) * disc;
                    got[half] = view_mean(methods[mi], model[f].file, transform[k], q, wo, s,
                                          0.53, 16);
                }
                double tilt = acos(dot(apply(a[k], mapped_normal(30, model[f].nscale)),
                                       apply(a[k], mapped_normal(0, model[f].nscale)))) *
                              180 / PI;
                print_message("%s: %s%s%s: tilted half %.6g, formula %.6g (%+.4f%%); flat half "
                              "%.6g, formula %.6g (%+.4f%%); ratio %.6g, cos ratio %.6g "
                              "(maps %.2f degrees apart)\n",
                              method_name[mi], model[f].file + strlen(MODELS),
                              transform[k][0] ? " " : "", transform[k], got[0], want[0],
                              100 * (got[0] / want[0] - 1), got[1], want[1],
                              100 * (got[1] / want[1] - 1), got[0] / got[1], want[0] / want[1],
                              tilt);
                for (int half = 0; half < 2; half++)
                    assert_true(fabs(got[half] / want[half] - 1) < 0.002);
            }
}

/* ---- MTL: Ns as roughness, norm as the normal map. */

/* The square of make_pbr_gltf.py as an OBJ (u along +x, v growing toward
 * -z) with material `mtl` (MTL text), written to the temporary folder;
 * returns the OBJ's path. */
static const char *write_obj(const char *name, const char *mtl)
{
    char mtl_name[64], obj_name[64], text[1024];
    snprintf(mtl_name, sizeof mtl_name, "%s.mtl", name);
    snprintf(obj_name, sizeof obj_name, "%s.obj", name);
    test_write_file(mtl_name, mtl);
    snprintf(text, sizeof text,
             "mtllib %s\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\n"
             "vt 0 1\nvn 0 1 0\nusemtl m\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n",
             mtl_name);
    return test_write_file(obj_name, text);
}

static void test_mtl(void **state)
{
    (void)state;
    /* Ns 98 without Pr: roughness (2 / 100)^(1/4), the same bits as a
     * scene material of that roughness on the same square. */
    char obj[512], mat[512];
    snprintf(obj, sizeof obj, "%s", write_obj("ns", "newmtl m\nKd 1 1 1\nPm 1\nNs 98\n"));
    snprintf(mat, sizeof mat,
             ", \"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 1, \"reflecting\": "
             "0, \"refractive\": 0}, \"color\": [1, 1, 1], \"refractiveindex\": 1e-30, "
             "\"roughness\": %.17g}",
             pow(2.0 / 100.0, 0.25));
    d3 s = unit(mk(0.3, 0.8, 0.2)), wo = unit(mk(-0.3, 0.7, -0.1));
    for (int mi = 0; mi < 2; mi++) {
        double a = view_mean(methods[mi], obj, "", mk(0, 0, 0), wo, s, 5, 16);
        char text[2048];
        d3 eye = add(mk(0, 0, 0), scale(wo, 3));
        snprintf(text, sizeof text,
                 "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, %.17g], \"irradiance\": "
                 "[100, 100, 100], \"angle\": 5}}, {\"mesh\": {\"file\": \"%s\"%s}}], "
                 "\"camera\": {\"position\": [%.17g, %.17g, %.17g], \"lookat\": [0, 0, 0], "
                 "\"fov\": 0.5, \"gridresolution\": [8, 8]}}",
                 s.x, s.y, s.z, obj, mat, eye.x, eye.y, eye.z);
        zt_scene *sc = test_scene_text(text, "ns_as_material");
        zt_image *im = test_render_level(sc, methods[mi], 1, 1, 16);
        double b = 0;
        for (int i = 0; i < 3 * im->width * im->height; i++)
            b += im->pixels[i];
        b /= 3 * im->width * im->height;
        zt_image_release(im);
        zt_scene_release(sc);
        print_message("%s: MTL Ns 98 %.7g, a material of roughness (2/100)^(1/4) %.7g\n",
                      method_name[mi], a, b);
        assert_true(a == b);
    }
    /* norm: tilt.gltf's normal map on the OBJ square reads as on the glTF
     * one. */
    test_copy_file(MODELS "tilt_n.png", test_tmp_path("tilt_n.png"));
    snprintf(obj, sizeof obj, "%s", write_obj("norm", "newmtl m\nKd 1 1 1\nnorm tilt_n.png\n"));
    double th = 0.53 / 2 * PI / 180, disc = (1 + cos(th)) / 2;
    s = unit(mk(0.5, 0.7, 0.3));
    wo = unit(mk(-0.2, 0.9, 0.35));
    for (int mi = 0; mi < 2; mi++)
        for (int half = 0; half < 2; half++) {
            double want = 100 / PI * dot(mapped_normal(half == 0 ? 30 : 0, 1), s) * disc;
            double got = view_mean(methods[mi], obj, "", mk(half == 0 ? -0.5 : 0.5, 0, 0), wo, s,
                                   0.53, 16);
            print_message("%s: MTL norm, %s half %.6g, formula %.6g (%+.4f%%)\n", method_name[mi],
                          half == 0 ? "tilted" : "flat", got, want, 100 * (got / want - 1));
            assert_true(fabs(got / want - 1) < 0.002);
        }
}

/* ---- Maps left out. */

static void test_maps_left_out(void **state)
{
    (void)state;
    /* Maps of another size than the base texture (8 x 8 over 16 x 16) are
     * used: looked up by texture coordinates, the tilted half reads as
     * tilt.gltf's. */
    double th = 0.53 / 2 * PI / 180, disc = (1 + cos(th)) / 2;
    d3 s = unit(mk(0.5, 0.7, 0.3)), wo = unit(mk(-0.2, 0.9, 0.35));
    double want = 100 / PI * dot(mapped_normal(30, 1.0), s) * disc;
    for (int mi = 0; mi < 2; mi++) {
        double got = view_mean(methods[mi], MODELS "sizes.gltf", "", mk(-0.5, 0, 0), wo, s, 0.53,
                               16);
        print_message("sizes.gltf (maps 8x8, base 16x16), %s: tilted half %.6g, formula %.6g "
                      "(%+.4f%%)\n", method_name[mi], got, want, 100 * (got / want - 1));
        assert_true(fabs(got / want - 1) < 0.002);
    }
    char text[1024];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [0.5, 0.7, 0.3], \"irradiance\": [100, 100, "
             "100]}}, {\"mesh\": {\"file\": \"%s\"}}], \"camera\": {\"position\": [0, 3, 1], "
             "\"lookat\": [0, 0, 0], \"fov\": 40, \"gridresolution\": [16, 16]}}",
             MODELS "sizes.gltf");
    zt_scene *sc = test_scene_text(text, "sizes");
    zt_scene_info info;
    zt_scene_get_info(sc, &info);
    assert_int_equal(info.map_fallbacks, 0);
    zt_scene_release(sc);

    /* Cannot be decoded: a copy of tilt.gltf whose two maps are not
     * images.  The flat square then reads the same in both halves. */
    const char *names[] = {"tilt.gltf", "tilt.bin"};
    for (int i = 0; i < 2; i++) {
        char from[512];
        snprintf(from, sizeof from, "%s%s", MODELS, names[i]);
        test_copy_file(from, test_tmp_path(names[i]));
    }
    test_write_file("tilt_mr.png", "not a PNG");
    test_write_file("tilt_n.png", "\x89PNG\r\n\x1a\n but cut short");
    char file[512];
    snprintf(file, sizeof file, "%s", test_tmp_path("tilt.gltf"));
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [0.5, 0.7, 0.3], \"irradiance\": [100, 100, "
             "100]}}, {\"mesh\": {\"file\": \"%s\"}}], \"camera\": {\"position\": [0, 3, 1], "
             "\"lookat\": [0, 0, 0], \"fov\": 40, \"gridresolution\": [16, 16]}}",
             file);
    sc = test_scene_text(text, "undecodable");
    zt_scene_get_info(sc, &info);
    print_message("tilt.gltf with broken maps: %d left out (%s)\n", info.map_fallbacks,
                  info.map_problem);
    assert_int_equal(info.map_fallbacks, 2);
    assert_non_null(strstr(info.map_problem, "tilt_mr.png"));
    zt_scene_release(sc);
    /* Without its texture the material is its factors: metallic 1 (the
     * file's factor), roughness 1.  Finite, and alike in both halves. */
    for (int mi = 0; mi < 2; mi++) {
        double l = view_mean(methods[mi], file, "", mk(-0.5, 0, 0), wo, s, 0.53, 16);
        double r = view_mean(methods[mi], file, "", mk(0.5, 0, 0), wo, s, 0.53, 16);
        print_message("%s: broken maps, halves %.6g and %.6g\n", method_name[mi], l, r);
        assert_true(isfinite(l) && isfinite(r) && l > 0);
        assert_true(fabs(l / r - 1) < 0.05);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rough_and_smooth_halves),
        cmocka_unit_test(test_tilted_normals),
        cmocka_unit_test(test_mtl),
        cmocka_unit_test(test_maps_left_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
