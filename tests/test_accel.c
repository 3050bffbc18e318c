/* Every acceleration backend against the brute-force oracle: the project's
 * scenes, random soups of triangles, spheres and planes (culled or not, in
 * the foreground and the background) and trees with awkward shapes.  The
 * BVH must agree bit for bit; Embree to 1e-4 in t, with rare ties (two parts
 * at the same distance, as on a shared edge) allowed to go either way. */
#include "test_support.h"

#include <dirent.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/accel_internal.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "geom/transmittance.h"
#include "material/bsdf.h"
#include "render/prim.h"
#include "render/render_scene.h"
#include "scene/scene.h"

static const struct {
    accel_kind kind;
    const char *name;
} BACKENDS[] = {{ACCEL_BRUTE, "brute"}, {ACCEL_EMBREE, "embree"}, {ACCEL_BVH, "bvh"}};
enum { BACKEND_COUNT = sizeof BACKENDS / sizeof BACKENDS[0] };

/* ---- random numbers and rays ---- */

static float rnd(uint32_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return (float)(*s >> 8) * (1.0f / 16777216.0f);
}

static float rnd_in(uint32_t *s, float lo, float hi) { return lo + (hi - lo) * rnd(s); }

/* Uniform directions, with some along the axes or in the axis planes:
 * zero components are the slab test's hard case. */
static vec3f rnd_dir(uint32_t *s)
{
    float kind = rnd(s);
    if (kind < 0.05f) {
        float c[3] = {0, 0, 0};
        c[(int)(rnd(s) * 3) % 3] = rnd(s) < 0.5f ? -1.0f : 1.0f;
        return f3(c[0], c[1], c[2]);
    }
    for (;;) {
        vec3f v = f3(rnd_in(s, -1, 1), rnd_in(s, -1, 1), rnd_in(s, -1, 1));
        if (kind < 0.1f)
            v.y = 0.0f;
        float l = f3_dot(v, v);
        if (l > 1e-4f && l <= 1.0f)
            return f3_scale(v, 1.0f / sqrtf(l));
    }
}

typedef struct test_ray {
    vec3f o, d;
} test_ray;

typedef struct bounds {
    vec3f lo, hi;
} bounds;

static bounds scene_bounds(const rscene *rs)
{
    bounds b = {f3_splat(FLT_MAX), f3_splat(-FLT_MAX)};
    for (int i = 0; i < rs->prim_count; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, i, &tmp);
        if (p->shape == SHAPE_PLANE)
            continue;
        float r = p->shape == SHAPE_SPHERE ? p->radius : 0.0f;
        vec3f pts[3] = {p->p0, f3_add(p->p0, p->e1), f3_add(p->p0, p->e2)};
        for (int k = 0; k < 3; k++) {
            b.lo = f3(fminf(b.lo.x, pts[k].x - r), fminf(b.lo.y, pts[k].y - r),
                      fminf(b.lo.z, pts[k].z - r));
            b.hi = f3(fmaxf(b.hi.x, pts[k].x + r), fmaxf(b.hi.y, pts[k].y + r),
                      fmaxf(b.hi.z, pts[k].z + r));
        }
    }
    if (b.lo.x > b.hi.x) {
        b.lo = f3_splat(-10);
        b.hi = f3_splat(10);
    }
    /* a margin, so some rays start outside everything */
    vec3f m = f3_scale(f3_sub(b.hi, b.lo), 0.2f);
    b.lo = f3_sub(b.lo, m);
    b.hi = f3_add(b.hi, m);
    return b;
}

static vec3f rnd_point(uint32_t *s, const bounds *b)
{
    return f3(rnd_in(s, b->lo.x, b->hi.x), rnd_in(s, b->lo.y, b->hi.y),
              rnd_in(s, b->lo.z, b->hi.z));
}

static float camera_point(const zt_camera *c, float u, float v, int k)
{
    double p = c->screen[0][k] + u * (c->screen[1][k] - c->screen[0][k]) +
               v * (c->screen[2][k] - c->screen[0][k]);
    return (float)p;
}

/* A path tracer's rays: a third from the camera (when there is one), a
 * third from random points, a third leaving earlier rays' hits in random
 * directions, from just off the surface on the side they leave by. */
