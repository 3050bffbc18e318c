/* Rough lobes (GGX) in the path tracer: white rough spheres in a white
 * furnace return the sky (energy compensation), roughness 0 is the smooth
 * material bit for bit, and the sun reflected by a rough mirror and seen
 * through a rough glass interface against the microfacet formulas written
 * out here (in double, independently of the renderer), which checks the
 * lobes' values, their densities and the MIS between them and the sun. */
#include "test_support.h"
#include "d3.h"
#include "ggx_reference.h"
#include "fresnel.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "zonetrace/render.h"
#include "zonetrace/scene.h"

#define PI 3.14159265358979323846


/* GGX with alpha a, in a frame whose z is the normal. */
static double ggx_d(d3 h, double a) { return ggx_ref_d(h.z, a); }
static double lambda(d3 w, double a) { return ggx_ref_lambda(w.z, a); }

/* The clear coat's Fresnel: Schlick's with F0 = 0.04. */
#define COAT (-1.0)
static double coat_schlick(double c)
{
    return 0.04 + 0.96 * pow(1 - c, 5);
}

/* f |cos_i| of the white rough interface from wo (z > 0) to wi, without
 * compensation and, for transmission, in energy (no 1/eta^2); eta = 0 is
 * the mirror, COAT the clear coat over a diffuse base. */
static double lobe(d3 wo, d3 wi, double a, double eta)
{
    double g2 = 1 / (1 + lambda(wo, a) + lambda(wi, a));
    if (wi.z > 0) {
        d3 h = unit(add(wo, wi));
        double f = eta > 0 ? fresnel(dot(wo, h), 1, eta) : eta == COAT ? coat_schlick(dot(wo, h)) : 1;
        return f * ggx_d(h, a) * g2 / (4 * wo.z);
    }
    if (eta <= 0)
        return 0;
    d3 h = unit(add(wo, scale(wi, eta)));
    if (h.z < 0)
        h = scale(h, -1);
    double co = dot(wo, h), ci = dot(wi, h);
    if (co <= 0 || ci >= 0)
        return 0;
    double den = ci + co / eta;
    return (1 - fresnel(co, 1, eta)) * ggx_d(h, a) * g2 * -ci * co / (wo.z * den * den);
}

/* The lobe's albedo at wo by the midpoint rule over the sphere of wi, in
 * cos theta (fine near the poles, where the lobes peak) and phi. */
static double albedo(d3 wo, double a, double eta)
{
    const int nt = 2000, np = 400;
    double sum = 0;
    for (int i = 0; i < nt; i++) {
        double z = -1 + 2 * (i + 0.5) / nt, r = sqrt(1 - z * z);
        for (int j = 0; j < np; j++) {
            double p = 2 * PI * (j + 0.5) / np;
            sum += lobe(wo, mk(r * cos(p), r * sin(p), z), a, eta);
        }
    }
    return sum * (2.0 / nt) * (2 * PI / np);
}

/* Radiance from a sun disc of half-angle th around s, irradiance e (the
 * renderer's radiance e / (pi sin^2 th)), through the uncompensated lobe
 * toward wo, times Schlick's Fresnel at the half vector with r0 when r0 >=
 * 0; etap_radiance is the radiance factor of transmission. */
static double sun_through_single(d3 wo, d3 s, double th, double e, double a, double eta,
                                 double etap_radiance, double r0)
{
    d3 u = unit(fabs(s.x) < 0.9 ? mk(s.z, 0, -s.x) : mk(0, s.z, -s.y));
    d3 v = mk(s.y * u.z - s.z * u.y, s.z * u.x - s.x * u.z, s.x * u.y - s.y * u.x);
    const int nr = 200, np = 200;
    double sum = 0, ct_min = cos(th);
    for (int i = 0; i < nr; i++) {
        double ct = 1 - (1 - ct_min) * (i + 0.5) / nr, st = sqrt(1 - ct * ct);
        for (int j = 0; j < np; j++) {
            double p = 2 * PI * (j + 0.5) / np;
            d3 wi = add(scale(s, ct), add(scale(u, st * cos(p)), scale(v, st * sin(p))));
            double f = lobe(wo, wi, a, eta);
            if (r0 >= 0)
                f *= r0 + (1 - r0) * pow(1 - dot(wo, unit(add(wo, wi))), 5);
            sum += wi.z > 0 ? f : f * etap_radiance;
        }
    }
    double solid = 2 * PI * (1 - ct_min);
    double radiance = e / (PI * sin(th) * sin(th));
    return radiance * sum * solid / (nr * np);
}

