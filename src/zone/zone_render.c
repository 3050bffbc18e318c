/* The zone tracer's driver: Phase One when the renderer is made, Phase Two
 * for every image. */
#include <stdlib.h>
#include <string.h>

#include "camera/camera.h"
#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "util/error.h"
#include "zone/zone_internal.h"

static zone_quality quality_for(const zt_scene *sc, int q)
{
    /* The scene's size sets the texel size; each quality step halves it
     * (in area) and doubles the gather directions. */
    double extent = 0;
    for (int i = 0; i < sc->part_count; i++) {
        const part *p = &sc->parts[i];
        for (int k = 0; k < 3 && p->shape == SHAPE_TRIANGLE; k++)
            extent = fmax(extent, v3_length(v3_sub(p->p[k], p->p[(k + 1) % 3])));
        if (p->shape == SHAPE_SPHERE)
            extent = fmax(extent, 2 * p->radius);
    }
    extent = fmax(extent, v3_length(v3_sub(v3_from(sc->camera.screen[1]), v3_from(sc->camera.screen[0]))));
    zone_quality z;
    z.gather = 32 << q;
    z.texel = extent / (12.0 * pow(sqrt(2.0), q));
    z.sides = 16 << (q / 2);
    z.aa = q < 2 ? 1 : 2;
    if (getenv("ZT_ZONE_GATHER"))
        z.gather = atoi(getenv("ZT_ZONE_GATHER"));
    if (getenv("ZT_ZONE_TEXEL"))
        z.texel = extent / atof(getenv("ZT_ZONE_TEXEL"));
    return z;
}

zt_status zone_prepare(zt_renderer *r, zt_render_stats *stats, zt_error *err)
{
    double t0 = render_clock();
    zone_forest *f = calloc(1, sizeof *f);
    if (!f)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    r->forest = (struct zone_forest *)f;
    f->q = quality_for(r->scene, r->options.quality);
    f->direct.scene = r->scene;
    f->direct.rs = &r->rs;
    f->direct.sides = f->q.sides;
    zt_status st = forest_build_tree(f, r, err);
    if (st == ZT_OK)
        st = forest_build_maps(f, r, err);
    f->phase_one_seconds = render_clock() - t0;
    if (stats) {
        stats->phase_one_seconds = f->phase_one_seconds;
        stats->zones = (uint64_t)f->zone_count;
        stats->zones_pruned = f->pruned;
        for (int i = 0; i < f->zone_count; i++)
            if (f->zones[i].level < 32)
                stats->zones_per_level[f->zones[i].level]++;
    }
    return st;
}

void zone_release(zt_renderer *r)
{
    zone_forest *f = (zone_forest *)r->forest;
    if (!f)
        return;
    forest_free(f);
    free(f);
    r->forest = NULL;
}

/* What a camera ray sees, as a number: the parts along its specular chain
 * (the transmitted branch through glass).  Sub-pixel samples with the same
 * signature see one smooth surface; differing ones mark an edge. */
static uint32_t ray_signature(const rscene *rs, vec3f o, vec3f d, int steps, uint64_t *rays,
                              int *first_part)
{
    uint32_t sig = 0x811c9dc5u;
    for (int k = 0; k <= steps; k++) {
        hit h = accel_intersect(rs, o, d);
        (*rays)++;
        if (k == 0)
            *first_part = h.part;
        sig = (sig ^ (uint32_t)(h.part + 1)) * 16777619u;
        if (h.part < 0)
            break;
        const rs_part *p = &rs->parts[h.part];
        const rs_object *m = &rs->objects[p->object];
        if (p->is_light || m->weight[LOBE_DIFFUSE] >= 1.0f)
            break;
        vec3f x = f3_madd(o, d, h.t);
        vec3f ng = shape_normal(p, x);
        vec3f n = f3_dot(ng, d) < 0.0f ? ng : f3_neg(ng);
        if (m->weight[LOBE_REFRACTIVE] > 0.0f) {
            /* Direction changes matter little for the signature: go on
             * straight through, off the far side of the surface. */
            o = ray_offset(x, f3_neg(n));
        } else {
            d = f3_sub(d, f3_scale(n, 2.0f * f3_dot(d, n)));
            o = ray_offset(x, n);
        }
    }
    return sig;
}

#define SHADE_FLAGS (ZR_EXACT_DIRECT | ZR_NO_EMISSION)
#define EDGE_GRID 16   /* sub-pixel grid for coverage at edges */
#define EDGE_SHADE 4   /* shaded samples per side of that grid */