static void make_rays(const rscene *oracle, const zt_scene *scene, test_ray *out,
                      int n, uint32_t seed)
{
    bounds b = scene_bounds(oracle);
    zt_camera cam = zt_scene_get_camera(scene);
    for (int i = 0; i < n; i++) {
        test_ray *r = &out[i];
        int kind = i % 3;
        if (kind == 0 && scene->has_camera) {
            float u = rnd(&seed), v = rnd(&seed);
            r->o = f3(camera_point(&cam, u, v, 0), camera_point(&cam, u, v, 1),
                      camera_point(&cam, u, v, 2));
            vec3f eye = f3((float)cam.viewpoint[0], (float)cam.viewpoint[1],
                           (float)cam.viewpoint[2]);
            r->d = f3_normalize(f3_sub(r->o, eye));
            continue;
        }
        if (kind == 2 && i > 0) {
            const test_ray *prev = &out[i - 1 - (int)(rnd(&seed) * (i < 30 ? i : 30))];
            hit h = accel_intersect(oracle, prev->o, prev->d);
            if (h.part >= 0) {
                rs_part tmp;
                const rs_part *p = rs_prim(oracle, h.part, &tmp);
                vec3f x = f3_madd(prev->o, prev->d, h.t);
                vec3f n = shape_normal(p, x);
                r->d = rnd_dir(&seed);
                r->o = ray_offset(x, f3_dot(r->d, n) >= 0.0f ? n : f3_neg(n));
                continue;
            }
        }
        r->o = rnd_point(&seed, &b);
        r->d = rnd_dir(&seed);
    }
}

/* Rays aimed at the vertices and edges of random triangles, where the
 * inclusive edge test meets the rounding of the box test. */
static void aim_rays(const rscene *oracle, const zt_scene *scene, test_ray *out,
                     int n, uint32_t seed)
{
    bounds b = scene_bounds(oracle);
    int tris = 0;
    for (int i = 0; i < oracle->part_count; i++)
        tris += oracle->parts[i].shape == SHAPE_TRIANGLE;
    assert_true(tris > 0);
    for (int i = 0; i < n; i++) {
        int pick = (int)(rnd(&seed) * (float)tris), k = -1;
        while (pick >= 0)
            pick -= oracle->parts[++k].shape == SHAPE_TRIANGLE;
        const rs_part *p = &oracle->parts[k];
        float w = rnd(&seed);
        const float uv[][2] = {{0, 0}, {1, 0}, {0, 1}, {w, 0}, {0, w}, {1 - w, w}, {0.5f, 0.5f}};
        const float *c = uv[(int)(rnd(&seed) * 7) % 7];
        vec3f target = f3_add(p->p0, f3_add(f3_scale(p->e1, c[0]), f3_scale(p->e2, c[1])));
        out[i].o = rnd_point(&seed, &b);
        out[i].d = f3_normalize(f3_sub(target, out[i].o));
    }
    (void)scene;
}

/* ---- comparison with the oracle ---- */

typedef struct checker {
    const char *scene, *backend;
    int exact;   /* bit for bit (BVH) or to 1e-4 with ties (Embree) */
    int rays, ties, hits;
} checker;

static void report(const checker *c, const test_ray *r, const char *what)
{
    fprintf(stderr, "%s, %s: %s for ray o (%.9g %.9g %.9g) d (%.9g %.9g %.9g)\n",
            c->scene, c->backend, what, r->o.x, r->o.y, r->o.z, r->d.x, r->d.y,
            r->d.z);
}

/* 1e-4 relative; for hits very near the origin, relative to the origin's
 * own precision (a few units in the last place of its coordinates). */
static int close_t(float a, float b, vec3f o)
{
    float scale = fmaxf(fabsf(a), 0.1f * fmaxf(fabsf(o.x), fmaxf(fabsf(o.y), fabsf(o.z))));
    return fabsf(a - b) <= 1e-4f * scale;
}

/* Parts and mesh triangles alike. */
static int prim_background(const rscene *rs, int prim)
{
    rs_part tmp;
    return rs_prim(rs, prim, &tmp)->background;
}

