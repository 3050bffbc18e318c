/* Gathers shared between neighbouring pixels: a screen-space irradiance
 * cache (after Ward, Rubinstein and Clear 1988).
 *
 * A camera sample on a mesh gathers its light of levels >= 2 over a few
 * dozen directions (gather.c).  Where that light comes from a small bright
 * patch (a room lit by the sun through a window), a few dozen directions
 * find the patch or miss it from pixel to pixel, and the image is speckled.
 * The light itself changes slowly there: over a distance d it changes by
 * about d / R, R the harmonic mean distance of the surfaces around.  So
 * before the pixels are shaded, each pixel's centre that sees a mesh's
 * diffuse surface gathers once (a record: the irradiance of every level the
 * image reads, the point, its normal and R), and a sample then blends the
 * records of its own and its eight neighbouring pixels that hold for it,
 * Ward's error eps = |x - x_i| / R_i + sqrt(1 - n . n_i) below CACHE_EPS,
 * each weighed by 1 - eps / CACHE_EPS.  On a smooth wall that is nine
 * pixels' directions for one pixel's rays; at a fold, a contact or an edge
 * (R small, normals apart) only the sample's own pixel's record holds, or
 * none, and the sample gathers for itself as before.  Samples of pixels
 * with more than 2 x 2 of them (a mesh's detail) always gather for
 * themselves.  The house's interior at the default quality: 29.3% -> 19.5%
 * per pixel against the path reference; the engine room 0.871% -> 0.859%
 * (BENCHMARKS.md).
 *
 * The records are built before any pixel is shaded, by both strategies
 * alike; split over processes, each builds those of its own rows and the
 * processes exchange them (a sample reads its neighbouring rows' too), so
 * the image stays the same bit for bit at any thread count, strategy and
 * process count. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "render/share.h"
#include "util/error.h"
#include "util/vec3_convert.h"
#include "zone/phase_two/phase_two.h"

/* Ward's eps below which a record holds.  On the engine room at 512 x 512
 * (one-sample pixels reading records) 0.1, 0.2 and 0.3 gave 0.872%, 0.866%
 * and 0.868% per pixel against the path reference. */
#define CACHE_EPS 0.2

/* The record at pixel (px, py), if its centre sees a mesh's diffuse
 * surface (else its R stays 0: no record). */
static void record_at(const p2_ctx *c, zone_trace *t, struct zone_gather_cache *gc, int px,
                     int py)
{
    const rscene *rs = &c->r->rs;
    size_t i = (size_t)py * (size_t)gc->width + (size_t)px;
    p2_sample s;
    memset(&s, 0, sizeof s);
    cam_ray(&c->c, (float)px + 0.5f, (float)py + 0.5f, &s.o, &s.d);
    hit h = accel_intersect(rs, s.o, s.d);
    t->rays++;
    if (h.part < 0 || !zone_gathers(rs, h.part))
        return;
    s.t = h.t;
    s.part = h.part;
    p2_surface sf;
    p2_surface_of(rs, &s, &sf);
    if (sf.m->weight[LOBE_DIFFUSE] <= 0.0f || sf.m->is_light)
        return;
    /* The directions the pixel's one sample would take. */
    t->gather = (zone_gather_slot){.pixel = (uint32_t)i, .count = 1, .samples = 1};
    double inv_dist = 0;
    for (int k = 0; k < gc->levels; k++) {
        double id;
        vec3 e = zone_gather_irradiance(t, sf.xf, sf.nf, sf.n, gc->first + k, &id);
        if (k == 0)
            inv_dist = id;
        float *out = gc->e + (i * (size_t)gc->levels + (size_t)k) * 3;
        out[0] = (float)e.x;
        out[1] = (float)e.y;
        out[2] = (float)e.z;
    }
    t->gather = (zone_gather_slot){0};
    gc->x[i] = sf.xf;
    gc->n[i] = sf.nf;
    /* Every ray escaping: R is unbounded, the light the same everywhere
     * but for what the surface itself hides. */
    gc->r[i] = inv_dist > 0 ? (float)(1.0 / inv_dist) : INFINITY;
}