/* The same through the compensated white lobe (F = 1 or the dielectric's). */
static double sun_through_lobe(d3 wo, d3 s, double th, double e, double a, double eta,
                               double etap_radiance)
{
    return sun_through_single(wo, s, th, e, a, eta, etap_radiance, -1) / albedo(wo, a, eta);
}

#define SPHERE_SCENE "{\"scene\": [{\"sky\": {\"color\": [1, 1, 1]}}, {\"sphere\": {\"center\": " \
    "[0, 0, 0], \"radius\": 1, \"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 0, " \
    "\"reflecting\": %d, \"refractive\": %d}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5, " \
    "\"roughness\": %g}}}], \"camera\": {\"position\": [0, 0, 4], \"lookat\": [0, 0, 0], " \
    "\"fov\": 30, \"gridresolution\": [32, 32]}}"

/* The mean over the pixels well inside the sphere's outline. */
static double sphere_mean(const zt_image *im)
{
    double sum = 0, r = 0.85 * im->width / 2 / tan(15 * PI / 180) / 4;
    int n = 0;
    for (int y = 0; y < im->height; y++)
        for (int x = 0; x < im->width; x++) {
            double dx = x + 0.5 - im->width / 2.0, dy = y + 0.5 - im->height / 2.0;
            if (dx * dx + dy * dy < r * r) {
                const float *p = im->pixels + 3 * (y * im->width + x);
                sum += (p[0] + p[1] + p[2]) / 3.0;
                n++;
            }
        }
    return sum / n;
}

static void test_furnace(void **state)
{
    (void)state;
    const double rough[] = {0.1, 0.3, 0.6, 1.0};
    for (int glass = 0; glass < 2; glass++)
        for (int i = 0; i < 4; i++) {
            char text[1024];
            snprintf(text, sizeof text, SPHERE_SCENE, !glass, glass, rough[i]);
            zt_scene *s = test_scene_text(text, "rough_furnace");
            /* Deep enough that light inside the glass sphere gets out. */
            zt_image *im = test_render_level(s, ZT_METHOD_PATH, -1, 64, 1024);
            double mean = sphere_mean(im);
            print_message("white furnace, rough %s sphere, roughness %.1f: %.4f\n",
                          glass ? "refractive" : "reflecting", rough[i], mean);
            assert_true(fabs(mean - 1) < 0.01);
            zt_image_release(im);
            zt_scene_release(s);
        }
}

/* "roughness": 0 is the smooth material: the same bits. */
static void test_roughness_zero(void **state)
{
    (void)state;
    char a[1024], b[1024];
    snprintf(a, sizeof a, SPHERE_SCENE, 0, 1, 0.0);
    snprintf(b, sizeof b, "%s", a);
    char *r = strstr(b, ", \"roughness\": 0");
    assert_non_null(r);
    memmove(r, r + strlen(", \"roughness\": 0"), strlen(r + strlen(", \"roughness\": 0")) + 1);
    zt_scene *sa = test_scene_text(a, "rough0"), *sb = test_scene_text(b, "smooth");
    zt_image *ia = test_render_level(sa, ZT_METHOD_PATH, -1, 16, 16);
    zt_image *ib = test_render_level(sb, ZT_METHOD_PATH, -1, 16, 16);
    test_assert_same_image(ia, ib, "roughness 0 against no roughness");
    zt_image_release(ia);
    zt_image_release(ib);
    zt_scene_release(sa);
    zt_scene_release(sb);
}

/* A camera with a narrow view at a point of the plane y = 0 from direction
 * wo (world), the sun of half-angle th around direction s; the material's
 * lobe (reflecting or refractive), roughness r.  Returns the image mean. */
static double sun_on_plane(zt_method method, d3 wo, d3 s, double th, int glass, double r)
{
    char text[1536];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, %.17g], \"irradiance\": "
             "[100, 100, 100], \"angle\": %.17g}}, {\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, "
             "\"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 0, \"reflecting\": %d, "
             "\"refractive\": %d}, \"color\": [1, 1, 1], \"refractiveindex\": 1.5, \"roughness\": "
             "%g}}}], \"camera\": {\"position\": [%.17g, %.17g, %.17g], \"lookat\": [0, 0, 0], "
             "\"fov\": 0.5, \"gridresolution\": [8, 8]}}",
             s.x, s.y, s.z, 2 * th * 180 / PI, !glass, glass, r, 3 * wo.x, 3 * wo.y, 3 * wo.z);
    zt_scene *sc = test_scene_text(text, "rough_sun");
    zt_image *im = test_render_level(sc, method, 1, 1, 256);
    double sum = 0;
    int n = 3 * im->width * im->height;
    for (int i = 0; i < n; i++)
        sum += im->pixels[i];
    zt_image_release(im);
    zt_scene_release(sc);
    return sum / n;
}