static void check_nearest(checker *c, const rscene *oracle, const rscene *rs,
                          const test_ray *r)
{
    hit want = accel_intersect(oracle, r->o, r->d);
    hit got = accel_intersect(rs, r->o, r->d);
    c->rays++;
    c->hits += want.part >= 0;
    if (want.part == got.part && (want.part < 0 || (c->exact ? want.t == got.t
                                                             : close_t(want.t, got.t, r->o))))
        return;
    /* Two parts of the same layer at the same distance: either is right. */
    if (!c->exact && want.part >= 0 && got.part >= 0 && close_t(want.t, got.t, r->o) &&
        prim_background(oracle, want.part) == prim_background(oracle, got.part)) {
        c->ties++;
        return;
    }
    char what[160];
    snprintf(what, sizeof what, "nearest part %d t %.9g, oracle part %d t %.9g",
             got.part, got.t, want.part, want.t);
    report(c, r, what);
    fail();
}

/* Parts and mesh triangles alike. */
static void check_occluded(checker *c, const rscene *oracle, const rscene *rs,
                           const test_ray *r, float dist, int bg)
{
    int want = accel_occluded(oracle, r->o, r->d, dist, bg);
    int got = accel_occluded(rs, r->o, r->d, dist, bg);
    if (want != got) {
        char what[120];
        snprintf(what, sizeof what, "occluded %d, oracle %d (distance %.9g, %s target)",
                 got, want, dist, bg ? "background" : "foreground");
        report(c, r, what);
        fail();
    }
}

typedef void (*ray_maker)(const rscene *, const zt_scene *, test_ray *, int, uint32_t);

/* Nearest hits, and visibility of random distances along the ray for both
 * target layers and of the hit point itself (which must be visible).  Rays
 * aimed at edges are only for the backends that share the oracle's hit
 * tests: Embree's own edge rule may decide those either way. */
static void check_scene(const zt_scene *scene, const char *name, ray_maker make,
                        int nrays, uint32_t seed)
{
    zt_error err = {0};
    rscene oracle, rs;
    assert_int_equal(rscene_build(&oracle, scene, NULL, 0, ACCEL_BRUTE, &err), ZT_OK);
    test_ray *rays = test_malloc((size_t)nrays * sizeof *rays);
    make(&oracle, scene, rays, nrays, seed);
    bounds b = scene_bounds(&oracle);
    float reach = 2.0f * f3_length(f3_sub(b.hi, b.lo));
    for (int k = 0; k < BACKEND_COUNT; k++) {
        if (make == aim_rays && BACKENDS[k].kind == ACCEL_EMBREE)
            continue;
        if (rscene_build(&rs, scene, NULL, 0, BACKENDS[k].kind, &err) != ZT_OK)
            fail_msg("%s: building %s: %s", name, BACKENDS[k].name, err.message);
        checker c = {name, BACKENDS[k].name, BACKENDS[k].kind != ACCEL_EMBREE, 0, 0, 0};
        uint32_t s = seed ^ 0x9e3779b9u;
        for (int i = 0; i < nrays; i++) {
            const test_ray *r = &rays[i];
            check_nearest(&c, &oracle, &rs, r);
            hit h = accel_intersect(&oracle, r->o, r->d);
            float far = h.part >= 0 ? 2.0f * h.t : reach;
            for (int bg = 0; bg < 2; bg++)
                check_occluded(&c, &oracle, &rs, r, rnd_in(&s, 1e-3f, 1.0f) * far, bg);
            if (h.part >= 0) {
                int bg = prim_background(&oracle, h.part);
                assert_false(accel_occluded(&oracle, r->o, r->d, h.t, bg));
                /* At exactly the oracle's distance only exact backends
                 * agree: Embree's own triangle test rounds differently. */
                if (c.exact)
                    check_occluded(&c, &oracle, &rs, r, h.t, bg);
            }
        }
        if (c.ties > c.rays / 100) {
            fprintf(stderr, "%s, %s: %d ties in %d rays\n", name, c.backend, c.ties, c.rays);
            fail();
        }
        if (k == 0)
            print_message("%s: %d rays, %d hit\n", name, c.rays, c.hits);
        rscene_free(&rs);
    }
    test_free(rays);
    rscene_free(&oracle);
}

