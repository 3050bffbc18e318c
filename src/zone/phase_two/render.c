/* Phase Two, step three: the two strategies.
 *
 * Pixel by pixel: rows in parallel; each pixel builds its sample list, then
 * adds the terms whose source it sees (the terms of the surfaces its samples
 * hit, the root terms of the lights it sees, the sky's) in term order.
 *
 * Zone by zone: first the sample lists of the whole image (rows in
 * parallel), and for every surface the pixels that see it; then the terms one
 * after another, each added (pixels in parallel: a pixel belongs to one
 * thread at a time) to the pixels that see its source.
 *
 * Each pixel's value is summed in double precision by p2_apply in both, over
 * the same terms in the same order, then added to the float image once: the
 * two images are identical bit for bit, at any thread count.  Split over
 * processes, each renders its rows (render/share.h) and leaves the others
 * untouched. */
#include <stdlib.h>
#include <string.h>

#include "render/share.h"
#include "util/error.h"
#include "zone/phase_two/phase_two.h"

static void add_to_image(zt_image *sum, int x, int y, const double acc[3])
{
    float *px = zt_image_pixel(sum, x, y);
    px[0] += (float)acc[0];
    px[1] += (float)acc[1];
    px[2] += (float)acc[2];
}

/* A camera path's trace: the gather records, and the pixel's footprint
 * (the caustics' photons are read over it). */
static zone_trace p2_trace(const p2_ctx *c)
{
    return (zone_trace){.f = c->f, .r = c->r, .cache = c->cache, .eye = c->c.viewpoint,
                        .pixel_angle = c->pixel_angle};
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The terms pixel px needs, ascending, into *list (grown as needed).
 * Returns the count, or -1 when out of memory. */
static int pixel_terms(const p2_ctx *c, const p2_pixel *px, int **list, int *cap)
{
    const p2_terms *T = &c->terms;
    int surfaces = T->surfaces, n = 0;
    /* Distinct surfaces hit (`surfaces` stands for nothing hit), in
     * first-seen order; their term lists are disjoint. */
    int seen_local[P2_MAX_PIXEL_SAMPLES], nseen = 0;
    /* A fine grid over a dense mesh can shade more samples than that. */
    int *seen = px->n <= P2_MAX_PIXEL_SAMPLES ? seen_local : malloc((size_t)px->n * sizeof *seen);
    if (!seen)
        return -1;
    for (int i = 0; i < px->n; i++) {
        int q = px->s[i].surface < 0 ? surfaces : px->s[i].surface, dup = 0;
        for (int j = 0; j < nseen && !dup; j++)
            dup = seen[j] == q;
        if (!dup)
            seen[nseen++] = q;
    }
    int need = px->nlights;
    for (int j = 0; j < nseen; j++)
        need += T->part_first[seen[j] + 1] - T->part_first[seen[j]];
    if (need > *cap) {
        int nc = need + 64;
        int *nl = realloc(*list, (size_t)nc * sizeof *nl);
        if (!nl) {
            if (seen != seen_local)
                free(seen);
            return -1;
        }
        *list = nl;
        *cap = nc;
    }
    for (int j = 0; j < nseen; j++)
        for (int k = T->part_first[seen[j]]; k < T->part_first[seen[j] + 1]; k++)
            (*list)[n++] = T->part_terms[k];
    if (seen != seen_local)
        free(seen);
    for (int i = 0; i < px->nlights; i++)
        if (T->root_term[px->lights[i]] >= 0)
            (*list)[n++] = T->root_term[px->lights[i]];
    if (n > 1)
        qsort(*list, (size_t)n, sizeof **list, cmp_int);
    return n;
}

/* A thread's time split, added to the context's once it is done. */
static void split_add(const p2_ctx *c, const p2_split *own)
{
    if (!c->split)
        return;
#pragma omp critical(p2_split)
    {
        c->split->lists += own->lists;
        c->split->records += own->records;
        for (int k = 0; k < ZT_PIXEL_KINDS; k++) {
            c->split->shade[k] += own->shade[k];
            c->split->pixels[k] += own->pixels[k];
            c->split->samples[k] += own->samples[k];
        }
    }
}

zt_status p2_render_pixels(const p2_ctx *c, zt_image *sum, uint64_t *rays_out, zt_error *err)
{
    const zt_render_options *o = &c->r->options;
    int threads = render_thread_count(o->threads);
    progress prog;
    progress_init(&prog, o, "zone", (double)share_owned(o, sum->height));
    uint64_t rays = 0;
    volatile int failed = 0; /* set by any thread that runs out of memory */
#pragma omp parallel num_threads(threads) reduction(+ : rays)
    {
        zone_trace t = p2_trace(c);
        /* The gathers' hits, kept from a pixel's one level to the next:
         * the same rays (gather.c). */
        t.memo = malloc(sizeof *t.memo);
        if (t.memo)
            t.memo->pixel = UINT32_MAX;
        p2_row row;
        memset(&row, 0, sizeof row);
        int *list = NULL, cap = 0;
        p2_split own = {0};
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < sum->height; y++) {
            if (prog.cancelled || failed || !share_owns(o, y))
                continue;
            double t0 = render_clock();
            if (!p2_row_build(c, y, &row, &t.rays)) {
                failed = 1;
                continue;
            }
            double t1 = render_clock();
            own.lists += t1 - t0;
            for (int x = 0; x < sum->width && !failed; x++) {
                p2_pixel px;
                p2_row_pixel(&row, x, y, &px);
                int n = pixel_terms(c, &px, &list, &cap);
                if (n < 0) {
                    failed = 1;
                    break;
                }
                double acc[3] = {0, 0, 0};
                for (int k = 0; k < n; k++)
                    p2_apply(c, &t, list[k], &px, acc);
                add_to_image(sum, x, y, acc);
                double t2 = render_clock();
                own.shade[px.kind] += t2 - t1;
                own.pixels[px.kind]++;
                own.samples[px.kind] += (uint64_t)px.n;
                t1 = t2;
            }
            t.rays += direct_rays_take();
            progress_add(&prog, 1.0);
        }
        free(list);
        free(t.memo);
        p2_row_free(&row);
        rays += t.rays;
        split_add(c, &own);
    }
    *rays_out += rays;
    if (failed)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory in Phase Two");
    if (prog.cancelled)
        return zt_fail(err, ZT_ERR_CANCELLED, "render cancelled");
    return ZT_OK;
}