static const char *const method_name[] = {"path", "zone"};
static const zt_method methods[] = {ZT_METHOD_PATH, ZT_METHOD_ZONE};

/* Both renderers: the zone tracer's rough lobes weigh their directions
 * against light samples of the sun (phase_two/rough.c) as the path tracer
 * does. */
static void test_sun_rough_mirror(void **state)
{
    (void)state;
    for (int mi = 0; mi < 2; mi++) {
    /* Roughness 0.2 under a sun of 5 degrees: the lobe is narrower than
     * the disc, so both the lobe's and the sun's samples carry light. */
    const double cases[][2] = {{0.2, 5}, {0.5, 0.53}, {1.0, 0.53}};
    for (int i = 0; i < 3; i++) {
        double r = cases[i][0], th = cases[i][1] / 2 * PI / 180;
        d3 s = unit(mk(0.3, 0.8, 0.2)), wo = unit(mk(-0.3, 0.7, -0.1));
        double got = sun_on_plane(methods[mi], wo, s, th, 0, r);
        /* The plane's frame: z is the world's y. */
        double want = sun_through_lobe(mk(wo.x, wo.z, wo.y), mk(s.x, s.z, s.y), th, 100, r * r, 0, 1);
        print_message("%s: sun on a rough mirror, roughness %.1f, sun %.2f deg: %.5g, formula %.5g\n",
                      method_name[mi], r, cases[i][1], got, want);
        assert_true(fabs(got / want - 1) < 0.01);
    }
    }
}

static void test_sun_through_rough_glass(void **state)
{
    (void)state;
    for (int mi = 0; mi < 2; mi++) {
    /* The camera below the interface, in the lighter medium, the sun above
     * it: radiance leaving the denser side carries (1 / 1.5)^2. */
    const double rough[] = {0.3, 0.7};
    for (int i = 0; i < 2; i++) {
        double th = 0.53 / 2 * PI / 180;
        d3 s = unit(mk(0.2, 0.9, 0.1)), wo = unit(mk(0.1, -0.8, 0.3));
        double got = sun_on_plane(methods[mi], wo, s, th, 1, rough[i]);
        /* Frame: z is the world's -y (the camera's side). */
        double want = sun_through_lobe(mk(wo.x, wo.z, -wo.y), mk(s.x, s.z, -s.y), th, 100,
                                       rough[i] * rough[i], 1.5, 1 / 2.25);
        print_message("%s: sun through rough glass, roughness %.1f: %.5g, formula %.5g\n",
                      method_name[mi], rough[i], got, want);
        assert_true(fabs(got / want - 1) < 0.01);
    }
    }
}

/* A coloured rough metal under the sun: the metallic lobe's Fresnel is
 * Schlick's (F0 = R0 from the index, times the colour c), and the light
 * single scattering loses is put back with F0 = c R0 in each channel
 * (Turquin 2019): c F f cos (1 + c R0 (1 - E) / E), E the white lobe's
 * albedo at wo.  A white lobe's gain would give dark channels too much (at
 * roughness 0.8, blue 0.2 here about 30%). */