/* ---- scenes ---- */

static void add_object(zt_scene *s, int background, int culled)
{
    object o;
    memset(&o, 0, sizeof o);
    o.background = background;
    o.backculled = culled;
    o.mat = material_default();
    assert_true(scene_add_object(s, &o) >= 0);
}

static void add_part(zt_scene *s, part_shape shape, vec3 a, vec3 b, vec3 c,
                     double radius)
{
    part p;
    memset(&p, 0, sizeof p);
    p.shape = shape;
    p.p[0] = a;
    p.p[1] = b;
    p.p[2] = c;
    p.radius = radius;
    if (shape == SHAPE_PLANE) {
        p.normal = v3_normalize(v3_length(b) > 0.1 ? b : v3(0, 1, 0));
        p.offset = v3_dot(p.normal, a);
    }
    assert_true(scene_add_part(s, &p) >= 0);
}

static vec3 rnd_v3(uint32_t *s, double lo, double hi)
{
    return v3(rnd_in(s, (float)lo, (float)hi), rnd_in(s, (float)lo, (float)hi),
              rnd_in(s, (float)lo, (float)hi));
}

/* Triangles, spheres and a few planes in a cube of side 20, in four
 * objects each: every combination of culled and background. */
static zt_scene *soup(int triangles, int spheres, int planes, uint32_t seed)
{
    zt_scene *s = scene_create();
    assert_non_null(s);
    for (int kind = 0; kind < 4; kind++) {
        add_object(s, kind & 1, kind >> 1);
        for (int i = kind; i < triangles; i += 4) {
            vec3 a = rnd_v3(&seed, -10, 10);
            double size = rnd_in(&seed, 0.2f, 3.0f);
            add_part(s, SHAPE_TRIANGLE, a, v3_add(a, rnd_v3(&seed, -size, size)),
                     v3_add(a, rnd_v3(&seed, -size, size)), 0);
        }
        add_object(s, kind & 1, kind >> 1);
        for (int i = kind; i < spheres; i += 4)
            add_part(s, SHAPE_SPHERE, rnd_v3(&seed, -10, 10), v3(0, 0, 0), v3(0, 0, 0),
                     rnd_in(&seed, 0.1f, 2.0f));
        add_object(s, kind & 1, kind >> 1);
        for (int i = kind; i < planes; i += 4)
            add_part(s, SHAPE_PLANE, rnd_v3(&seed, -12, 12), rnd_v3(&seed, -1, 1),
                     v3(0, 0, 0), 0);
    }
    return s;
}

static void test_project_scenes(void **state)
{
    (void)state;
    DIR *dir = opendir(ZT_SOURCE_DIR "/scenes");
    assert_non_null(dir);
    int count = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len < 6 || strcmp(e->d_name + len - 5, ".json") != 0)
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/scenes/%s", ZT_SOURCE_DIR, e->d_name);
        zt_scene *scene = NULL;
        zt_error err = {0};
        if (zt_scene_load_file(path, &scene, &err) != ZT_OK) {
            /* The model scenes need Debian's assimp-testmodels. */
            if (err.status == ZT_ERR_READ && strstr(err.message, "/usr/share/assimp")) {
                print_message("%s: skipped (%s)\n", e->d_name, err.message);
                continue;
            }
            fail_msg("%s", err.message);
        }
        zt_scene_info info;
        zt_scene_get_info(scene, &info);
        if (info.light_parts + info.thing_parts > 20000) {
            /* The brute-force oracle would take minutes; meshes are
             * checked at scale by the soups and by bench_accel. */
            print_message("%s: skipped (%d primitives)\n", e->d_name,
                          info.light_parts + info.thing_parts);
            zt_scene_release(scene);
            continue;
        }
        check_scene(scene, e->d_name, make_rays, 6000, 1234u + (uint32_t)count);
        zt_scene_release(scene);
        count++;
    }
    closedir(dir);
    assert_true(count >= 3);
}

static void test_random_soup(void **state)
{
    (void)state;
    zt_scene *s = soup(3000, 80, 8, 99);
    check_scene(s, "soup", make_rays, 6000, 5);
    zt_scene_release(s);
}