zt_status p2_render_reference(const p2_ctx *c, zt_image *sum, uint64_t *rays_out, zt_error *err)
{
    const zt_render_options *o = &c->r->options;
    int threads = render_thread_count(o->threads);
    uint64_t rays = 0;
    volatile int failed = 0; /* set by any thread that runs out of memory */
#pragma omp parallel num_threads(threads) reduction(+ : rays)
    {
        zone_trace t = p2_trace(c);
        p2_row row;
        memset(&row, 0, sizeof row);
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < sum->height; y++) {
            if (failed)
                continue;
            if (!p2_row_build(c, y, &row, &t.rays)) {
                failed = 1;
                continue;
            }
            for (int x = 0; x < sum->width; x++) {
                p2_pixel px;
                p2_row_pixel(&row, x, y, &px);
                double acc[3] = {0, 0, 0};
                p2_reference(c, &t, &px, acc);
                add_to_image(sum, x, y, acc);
            }
            t.rays += direct_rays_take();
        }
        p2_row_free(&row);
        rays += t.rays;
    }
    *rays_out += rays;
    if (failed)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory in Phase Two");
    return ZT_OK;
}

zt_status p2_render_zones(const p2_ctx *c, zt_image *sum, uint64_t *rays_out, zt_error *err)
{
    const zt_render_options *o = &c->r->options;
    const p2_terms *T = &c->terms;
    int threads = render_thread_count(o->threads);
    int w = sum->width, h = sum->height, parts = c->r->rs.part_count;
    int surfaces = T->surfaces;
    size_t npix = (size_t)w * (size_t)h;
    zt_status st = ZT_OK;
    uint64_t rays = 0;
    volatile int failed = 0; /* set by any thread that runs out of memory */

    /* 1. The sample lists of the whole image. */
    p2_row *rows = calloc((size_t)h, sizeof *rows);
    double *acc = calloc(npix * 3, sizeof *acc);
    int *hit_first = calloc((size_t)surfaces + 2, sizeof *hit_first);
    int *light_first = calloc((size_t)parts + 2, sizeof *light_first);
    int *last = malloc(((size_t)surfaces + 1) * sizeof *last);
    int *hit_pixels = NULL, *light_pixels = NULL;
    if (!rows || !acc || !hit_first || !light_first || !last) {
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory for the zone by zone strategy");
        goto done;
    }
    progress prog;
    progress_init(&prog, o, "zone samples", (double)share_owned(o, h));
#pragma omp parallel num_threads(threads) reduction(+ : rays)
    {
        uint64_t r = 0;
        p2_split own = {0};
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < h; y++) {
            if (prog.cancelled || failed || !share_owns(o, y))
                continue;
            double t0 = render_clock();
            if (!p2_row_build(c, y, &rows[y], &r))
                failed = 1;
            own.lists += render_clock() - t0;
            progress_add(&prog, 1.0);
        }
        rays += r;
        split_add(c, &own);
    }
    if (failed) {
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory in Phase Two");
        goto done;
    }
    if (prog.cancelled) {
        st = zt_fail(err, ZT_ERR_CANCELLED, "render cancelled");
        goto done;
    }

    /* 2. For every surface, the pixels whose samples hit it (slot
     * `surfaces`: nothing hit), and for every light part the pixels that see
     * it; ascending. */
    for (int pass = 0; pass < 2; pass++) {
        for (int q = 0; q <= surfaces; q++)
            last[q] = -1;
        size_t total_hits = 0, total_lights = 0;
        for (int y = 0; y < h; y++) {
            if (!share_owns(o, y))
                continue;
            for (int x = 0; x < w; x++) {
                p2_pixel px;
                p2_row_pixel(&rows[y], x, y, &px);
                int pi = y * w + x;
                for (int i = 0; i < px.n; i++) {
                    int q = px.s[i].surface < 0 ? surfaces : px.s[i].surface;
                    if (last[q] == pi)
                        continue;
                    last[q] = pi;
                    if (pass == 0)
                        hit_first[q + 1]++;
                    else
                        hit_pixels[hit_first[q]++] = pi;
                    total_hits++;
                }
                for (int i = 0; i < px.nlights; i++) {
                    int q = px.lights[i];
                    if (pass == 0)
                        light_first[q + 1]++;
                    else
                        light_pixels[light_first[q]++] = pi;
                    total_lights++;
                }
            }
        }
        if (pass == 0) {
            for (int q = 0; q <= surfaces; q++)
                hit_first[q + 1] += hit_first[q];
            for (int q = 0; q <= parts; q++)
                light_first[q + 1] += light_first[q];
            hit_pixels = malloc((total_hits + 1) * sizeof *hit_pixels);
            light_pixels = malloc((total_lights + 1) * sizeof *light_pixels);
            if (!hit_pixels || !light_pixels) {
                st = zt_fail(err, ZT_ERR_MEMORY, "out of memory for the zone by zone strategy");
                goto done;
            }
        } else {
            /* The fill moved each start to the next one's: shift back. */
            for (int q = surfaces; q >= 0; q--)
                hit_first[q + 1] = hit_first[q];
            for (int q = parts; q >= 0; q--)
                light_first[q + 1] = light_first[q];
            hit_first[0] = light_first[0] = 0;
        }
    }

    /* 3. Zone by zone, in term order. */
    double work = 0;
    for (int k = 0; k < T->count; k++) {
        const p2_term *term = &T->term[k];
        int q = term->type == P2_SKY ? surfaces : term->part;
        const int *first = term->type == P2_ROOT ? light_first : hit_first;
        work += first[q + 1] - first[q];
    }
    progress_init(&prog, o, "zone terms", work > 0 ? work : 1);
    for (int k = 0; k < T->count && !prog.cancelled; k++) {
        const p2_term *term = &T->term[k];
        int q = term->type == P2_SKY ? surfaces : term->part;
        const int *list = term->type == P2_ROOT ? light_pixels + light_first[q]
                                                : hit_pixels + hit_first[q];
        int n = term->type == P2_ROOT ? light_first[q + 1] - light_first[q]
                                      : hit_first[q + 1] - hit_first[q];
        if (n == 0)
            continue;
        /* Small terms stay on this thread: waking the others costs more. */
#pragma omp parallel num_threads(threads) reduction(+ : rays) if (n >= 256)
        {
            zone_trace t = p2_trace(c);
            int done = 0;
#pragma omp for schedule(dynamic, 16)
            for (int i = 0; i < n; i++) {
                int pi = list[i];
                p2_pixel px;
                p2_row_pixel(&rows[pi / w], pi % w, pi / w, &px);
                p2_apply(c, &t, k, &px, acc + (size_t)pi * 3);
                if (++done == 256) {
                    progress_add(&prog, done);
                    done = 0;
                }
            }
            if (done)
                progress_add(&prog, done);
            rays += t.rays + direct_rays_take();
        }
    }
    if (prog.cancelled) {
        st = zt_fail(err, ZT_ERR_CANCELLED, "render cancelled");
        goto done;
    }
    for (int y = 0; y < h; y++)
        if (share_owns(o, y))
            for (int x = 0; x < w; x++)
                add_to_image(sum, x, y, acc + ((size_t)y * w + x) * 3);

done:
    if (rows)
        for (int y = 0; y < h; y++)
            p2_row_free(&rows[y]);
    free(rows);
    free(acc);
    free(hit_first);
    free(light_first);
    free(last);
    free(hit_pixels);
    free(light_pixels);
    *rays_out += rays;
    return st;
}