/* One pixel: a g x g grid of shaded samples; where their signatures
 * differ, coverage is measured on a finer grid, and each surface seen is
 * shaded on a sparse subset of its samples and weighted by its coverage. */
/* Lights seen directly somewhere in the pixel, collected from samples. */
typedef struct seen_lights {
    int part[8];
    int count;
} seen_lights;

static void note_light(const rscene *rs, seen_lights *s, int part)
{
    if (part < 0 || !rs->parts[part].is_light)
        return;
    for (int i = 0; i < s->count; i++)
        if (s->part[i] == part)
            return;
    if (s->count < 8)
        s->part[s->count++] = part;
}

/* Level 0 of a pixel: the lights it sees, by their exact coverage. */
static vec3 pixel_emission(zone_trace *t, const cam *c, int px, int py, const seen_lights *s)
{
    const rscene *rs = &t->r->rs;
    vec3 corner[4];
    const float cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
    for (int i = 0; i < 4; i++) {
        vec3f o, d;
        cam_ray(c, (float)px + cx[i], (float)py + cy[i], &o, &d);
        corner[i] = v3(o.x, o.y, o.z);
    }
    vec3 eye = v3(c->viewpoint.x, c->viewpoint.y, c->viewpoint.z), out = v3(0, 0, 0);
    for (int i = 0; i < s->count; i++) {
        double cov = direct_pixel_coverage(&t->f->direct, s->part[i], eye, corner);
        vec3f e = rs->objects[rs->parts[s->part[i]].object].emission;
        out = v3_add(out, v3_scale(v3(e.x, e.y, e.z), cov));
    }
    return out;
}

static vec3 shade_pixel(zone_trace *t, const cam *c, int px, int py, int g, int lo, int hi,
                        const uint32_t corners[4], seen_lights *lights)
{
    const rscene *rs = &t->r->rs;
    vec3f org, dir;
    uint32_t first = corners[0];
    int fp;
    vec3 level0 = v3(0, 0, 0);
    /* An edge that crosses the pixel separates some of its corners or
     * inner samples from the others. */
    int edge = corners[1] != first || corners[2] != first || corners[3] != first;
    vec3 acc = v3(0, 0, 0);
    for (int sy = 0; sy < g; sy++)
        for (int sx = 0; sx < g; sx++) {
            cam_ray(c, (float)px + (sx + 0.5f) / g, (float)py + (sy + 0.5f) / g, &org, &dir);
            if (ray_signature(rs, org, dir, hi, &t->rays, &fp) != first)
                edge = 1;
            note_light(rs, lights, fp);
            acc = v3_add(acc, zone_radiance(t, org, dir, lo, hi, SHADE_FLAGS, NULL, 0));
        }
    if (!edge) {
        if (lo == 0 && lights->count)
            level0 = pixel_emission(t, c, px, py, lights);
        return v3_add(level0, v3_scale(acc, 1.0 / (g * g)));
    }

    uint32_t sigs[EDGE_GRID * EDGE_GRID];
    uint32_t group_sig[EDGE_GRID * EDGE_GRID];
    int group_count[EDGE_GRID * EDGE_GRID], group_shaded[EDGE_GRID * EDGE_GRID];
    vec3 group_sum[EDGE_GRID * EDGE_GRID];
    int groups = 0;
    for (int i = 0; i < EDGE_GRID * EDGE_GRID; i++) {
        int sx = i % EDGE_GRID, sy = i / EDGE_GRID;
        cam_ray(c, (float)px + (sx + 0.5f) / EDGE_GRID, (float)py + (sy + 0.5f) / EDGE_GRID, &org, &dir);
        sigs[i] = ray_signature(rs, org, dir, hi, &t->rays, &fp);
        note_light(rs, lights, fp);
        int k = 0;
        while (k < groups && group_sig[k] != sigs[i])
            k++;
        if (k == groups) {
            group_sig[k] = sigs[i];
            group_count[k] = 0;
            group_shaded[k] = 0;
            group_sum[k] = v3(0, 0, 0);
            groups++;
        }
        group_count[k]++;
        const int step = EDGE_GRID / EDGE_SHADE;
        int on_subset = (sx % step == step / 2) && (sy % step == step / 2);
        if (on_subset) {
            group_sum[k] = v3_add(group_sum[k], zone_radiance(t, org, dir, lo, hi, SHADE_FLAGS, NULL, 0));
            group_shaded[k]++;
        }
    }
    /* Surfaces too small to meet the subset: shade their first sample. */
    for (int k = 0; k < groups; k++) {
        if (group_shaded[k])
            continue;
        for (int i = 0; i < EDGE_GRID * EDGE_GRID; i++)
            if (sigs[i] == group_sig[k]) {
                int sx = i % EDGE_GRID, sy = i / EDGE_GRID;
                cam_ray(c, (float)px + (sx + 0.5f) / EDGE_GRID,
                        (float)py + (sy + 0.5f) / EDGE_GRID, &org, &dir);
                group_sum[k] = zone_radiance(t, org, dir, lo, hi, SHADE_FLAGS, NULL, 0);
                group_shaded[k] = 1;
                break;
            }
    }
    vec3 out = lo == 0 && lights->count ? pixel_emission(t, c, px, py, lights) : v3(0, 0, 0);
    for (int k = 0; k < groups; k++)
        out = v3_add(out, v3_scale(group_sum[k],
                                   (double)group_count[k] / (group_shaded[k] * EDGE_GRID * EDGE_GRID)));
    return out;
}