static void test_large_soup(void **state)
{
    (void)state;
    zt_scene *s = soup(20000, 400, 4, 7);
    check_scene(s, "large soup", make_rays, 1200, 11);
    zt_scene_release(s);
}

/* An axis-aligned box of 12 triangles facing out. */
static void add_box(zt_scene *s, vec3 lo, vec3 hi)
{
    static const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                    {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    vec3 c[8];
    for (int i = 0; i < 8; i++)
        c[i] = v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    for (int f = 0; f < 6; f++) {
        const int *q = quads[f];
        add_part(s, SHAPE_TRIANGLE, c[q[0]], c[q[1]], c[q[2]], 0);
        add_part(s, SHAPE_TRIANGLE, c[q[0]], c[q[2]], c[q[3]], 0);
    }
}

/* Flat, axis-aligned bounds and shared edges: the Cornell box, and boxes
 * from a hundredth of a unit to hundreds, near the origin and far off. */
static void test_edges_and_vertices(void **state)
{
    (void)state;
    zt_scene *s = NULL;
    zt_error err = {0};
    if (zt_scene_load_file(ZT_SOURCE_DIR "/scenes/cornell.json", &s, &err) != ZT_OK)
        fail_msg("%s", err.message);
    check_scene(s, "cornell, aimed", aim_rays, 6000, 21);
    zt_scene_release(s);

    s = scene_create();
    uint32_t seed = 31;
    for (int i = 0; i < 60; i++) {
        add_object(s, i % 3 == 0, i % 2);
        double size = pow(10.0, rnd_in(&seed, -2, 2.5f));
        vec3 lo = v3_scale(rnd_v3(&seed, 0, 1), i < 30 ? 1.0 : 500.0);
        add_box(s, lo, v3_add(lo, v3_scale(rnd_v3(&seed, 0.3, 1), size)));
    }
    check_scene(s, "boxes, aimed", aim_rays, 6000, 22);
    check_scene(s, "boxes", make_rays, 3000, 23);
    zt_scene_release(s);
}

/* Inputs that strain a tree builder: many parts with the same bounds,
 * sizes falling off geometrically (SAH peels one part per level), a single
 * part, planes only and nothing at all. */
static void test_awkward_trees(void **state)
{
    (void)state;
    zt_scene *s = scene_create();
    add_object(s, 0, 0);
    for (int i = 0; i < 200; i++)
        add_part(s, SHAPE_TRIANGLE, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), 0);
    add_object(s, 0, 1);
    for (int i = 0; i < 120; i++) {
        double x = 5.0 * pow(0.5, i);
        add_part(s, SHAPE_SPHERE, v3(x, -x, x), v3(0, 0, 0), v3(0, 0, 0), 0.3 * x);
    }
    check_scene(s, "stacked and geometric", make_rays, 3000, 3);
    zt_scene_release(s);

    s = scene_create();
    add_object(s, 1, 1);
    add_part(s, SHAPE_SPHERE, v3(1, 2, 3), v3(0, 0, 0), v3(0, 0, 0), 2);
    check_scene(s, "one sphere", make_rays, 1000, 4);
    zt_scene_release(s);

    s = scene_create();
    add_object(s, 0, 1);
    add_part(s, SHAPE_PLANE, v3(0, -1, 0), v3(0, 1, 0), v3(0, 0, 0), 0);
    check_scene(s, "one plane", make_rays, 500, 5);
    zt_scene_release(s);

    s = scene_create();
    check_scene(s, "empty", make_rays, 200, 6);
    zt_scene_release(s);
}

/* A background part nearer than a foreground one is not the hit, and does
 * not hide it; a background target is hidden by foreground beyond it. */