zt_status p2_gather_cache_build(struct zone_gather_cache *gc, const p2_ctx *c, uint64_t *rays_out,
                                zt_error *err)
{
    memset(gc, 0, sizeof *gc);
    const zt_render_options *o = &c->r->options;
    const rscene *rs = &c->r->rs;
    /* Levels gathered: E_{l-1} for the image's levels l >= 2, on meshes. */
    int first = c->lo > 2 ? c->lo - 1 : 1, last = c->hi - 1;
    if (last < first || rs->prim_count <= rs->part_count)
        return ZT_OK;
    int w = c->c.width, h = c->c.height;
    size_t n = (size_t)w * (size_t)h;
    gc->width = w;
    gc->height = h;
    gc->first = first;
    gc->levels = last - first + 1;
    /* Zero where nothing is written: the processes' exchange joins the
     * bytes each wrote. */
    gc->x = calloc(n, sizeof *gc->x);
    gc->n = calloc(n, sizeof *gc->n);
    gc->r = calloc(n, sizeof *gc->r);
    gc->e = calloc(n * (size_t)gc->levels * 3, sizeof *gc->e);
    if (!gc->x || !gc->n || !gc->r || !gc->e) {
        p2_gather_cache_free(gc);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the pixels' gathers");
    }
    int threads = render_thread_count(o->threads);
    uint64_t rays = 0;
    volatile int failed = 0;
#pragma omp parallel num_threads(threads) reduction(+ : rays)
    {
        zone_trace t = {.f = c->f, .r = c->r};
        /* A record's levels gather along the same directions: the first
         * one's hits serve the rest (gather.c). */
        t.memo = malloc(sizeof *t.memo);
        if (!t.memo)
            failed = 1;
        else
            t.memo->pixel = UINT32_MAX;
        double spent = 0;
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < h; y++) {
            if (failed || !share_owns(o, y))
                continue;
            double t0 = render_clock();
            for (int x = 0; x < w; x++)
                record_at(c, &t, gc, x, y);
            spent += render_clock() - t0;
        }
        free(t.memo);
        rays += t.rays;
        if (c->split) {
#pragma omp atomic
            c->split->records += spent;
        }
    }
    *rays_out += rays;
    zt_status st = failed ? zt_fail(err, ZT_ERR_MEMORY, "out of memory for the pixels' gathers")
                          : ZT_OK;
    if (st == ZT_OK && share_ranks(o) > 1) {
        size_t levels = (size_t)gc->levels;
        st = share_merge(o, gc->x, n * sizeof *gc->x, err);
        if (st == ZT_OK)
            st = share_merge(o, gc->n, n * sizeof *gc->n, err);
        if (st == ZT_OK)
            st = share_merge(o, gc->r, n * sizeof *gc->r, err);
        if (st == ZT_OK)
            st = share_merge(o, gc->e, n * levels * 3 * sizeof *gc->e, err);
    }
    if (st != ZT_OK)
        p2_gather_cache_free(gc);
    return st;
}

void p2_gather_cache_free(struct zone_gather_cache *gc)
{
    free(gc->x);
    free(gc->n);
    free(gc->r);
    free(gc->e);
    memset(gc, 0, sizeof *gc);
}

int zone_gather_cache_read(const zone_trace *t, vec3f x, vec3f nf, int level, vec3 *e)
{
    const struct zone_gather_cache *gc = t->cache;
    if (!gc || !gc->r || !t->gather.count || level < gc->first ||
        level >= gc->first + gc->levels)
        return 0;
    /* A mesh detail pixel's 8 x 8 samples are there to find what lies
     * between pixel centres (a stack of fins' gaps): they gather for
     * themselves.  On the engine room letting them read the records too
     * took the error from 0.871% to 0.904% per pixel; keeping them apart,
     * 0.859%. */
    if (t->gather.count > 4)
        return 0;
    int w = gc->width, h = gc->height;
    int px = (int)(t->gather.pixel % (uint32_t)w), py = (int)(t->gather.pixel / (uint32_t)w);
    double sum[3] = {0, 0, 0}, wsum = 0;
    for (int y = py - 1; y <= py + 1; y++) {
        if (y < 0 || y >= h)
            continue;
        for (int xx = px - 1; xx <= px + 1; xx++) {
            if (xx < 0 || xx >= w)
                continue;
            size_t i = (size_t)y * (size_t)w + (size_t)xx;
            if (!(gc->r[i] > 0.0f)) /* no record */
                continue;
            double cosn = f3_dot(nf, gc->n[i]);
            if (cosn <= 0.0)
                continue;
            double eps = f3_length(f3_sub(x, gc->x[i])) / gc->r[i] + sqrt(fmax(0.0, 1.0 - cosn));
            if (eps >= CACHE_EPS)
                continue;
            double wt = 1.0 - eps / CACHE_EPS;
            const float *v = gc->e + (i * (size_t)gc->levels + (size_t)(level - gc->first)) * 3;
            sum[0] += wt * v[0];
            sum[1] += wt * v[1];
            sum[2] += wt * v[2];
            wsum += wt;
        }
    }
    if (wsum <= 0.0)
        return 0;
    *e = v3(sum[0] / wsum, sum[1] / wsum, sum[2] / wsum);
    return 1;
}