static void test_sun_coloured_metal(void **state)
{
    (void)state;
    const double color[3] = {0.9, 0.5, 0.2}, ior = 0.01, r = 0.8, th = 0.53 / 2 * PI / 180;
    const double r0 = (ior - 1) * (ior - 1) / ((ior + 1) * (ior + 1));
    d3 s = unit(mk(0.3, 0.8, 0.2)), wo = unit(mk(-0.3, 0.7, -0.1));
    /* The plane's frame: z is the world's y. */
    d3 sl = mk(s.x, s.z, s.y), wl = mk(wo.x, wo.z, wo.y);
    double a = r * r, e = albedo(wl, a, 0);
    double single = sun_through_single(wl, sl, th, 100, a, 0, 1, r0);
    char text[1536];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, %.17g], \"irradiance\": "
             "[100, 100, 100], \"angle\": 0.53}}, {\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, "
             "\"material\": {\"character\": {\"diffuse\": 0, \"metallic\": 1, \"reflecting\": 0, "
             "\"refractive\": 0}, \"color\": [%g, %g, %g], \"refractiveindex\": %g, \"roughness\": "
             "%g}}}], \"camera\": {\"position\": [%.17g, %.17g, %.17g], \"lookat\": [0, 0, 0], "
             "\"fov\": 0.5, \"gridresolution\": [8, 8]}}",
             s.x, s.y, s.z, color[0], color[1], color[2], ior, r, 3 * wo.x, 3 * wo.y, 3 * wo.z);
    zt_scene *sc = test_scene_text(text, "rough_metal_sun");
    for (int mi = 0; mi < 2; mi++) {
        zt_image *im = test_render_level(sc, methods[mi], 1, 1, 256);
        for (int c = 0; c < 3; c++) {
            double got = 0;
            for (int i = 0; i < im->width * im->height; i++)
                got += im->pixels[3 * i + c];
            got /= im->width * im->height;
            double want = color[c] * single * (1 + color[c] * r0 * (1 - e) / e);
            print_message("%s: sun on a rough metal of colour %.1f: %.5g, formula %.5g\n",
                          method_name[mi], color[c], got, want);
            assert_true(fabs(got / want - 1) < 0.01);
        }
        zt_image_release(im);
    }
    zt_scene_release(sc);
}

/* The zone tracer's white furnace: a rough mirror sphere under a white sky
 * sends it back whole at its first bounce (the lobe's lost energy put
 * back), read over the lobe's directions. */
static void test_zone_furnace(void **state)
{
    (void)state;
    const double rough[] = {0.1, 0.3, 0.6, 1.0};
    for (int i = 0; i < 4; i++) {
        char text[1024];
        snprintf(text, sizeof text, SPHERE_SCENE, 1, 0, rough[i]);
        zt_scene *s = test_scene_text(text, "rough_furnace");
        zt_image *im = test_render_level(s, ZT_METHOD_ZONE, 1, 1, 1);
        double mean = sphere_mean(im);
        print_message("zone: white furnace, rough reflecting sphere, roughness %.1f: %.4f\n",
                      rough[i], mean);
        assert_true(fabs(mean - 1) < 0.01);
        zt_image_release(im);
        zt_scene_release(s);
    }
}

/* A white diffuse sphere under a clear coat (specular 1) in a white
 * furnace: the coat reflects s E(cos_o) and the base keeps the rest, so
 * the sky comes back whole at the first bounce, in both renderers. */
static void test_coat_furnace(void **state)
{
    (void)state;
    const double rough[] = {0.0, 0.3, 1.0};
    for (int i = 0; i < 3; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "{\"scene\": [{\"sky\": {\"color\": [1, 1, 1]}}, {\"sphere\": {\"center\": "
                 "[0, 0, 0], \"radius\": 1, \"material\": {\"character\": {\"diffuse\": 1, "
                 "\"metallic\": 0, \"reflecting\": 0, \"refractive\": 0}, \"color\": [1, 1, 1], "
                 "\"specular\": 1, \"roughness\": %g}}}], \"camera\": {\"position\": [0, 0, 4], "
                 "\"lookat\": [0, 0, 0], \"fov\": 30, \"gridresolution\": [32, 32]}}",
                 rough[i]);
        zt_scene *s = test_scene_text(text, "coat_furnace");
        for (int mi = 0; mi < 2; mi++) {
            zt_image *im = test_render_level(s, methods[mi], 1, 1, 256);
            double mean = sphere_mean(im);
            print_message("%s: white furnace, coated white sphere, roughness %.1f: %.5f\n",
                          method_name[mi], rough[i], mean);
            assert_true(fabs(mean - 1) < 0.005);
            zt_image_release(im);
        }
        zt_scene_release(s);
    }
}

/* The same furnace on a mesh seen at 45 degrees: its pixels take the 8 x 8
 * detail samples, whose shares of the coat's level-0 light samples are
 * below one each, so a stratified few of them take them, weighted by
 * their inverse probability (rough.c).  A white coated plane under a white
 * sky returns the sky: with the weights left out the coat's share (about
 * 5%) would be missing. */