static void test_background_rule(void **state)
{
    (void)state;
    zt_scene *s = scene_create();
    add_object(s, 1, 0); /* background: triangle at z = 0, sphere at z = 2 */
    add_part(s, SHAPE_TRIANGLE, v3(-5, -5, 0), v3(5, -5, 0), v3(0, 5, 0), 0);
    add_part(s, SHAPE_SPHERE, v3(1, 0, 2), v3(0, 0, 0), v3(0, 0, 0), 0.5);
    add_object(s, 0, 1); /* foreground: triangle at z = -1, facing +z */
    add_part(s, SHAPE_TRIANGLE, v3(-5, -5, -1), v3(5, -5, -1), v3(0, 5, -1), 0);
    zt_error err = {0};
    for (int k = 0; k < BACKEND_COUNT; k++) {
        rscene rs;
        assert_int_equal(rscene_build(&rs, s, NULL, 0, BACKENDS[k].kind, &err), ZT_OK);
        vec3f o = f3(0, 0, 5), down = f3(0, 0, -1);
        hit h = accel_intersect(&rs, o, down);
        assert_int_equal(h.part, 2);
        assert_true(close_t(6.0f, h.t, o));
        h = accel_intersect(&rs, f3(1, 0, 5), down); /* past the sphere too */
        assert_int_equal(h.part, 2);
        h = accel_intersect(&rs, o, f3(0, 0, 1)); /* nothing foreground: sky */
        assert_int_equal(h.part, -1);
        h = accel_intersect(&rs, f3(0, 0, -0.5f), f3(0, 0, 1)); /* background only */
        assert_int_equal(h.part, 0);
        assert_true(close_t(0.5f, h.t, o));
        /* the foreground target is seen past the background triangle */
        if (BACKENDS[k].kind != ACCEL_EMBREE) /* see check_scene */
            assert_false(accel_occluded(&rs, o, down, 6.0f, 0));
        assert_false(accel_occluded(&rs, o, down, 5.9f, 0));
        assert_true(accel_occluded(&rs, o, down, 6.5f, 0));
        /* the background triangle is hidden by the foreground one behind it */
        assert_true(accel_occluded(&rs, o, down, 5.0f, 1));
        assert_false(accel_occluded(&rs, f3(0, 0, -0.5f), f3(0, 0, 1), 0.4999f, 1));
        assert_true(accel_occluded(&rs, f3(1, 0, 5), down, 2.5f, 1)); /* sphere */
        rscene_free(&rs);
    }
    zt_scene_release(s);
}

/* ---- rays from one point, traced together ---- */

/* accel_transmittance_panes by the rule written out in full (accel.h): up
 * to 32 panes crossed on the way, and at the end accel_occluded's answer
 * for what remains; the renderer's version reads that answer off the
 * nearest hit instead. */
static vec3f transmittance_by_rule(const rscene *rs, vec3f o, vec3f d, float dist, int bg)
{
    vec3f tr = f3_splat(1.0f);
    for (int k = 0; k < 32; k++) {
        hit h = accel_intersect(rs, o, d);
        if (h.part < 0 || !(h.t < dist))
            break;
        rs_part tmp;
        const rs_part *p = rs_prim(rs, h.part, &tmp);
        const rs_object *m = &rs->objects[p->object];
        if (!rs_passes(m) || p->is_light)
            break;
        vec3f x = shape_hit_point(p, o, d, h.t);
        vec3f ng = shape_normal(p, x);
        float c = f3_dot(ng, d);
        tr = f3_mul(tr, bsdf_pass_through(m, rs_coverage(rs, h.part, p, m, x), fabsf(c)));
        o = ray_offset(x, c > 0.0f ? ng : f3_neg(ng));
        dist -= h.t;
    }
    return accel_occluded(rs, o, d, dist, bg) ? f3_splat(0.0f) : tr;
}

/* The soup with the triangles of two of its four objects thin panes
 * (foreground and background, not culled). */
static zt_scene *soup_with_panes(uint32_t seed)
{
    zt_scene *s = soup(2000, 60, 4, seed);
    /* Objects 0, 3, 6, 9 hold the triangles of each layer and culling. */
    for (int k = 0; k < 2; k++) {
        material *m = &s->objects[3 * k].mat;
        m->thin = 1;
        m->weight[LOBE_DIFFUSE] = 0.0;
        m->weight[LOBE_REFRACTIVE] = 1.0;
        m->ior = 1.5;
        m->tint = v3(0.9, 0.8, 0.7);
    }
    return s;
}

enum { POINTS = 150, RAYS = 37 };

/* One backend's answers for rays from POINTS points of b, RAYS each,
 * against its single rays and the oracle. */