zt_status zone_accumulate(zt_renderer *r, zt_image *sum, zt_render_stats *stats,
                          zt_error *err)
{
    zone_forest *f = (zone_forest *)r->forest;
    const zt_render_options *o = &r->options;
    int lo = o->level >= 0 ? o->level : 0;
    int hi = o->level >= 0 ? o->level : o->depth;
    cam c;
    cam_init(&c, &r->scene->camera);
    int threads = render_thread_count(o->threads);
    int g = f->q.aa;
    double t0 = render_clock();
    progress prog;
    progress_init(&prog, o, "zone", (double)sum->height);
    uint64_t rays = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : rays)
    for (int y = 0; y < sum->height; y++) {
        if (prog.cancelled)
            continue;
        zone_trace t = {f, r, 0, 0.0f};
        /* Signatures at the pixel corners of this row (top and bottom). */
        uint32_t *corner = malloc(2 * ((size_t)sum->width + 1) * sizeof *corner);
        int *corner_part = malloc(2 * ((size_t)sum->width + 1) * sizeof *corner_part);
        if (!corner || !corner_part) {
            free(corner);
            free(corner_part);
            prog.cancelled = 1;
            continue;
        }
        for (int k = 0; k < 2 * (sum->width + 1); k++) {
            vec3f org, dir;
            cam_ray(&c, (float)(k % (sum->width + 1)), (float)(y + k / (sum->width + 1)), &org, &dir);
            int fp;
            corner[k] = ray_signature(&r->rs, org, dir, hi, &t.rays, &fp);
            corner_part[k] = fp;
        }
        for (int x = 0; x < sum->width; x++) {
            uint32_t cs[4] = {corner[x], corner[x + 1], corner[sum->width + 1 + x],
                              corner[sum->width + 2 + x]};
            seen_lights lights = {{0}, 0};
            int w1 = sum->width + 1;
            note_light(&r->rs, &lights, corner_part[x]);
            note_light(&r->rs, &lights, corner_part[x + 1]);
            note_light(&r->rs, &lights, corner_part[w1 + x]);
            note_light(&r->rs, &lights, corner_part[w1 + x + 1]);
            vec3 v = shade_pixel(&t, &c, x, y, g, lo, hi, cs, &lights);
            float *px = zt_image_pixel(sum, x, y);
            px[0] += (float)v.x;
            px[1] += (float)v.y;
            px[2] += (float)v.z;
        }
        free(corner);
        free(corner_part);
        rays += t.rays;
        progress_add(&prog, 1.0);
    }
    stats->threads = threads;
    stats->rays = rays + f->rays;
    stats->samples = (uint64_t)sum->width * sum->height * (uint64_t)(g * g);
    stats->phase_one_seconds = f->phase_one_seconds;
    stats->phase_two_seconds = render_clock() - t0;
    stats->zones = (uint64_t)f->zone_count;
    stats->zones_pruned = f->pruned;
    memset(stats->zones_per_level, 0, sizeof stats->zones_per_level);
    for (int i = 0; i < f->zone_count; i++)
        if (f->zones[i].level < 32)
            stats->zones_per_level[f->zones[i].level]++;
    if (prog.cancelled)
        return zt_fail(err, ZT_ERR_CANCELLED, "render cancelled");
    return ZT_OK;
}