static void test_coat_furnace_detail(void **state)
{
    (void)state;
    const char *obj = test_write_file("coat_quad.obj", "v -50 0 -50\nv 50 0 -50\nv 50 0 50\n"
                                                       "v -50 0 50\nf 1 3 2\nf 1 4 3\n");
    char text[1024];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sky\": {\"color\": [1, 1, 1]}}, {\"mesh\": {\"file\": \"%s\", "
             "\"material\": {\"character\": {\"diffuse\": 1, \"metallic\": 0, \"reflecting\": 0, "
             "\"refractive\": 0}, \"color\": [1, 1, 1], \"specular\": 1, \"roughness\": 0.3}}}], "
             "\"camera\": {\"position\": [0, 5, 0], \"lookat\": [0, 0, 5], \"fov\": 20, "
             "\"gridresolution\": [16, 16]}}",
             obj);
    zt_scene *s = test_scene_text(text, "coat_furnace_detail");
    zt_image *im = test_render_level(s, ZT_METHOD_ZONE, 1, 1, 1);
    double sum = 0;
    for (int i = 0; i < 3 * im->width * im->height; i++)
        sum += im->pixels[i];
    double mean = sum / (3 * im->width * im->height);
    print_message("zone: white furnace, coated white mesh at 45 degrees: %.5f\n", mean);
    assert_true(fabs(mean - 1) < 0.005);
    zt_image_release(im);
    zt_scene_release(s);
}

/* A grey diffuse plane under a clear coat in the sun, seen from wo: the
 * base's c/pi (1 - E(cos_o)) E cos_s plus the coat's GGX reflection of the
 * sun's disc, E the coat's albedo at cos_o, both integrated here. */
static void test_sun_on_coat(void **state)
{
    (void)state;
    const double c = 0.5, r = 0.5, th = 0.53 / 2 * PI / 180, irr = 100;
    d3 s = unit(mk(0.3, 0.8, 0.2));
    /* Away from the highlight, and near it (the sun's mirror image). */
    const d3 views[2] = {unit(mk(-0.3, 0.7, -0.1)), unit(mk(-0.35, 0.75, -0.2))};
    for (int vi = 0; vi < 2; vi++) {
    d3 wo = views[vi];
    d3 sl = mk(s.x, s.z, s.y), wl = mk(wo.x, wo.z, wo.y);
    double a = r * r, e = albedo(wl, a, COAT);
    double want = c / PI * (1 - e) * irr * sl.z + sun_through_single(wl, sl, th, irr, a, COAT, 1, -1);
    char text[1536];
    snprintf(text, sizeof text,
             "{\"scene\": [{\"sun\": {\"direction\": [%.17g, %.17g, %.17g], \"irradiance\": "
             "[%g, %g, %g], \"angle\": 0.53}}, {\"plane\": {\"normal\": [0, 1, 0], \"offset\": 0, "
             "\"material\": {\"character\": {\"diffuse\": 1, \"metallic\": 0, \"reflecting\": 0, "
             "\"refractive\": 0}, \"color\": [%g, %g, %g], \"specular\": 1, \"roughness\": %g}}}], "
             "\"camera\": {\"position\": [%.17g, %.17g, %.17g], \"lookat\": [0, 0, 0], "
             "\"fov\": 0.5, \"gridresolution\": [8, 8]}}",
             s.x, s.y, s.z, irr, irr, irr, c, c, c, r, 3 * wo.x, 3 * wo.y, 3 * wo.z);
    zt_scene *sc = test_scene_text(text, "coat_sun");
    for (int mi = 0; mi < 2; mi++) {
        zt_image *im = test_render_level(sc, methods[mi], 1, 1, 256);
        double got = 0;
        for (int i = 0; i < im->width * im->height; i++)
            got += im->pixels[3 * i];
        got /= im->width * im->height;
        print_message("%s: sun on a coated grey plane: %.5g, formula %.5g (coat albedo %.4f)\n",
                      method_name[mi], got, want, e);
        assert_true(fabs(got / want - 1) < 0.01);
        zt_image_release(im);
    }
    zt_scene_release(sc);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_roughness_zero),
        cmocka_unit_test(test_sun_rough_mirror),
        cmocka_unit_test(test_sun_through_rough_glass),
        cmocka_unit_test(test_sun_coloured_metal),
        cmocka_unit_test(test_zone_furnace),
        cmocka_unit_test(test_coat_furnace),
        cmocka_unit_test(test_coat_furnace_detail),
        cmocka_unit_test(test_sun_on_coat),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