static void check_point_rays(const rscene *oracle, const rscene *rs, const bounds *b,
                             checker c, uint32_t seed)
{
    int differ = 0;
    for (int i = 0; i < POINTS; i++) {
        vec3f o = rnd_point(&seed, b), d[RAYS];
        float dist[RAYS];
        /* Half the points send a bundle (rays towards a small
         * patch, as at a light), half rays every way. */
        vec3f aim = rnd_dir(&seed);
        for (int j = 0; j < RAYS; j++) {
            d[j] = i % 2 ? rnd_dir(&seed)
                         : f3_normalize(f3_add(aim, f3_scale(rnd_dir(&seed), 0.05f)));
            dist[j] = rnd_in(&seed, 0.5f, 30.0f);
        }
        hit h[RAYS];
        accel_intersect_n(rs, o, d, RAYS, h);
        for (int j = 0; j < RAYS; j++) {
            test_ray r = {o, d[j]};
            hit one = accel_intersect(rs, o, d[j]);
            c.rays++;
            if (one.part == h[j].part && (one.part < 0 || one.t == h[j].t))
                continue;
            if (!c.exact && one.part >= 0 && h[j].part >= 0 && close_t(one.t, h[j].t, o)) {
                c.ties += one.part != h[j].part;
                continue;
            }
            report(&c, &r, "a packet's nearest hit is not the single ray's");
            fail();
        }
        for (int bg = 0; bg < 2; bg++) {
            unsigned char hidden[RAYS];
            vec3f tr[RAYS];
            int pane[RAYS];
            accel_occluded_n(rs, o, d, dist, RAYS, bg, hidden);
            accel_transmittance_panes_n(rs, o, d, dist, RAYS, bg, tr, pane);
            for (int j = 0; j < RAYS; j++) {
                int want = accel_occluded(oracle, o, d[j], dist[j], bg);
                vec3f one = accel_transmittance(rs, o, d[j], dist[j], bg);
                vec3f rule = transmittance_by_rule(oracle, o, d[j], dist[j], bg);
                /* Embree's packets may round a grazing ray the
                 * other way: a few in the thousands. */
                if (hidden[j] != want || tr[j].x != one.x || tr[j].y != one.y ||
                    tr[j].z != one.z) {
                    differ++;
                    if (c.exact) {
                        report(&c, &(test_ray){o, d[j]}, "a packet's answer differs");
                        fail();
                    }
                }
                if (c.exact && (fabsf(one.x - rule.x) > 1e-6f ||
                                fabsf(one.y - rule.y) > 1e-6f ||
                                fabsf(one.z - rule.z) > 1e-6f)) {
                    report(&c, &(test_ray){o, d[j]}, "transmittance breaks the rule");
                    fail();
                }
            }
        }
    }
    print_message("%s, %s: %d rays, %d ties, %d packet answers apart\n", c.scene,
                  c.backend, c.rays, c.ties, differ);
    assert_true(differ <= c.rays / 500);
    assert_true(c.ties <= c.rays / 100);
}

/* accel_intersect_n, accel_occluded_n and accel_transmittance_panes_n give
 * each ray what the single-ray queries give it, on every backend: 37 rays
 * a point (packets of 16 and a remainder), spheres, culling, both layers,
 * planes and panes.  Embree's packets run their own triangle test: its
 * nearest hits agree to 1e-4 in t, with ties allowed as above.  Embree
 * runs at its native packet width and every narrower one (the widths other
 * machines take). */
static void test_rays_from_one_point(void **state)
{
    (void)state;
    for (int variant = 0; variant < 2; variant++) {
        zt_scene *s = variant ? soup_with_panes(17) : soup(3000, 80, 8, 41);
        zt_error err = {0};
        rscene oracle;
        assert_int_equal(rscene_build(&oracle, s, NULL, 0, ACCEL_BRUTE, &err), ZT_OK);
        assert_int_equal(oracle.pane_count > 0, variant);
        bounds b = scene_bounds(&oracle);
        for (int k = 0; k < BACKEND_COUNT; k++) {
            rscene rs;
            if (rscene_build(&rs, s, NULL, 0, BACKENDS[k].kind, &err) != ZT_OK)
                fail_msg("building %s: %s", BACKENDS[k].name, err.message);
            int embree = BACKENDS[k].kind == ACCEL_EMBREE, native = rs.accel->packet;
            for (int width = 16; width >= 4; width /= 2) {
                if (embree ? width > native : width != 16)
                    continue;
                if (embree)
                    rs.accel->packet = width;
                char name[32];
                snprintf(name, sizeof name, embree ? "%s x%d" : "%s", BACKENDS[k].name, width);
                checker c = {variant ? "panes" : "soup", name, !embree, 0, 0, 0};
                check_point_rays(&oracle, &rs, &b, c, 77u + (uint32_t)variant);
            }
            rscene_free(&rs);
        }
        rscene_free(&oracle);
        zt_scene_release(s);
    }
}

/* accel_nearest_all_sides (node life's probes): the nearest triangle or
 * sphere of either layer with culling off, against every part tested on
 * its own with its culling cleared; Embree answers it, the BVH and the
 * brute force say they cannot (node life then walks its own index). */
static void test_nearest_all_sides(void **state)
{
    (void)state;
    zt_scene *s = soup(1200, 60, 0, 23);
    zt_error err = {0};
    for (int k = 0; k < BACKEND_COUNT; k++) {
        rscene rs;
        if (rscene_build(&rs, s, NULL, 0, BACKENDS[k].kind, &err) != ZT_OK)
            fail_msg("building %s: %s", BACKENDS[k].name, err.message);
        hit h;
        vec3f d0 = f3(0.0f, 0.0f, 1.0f);
        int answers = accel_nearest_all_sides(&rs, f3(0.0f, 0.0f, 0.0f), d0, FLT_MAX, &h);
        assert_int_equal(answers, BACKENDS[k].kind == ACCEL_EMBREE);
        if (!answers) {
            rscene_free(&rs);
            continue;
        }
        bounds b = scene_bounds(&rs);
        uint32_t seed = 5;
        int rays = 0, hits = 0, backs = 0, ties = 0;
        for (int i = 0; i < 4000; i++) {
            vec3f o = rnd_point(&seed, &b), d = rnd_dir(&seed);
            float reach = i % 2 ? rnd_in(&seed, 1.0f, 20.0f) : FLT_MAX;
            hit want = {reach, -1};
            for (int prim = 0; prim < rs.prim_count; prim++) {
                rs_part tmp;
                rs_part open = *rs_prim(&rs, prim, &tmp);
                open.culled = 0;
                float t = shape_hit(&open, o, d, 0.0f, want.t);
                if (t > 0.0f && t < want.t)
                    want = (hit){t, prim};
            }
            assert_int_equal(accel_nearest_all_sides(&rs, o, d, reach, &h), 1);
            rays++;
            if (want.part < 0) {
                if (h.part >= 0)
                    ties++; /* (a grazing hit one test rounds in) */
                continue;
            }
            hits++;
            rs_part tmp;
            const rs_part *p = rs_prim(&rs, want.part, &tmp);
            backs += p->culled && f3_dot(shape_normal(p, f3_madd(o, d, want.t)), d) > 0.0f;
            if (h.part != want.part) {
                ties++;
                if (h.part >= 0)
                    assert_true(close_t(h.t, want.t, o));
            } else {
                assert_true(close_t(h.t, want.t, o));
            }
        }
        print_message("%s: %d rays, %d hits, %d on the back of a culled primitive, %d ties\n",
                      BACKENDS[k].name, rays, hits, backs, ties);
        /* Culled backs are met (else the query would be culling), and
         * Embree's own triangle test rounds a few grazing hits apart. */
        assert_true(backs > hits / 8);
        assert_true(ties <= rays / 200);
        rscene_free(&rs);
    }
    zt_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_background_rule),
        cmocka_unit_test(test_project_scenes),
        cmocka_unit_test(test_random_soup),
        cmocka_unit_test(test_large_soup),
        cmocka_unit_test(test_awkward_trees),
        cmocka_unit_test(test_edges_and_vertices),
        cmocka_unit_test(test_rays_from_one_point),
        cmocka_unit_test(test_nearest_all_sides),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
