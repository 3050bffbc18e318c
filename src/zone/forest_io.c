/* The forest file: save and load (format in docs/zone-tracer.md).
 *
 * Everything is written byte by byte in little-endian order, so files move
 * between machines; doubles and floats as their IEEE-754 bit patterns, so a
 * loaded forest is the built one bit for bit and renders the same images. */
#define _POSIX_C_SOURCE 200809L /* mkstemp, fdopen */
#include "zone/forest_io.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "util/error.h"

static const char MAGIC[8] = {'Z', 'T', 'F', 'O', 'R', 'E', 'S', 'T'};
#define BYTE_ORDER_MARK 0x01020304u
#define MAP_DIM_MAX 65536

/* ---- hashing: 64-bit FNV-1a over little-endian values ---- */

typedef struct hasher { uint64_t h; } hasher;

static void h_bytes(hasher *h, const unsigned char *b, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        h->h ^= b[i];
        h->h *= 0x100000001b3ull;
    }
}

static void h_u64(hasher *h, uint64_t v)
{
    unsigned char b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    h_bytes(h, b, 8);
}

static void h_i32(hasher *h, int v) { h_u64(h, (uint64_t)(int64_t)v); }

static void h_f64(hasher *h, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    h_u64(h, u);
}

static void h_v3(hasher *h, vec3 v)
{
    h_f64(h, v.x);
    h_f64(h, v.y);
    h_f64(h, v.z);
}

uint64_t forest_scene_hash(const zt_scene *sc)
{
    hasher h = {0xcbf29ce484222325ull};
    h_i32(&h, sc->object_count);
    h_i32(&h, sc->part_count);
    for (int i = 0; i < sc->object_count; i++) {
        const object *o = &sc->objects[i];
        h_i32(&h, o->is_light);
        h_i32(&h, o->index);
        h_i32(&h, o->background);
        h_i32(&h, o->backculled);
        for (int k = 0; k < LOBE_COUNT; k++)
            h_f64(&h, o->mat.weight[k]);
        h_v3(&h, o->mat.color);
        h_f64(&h, o->mat.ior);
        h_v3(&h, o->emission);
        h_i32(&h, o->first_part);
        h_i32(&h, o->part_count);
    }
    for (int i = 0; i < sc->part_count; i++) {
        const part *p = &sc->parts[i];
        h_i32(&h, (int)p->shape);
        h_i32(&h, p->object);
        for (int k = 0; k < 3; k++)
            h_v3(&h, p->p[k]);
        h_f64(&h, p->radius);
        h_v3(&h, p->normal);
        h_f64(&h, p->offset);
    }
    h_v3(&h, sc->sky);
    h_i32(&h, sc->has_sky);
    return h.h;
}

/* The options that shape the forest, in a canonical form. */
typedef struct forest_options {
    int depth;          /* effective: the level when one is given */
    int quality;
    double cutoff;
    int lights_off_count;
    int lights_off[ZT_MAX_LIGHTS_OFF]; /* ascending, distinct */
    int gather, sides, aa;
    double texel_divisor, theta;
} forest_options;

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

static void options_of(const zt_render_options *o, const zone_quality *q, forest_options *fo)
{
    memset(fo, 0, sizeof *fo);
    fo->depth = o->level >= 0 ? o->level : o->depth;
    fo->quality = o->quality;
    fo->cutoff = o->cutoff;
    int n = o->lights_off_count < ZT_MAX_LIGHTS_OFF ? o->lights_off_count : ZT_MAX_LIGHTS_OFF;
    int tmp[ZT_MAX_LIGHTS_OFF];
    memcpy(tmp, o->lights_off, (size_t)n * sizeof *tmp);
    qsort(tmp, (size_t)n, sizeof *tmp, cmp_int);
    for (int i = 0; i < n; i++)
        if (i == 0 || tmp[i] != tmp[i - 1])
            fo->lights_off[fo->lights_off_count++] = tmp[i];
    fo->gather = q->gather;
    fo->sides = q->sides;
    fo->aa = q->aa;
    fo->texel_divisor = q->texel_divisor;
    fo->theta = q->theta;
}

static uint64_t options_hash(const forest_options *fo)
{
    hasher h = {0xcbf29ce484222325ull};
    h_i32(&h, fo->depth);
    h_i32(&h, fo->quality);
    h_f64(&h, fo->cutoff);
    h_i32(&h, fo->lights_off_count);
    for (int i = 0; i < fo->lights_off_count; i++)
        h_i32(&h, fo->lights_off[i]);
    h_i32(&h, fo->gather);
    h_i32(&h, fo->sides);
    h_i32(&h, fo->aa);
    h_f64(&h, fo->texel_divisor);
    h_f64(&h, fo->theta);
    return h.h;
}

/* ---- writing ---- */

typedef struct wbuf {
    unsigned char *b;
    size_t n, cap;
    int failed;
} wbuf;

static void w_bytes(wbuf *w, const void *p, size_t n)
{
    if (w->failed)
        return;
    if (w->n + n > w->cap) {
        size_t cap = w->cap ? w->cap : 1 << 16;
        while (cap < w->n + n)
            cap *= 2;
        unsigned char *nb = realloc(w->b, cap);
        if (!nb) {
            w->failed = 1;
            return;
        }
        w->b = nb;
        w->cap = cap;
    }
    memcpy(w->b + w->n, p, n);
    w->n += n;
}

static void w_u64(wbuf *w, uint64_t v)
{
    unsigned char b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    w_bytes(w, b, 8);
}

static void w_u32(wbuf *w, uint32_t v)
{
    unsigned char b[4];
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    w_bytes(w, b, 4);
}

static void w_i32(wbuf *w, int v) { w_u32(w, (uint32_t)v); }

static void w_f64(wbuf *w, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    w_u64(w, u);
}

static void w_f32(wbuf *w, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    w_u32(w, u);
}

static void w_v3(wbuf *w, vec3 v)
{
    w_f64(w, v.x);
    w_f64(w, v.y);
    w_f64(w, v.z);
}

static void w_f32s(wbuf *w, const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        w_f32(w, v[i]);
}

static int mip_size(int n, int k)
{
    n >>= k;
    return n > 0 ? n : 1;
}

/* Floats in mip k of a map: values of all levels and sides, and weights. */
static size_t mip_values(const part_map *m, int k)
{
    const map_layout *l = &m->layout;
    return (size_t)m->levels * l->sides * mip_size(l->nu, k) * mip_size(l->nv, k) * 3;
}

static size_t mip_weights(const part_map *m, int k)
{
    const map_layout *l = &m->layout;
    return (size_t)l->sides * mip_size(l->nu, k) * mip_size(l->nv, k);
}

/* What Phase Two needs that forest_build_maps derives from the final
 * texels of a level, redone after loading (keep in step with it; the
 * save/load round trip in tests/test_zone.c checks that the images stay
 * identical): the coarser copies.  The transfer's tables serve Phase One
 * only. */
static int derive_level(part_map *m, int level)
{
    return map_build_mips(m, level);
}

static size_t detail_values(const map_detail *d)
{
    return (size_t)d->ni * d->sub * d->nj * d->sub * 3;
}

/* A loaded cell may be split only inside a used texel a crossing cuts
 * (the read looks up that crossing). */
static int split_allowed(const part_map *m, const map_detail *d, size_t cell)
{
    size_t row = (size_t)d->ni * d->sub;
    int i = (int)(cell % row) / d->sub, j = (int)(cell / row) / d->sub;
    return d->use[(size_t)j * d->ni + i] &&
           m->cut[(size_t)(d->j0 + j) * m->layout.nu + d->i0 + i] >= 0;
}

static void w_axis(wbuf *w, const map_axis *a)
{
    w_i32(w, a->n);
    w_i32(w, a->k0);
    w_i32(w, a->k1);
    w_i32(w, a->grade);
    w_f64(w, a->w);
    w_f64(w, a->r);
    w_f64(w, a->len);
}

static void write_header(wbuf *w, const zone_forest *f, const zt_renderer *r,
                         const forest_options *fo)
{
    w_bytes(w, MAGIC, 8);
    w_u32(w, FOREST_FILE_VERSION);
    w_u32(w, BYTE_ORDER_MARK);
    w_u64(w, 0); /* file size, patched at the end */
    w_u64(w, forest_scene_hash(r->scene));
    w_u64(w, options_hash(fo));
    w_i32(w, r->scene->object_count);
    w_i32(w, r->scene->part_count);
    w_i32(w, fo->depth);
    w_i32(w, fo->quality);
    w_f64(w, fo->cutoff);
    w_i32(w, fo->lights_off_count);
    for (int i = 0; i < ZT_MAX_LIGHTS_OFF; i++)
        w_i32(w, i < fo->lights_off_count ? fo->lights_off[i] : -1);
    w_i32(w, fo->gather);
    w_i32(w, fo->sides);
    w_i32(w, fo->aa);
    w_f64(w, fo->texel_divisor);
    w_f64(w, fo->theta);
    w_f64(w, f->q.texel);
}

zt_status forest_save(const zone_forest *f, const zt_renderer *r, const char *path,
                      zt_error *err)
{
    forest_options fo;
    options_of(&r->options, &f->q, &fo);
    wbuf w = {0};
    write_header(&w, f, r, &fo);
    /* Zones and occluder lists. */
    w_i32(&w, f->zone_count);
    for (int i = 0; i < f->zone_count; i++) {
        const zone *z = &f->zones[i];
        w_i32(&w, z->parent);
        w_i32(&w, z->source);
        w_i32(&w, z->root_light);
        w_i32(&w, z->kind);
        w_i32(&w, z->level);
        w_f32(&w, z->power);
        w_i32(&w, z->first_child);
        w_i32(&w, z->child_count);
        w_i32(&w, z->first_occluder);
        w_i32(&w, z->occluder_count);
    }
    w_i32(&w, f->occluder_count);
    for (int i = 0; i < f->occluder_count; i++)
        w_i32(&w, f->occluders[i]);
    w_u64(&w, f->pruned);
    w_u64(&w, f->rays);
    w_f64(&w, f->build_seconds);
    /* Maps. */
    w_i32(&w, f->map_levels);
    w_i32(&w, f->map_count);
    for (int i = 0; i < f->map_count; i++) {
        const part_map *m = &f->maps[i];
        int present = m->texels != NULL;
        w_i32(&w, present);
        if (!present)
            continue;
        const map_layout *l = &m->layout;
        w_i32(&w, l->shape);
        w_i32(&w, l->nu);
        w_i32(&w, l->nv);
        w_i32(&w, l->sides);
        w_v3(&w, l->origin);
        w_v3(&w, l->du);
        w_v3(&w, l->dv);
        w_axis(&w, &l->au);
        w_axis(&w, &l->av);
        w_v3(&w, l->centre);
        w_f64(&w, l->radius);
        w_i32(&w, m->levels);
        w_f32s(&w, m->texels, mip_values(m, 0));
        w_f32s(&w, m->weight[0], mip_weights(m, 0));
        /* Crossings and the other halves of the texels they cut. */
        w_i32(&w, m->crossings);
        for (int c = 0; c < m->crossings; c++) {
            w_v3(&w, m->cross[c].n);
            w_f64(&w, m->cross[c].d);
            w_v3(&w, m->cross[c].a);
            w_v3(&w, m->cross[c].b);
            w_i32(&w, m->cross[c].part);
        }
        if (m->crossings > 0) {
            size_t cells = (size_t)l->nu * l->nv;
            for (size_t k = 0; k < cells; k++) {
                w_i32(&w, m->cut[k]);
                w_i32(&w, m->alt_sign[k]);
            }
            w_f32s(&w, m->alt, mip_values(m, 0));
            w_f32s(&w, m->alt_weight, mip_weights(m, 0));
        }
        /* Caustics kept apart (caustic.c). */
        w_i32(&w, m->details);
        for (int k = 0; k < m->details; k++) {
            const map_detail *d = &m->detail[k];
            w_i32(&w, d->level);
            w_i32(&w, d->side);
            w_i32(&w, d->i0);
            w_i32(&w, d->j0);
            w_i32(&w, d->ni);
            w_i32(&w, d->nj);
            w_i32(&w, d->sub);
            w_bytes(&w, d->use, (size_t)d->ni * d->nj);
            w_f32s(&w, d->e, detail_values(d));
            /* Texels read outside the marks: a caustic's only. */
            w_i32(&w, d->coarse != NULL);
            if (d->coarse)
                w_f32s(&w, d->coarse, (size_t)l->nu * l->nv * 3);
            /* Refinement cells split by a crossing. */
            w_i32(&w, d->split != NULL);
            if (d->split) {
                w_bytes(&w, d->split, detail_values(d) / 3);
                w_f32s(&w, d->far, detail_values(d) * 2);
            }
        }
    }
    /* File size and checksum. */
    uint64_t size = (uint64_t)w.n + 8;
    if (!w.failed)
        for (int i = 0; i < 8; i++)
            w.b[16 + i] = (unsigned char)(size >> (8 * i));
    hasher h = {0xcbf29ce484222325ull};
    if (!w.failed)
        h_bytes(&h, w.b, w.n);
    w_u64(&w, h.h);
    if (w.failed) {
        free(w.b);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory writing the forest");
    }

    size_t plen = strlen(path);
    char *tmp = malloc(plen + 16);
    if (!tmp) {
        free(w.b);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    }
    snprintf(tmp, plen + 16, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(tmp);
    if (fd >= 0)
        (void)fchmod(fd, 0644); /* mkstemp makes it private */
    FILE *fp = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (!fp) {
        int e = errno;
        if (fd >= 0) {
            close(fd);
            remove(tmp);
        }
        free(tmp);
        free(w.b);
        return zt_fail(err, ZT_ERR_WRITE, "cannot write forest file '%s': %s", path,
                       strerror(e));
    }
    int ok = fwrite(w.b, 1, w.n, fp) == w.n;
    int e = errno;
    ok = (fclose(fp) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        if (ok)
            e = errno;
        remove(tmp);
        free(tmp);
        free(w.b);
        return zt_fail(err, ZT_ERR_WRITE, "cannot write forest file '%s': %s", path,
                       strerror(e));
    }
    free(tmp);
    free(w.b);
    return ZT_OK;
}

zt_status zt_renderer_save_forest(const zt_renderer *r, const char *path, zt_error *err)
{
    if (!r || !path)
        return zt_fail(err, ZT_ERR_ARGUMENT, "no renderer or no path");
    if (r->options.method != ZT_METHOD_ZONE || !r->forest)
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "only the zone tracer has a forest to save (method path)");
    return forest_save((const zone_forest *)r->forest, r, path, err);
}

/* ---- reading ---- */

typedef struct rbuf {
    const unsigned char *b;
    size_t n, at;
    int short_read;
} rbuf;

static const unsigned char *r_take(rbuf *r, size_t n)
{
    if (r->short_read || n > r->n - r->at) {
        r->short_read = 1;
        return NULL;
    }
    const unsigned char *p = r->b + r->at;
    r->at += n;
    return p;
}

static uint64_t r_u64(rbuf *r)
{
    const unsigned char *p = r_take(r, 8);
    uint64_t v = 0;
    for (int i = 0; p && i < 8; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

static uint32_t r_u32(rbuf *r)
{
    const unsigned char *p = r_take(r, 4);
    uint32_t v = 0;
    for (int i = 0; p && i < 4; i++)
        v |= (uint32_t)p[i] << (8 * i);
    return v;
}

static int r_i32(rbuf *r) { return (int)(int32_t)r_u32(r); }

static double r_f64(rbuf *r)
{
    uint64_t u = r_u64(r);
    double v;
    memcpy(&v, &u, 8);
    return v;
}

static float r_f32(rbuf *r)
{
    uint32_t u = r_u32(r);
    float v;
    memcpy(&v, &u, 4);
    return v;
}

static vec3 r_v3(rbuf *r)
{
    double x = r_f64(r), y = r_f64(r), z = r_f64(r);
    return v3(x, y, z);
}

/* n floats into a new array, or NULL (short read or no memory: *oom). */
static float *r_f32s(rbuf *r, size_t n, int *oom)
{
    if (r->short_read || n > (r->n - r->at) / 4) {
        r->short_read = 1;
        return NULL;
    }
    float *v = malloc((n ? n : 1) * sizeof *v);
    if (!v) {
        *oom = 1;
        return NULL;
    }
    for (size_t i = 0; i < n; i++)
        v[i] = r_f32(r);
    return v;
}

/* n flags (bytes 0 or 1) into a new array, or NULL (short read, no memory:
 * *oom); *bad is set when one is neither. */
static unsigned char *r_flags(rbuf *r, size_t n, int *oom, int *bad)
{
    const unsigned char *p = r_take(r, n);
    if (!p)
        return NULL;
    unsigned char *v = malloc(n ? n : 1);
    if (!v) {
        *oom = 1;
        return NULL;
    }
    for (size_t i = 0; i < n; i++) {
        v[i] = p[i];
        *bad |= v[i] > 1;
    }
    return v;
}

static zt_status corrupt(zt_error *err, const char *path, const char *why)
{
    return zt_fail(err, ZT_ERR_PARSE, "forest file '%s' is corrupt: %s", path, why);
}

static void lights_text(char *out, size_t n, const forest_options *fo)
{
    size_t o = 0;
    out[0] = '\0';
    if (fo->lights_off_count == 0) {
        snprintf(out, n, "none");
        return;
    }
    for (int i = 0; i < fo->lights_off_count && o < n; i++) {
        int w = snprintf(out + o, n - o, i ? ",%d" : "%d", fo->lights_off[i]);
        if (w < 0)
            break;
        o += (size_t)w;
    }
}

/* Compares the file's forest options with the render's. */
static zt_status check_options(const char *path, const forest_options *file,
                               const forest_options *want, zt_error *err)
{
    const char *pre = "forest file '%s' was made with other options: ";
    char msg[ZT_ERROR_MESSAGE_MAX];
    if (file->depth != want->depth)
        snprintf(msg, sizeof msg, "depth %d, this render needs depth %d (--depth, or --level "
                 "when given)", file->depth, want->depth);
    else if (file->quality != want->quality)
        snprintf(msg, sizeof msg, "quality %d, this render uses %d", file->quality,
                 want->quality);
    else if (memcmp(&file->cutoff, &want->cutoff, sizeof file->cutoff) != 0)
        snprintf(msg, sizeof msg, "cutoff %.17g, this render uses %.17g", file->cutoff,
                 want->cutoff);
    else if (file->lights_off_count != want->lights_off_count ||
             memcmp(file->lights_off, want->lights_off,
                    (size_t)file->lights_off_count * sizeof(int)) != 0) {
        char a[200], b[200];
        lights_text(a, sizeof a, file);
        lights_text(b, sizeof b, want);
        snprintf(msg, sizeof msg, "lights off %s, this render %s", a, b);
    } else if (file->gather != want->gather)
        snprintf(msg, sizeof msg, "%d gather directions, this render %d",
                 file->gather, want->gather);
    else if (memcmp(&file->texel_divisor, &want->texel_divisor, sizeof(double)) != 0)
        snprintf(msg, sizeof msg, "texel divisor %g, this render %g",
                 file->texel_divisor, want->texel_divisor);
    else if (memcmp(&file->theta, &want->theta, sizeof(double)) != 0)
        snprintf(msg, sizeof msg, "transfer threshold %g, this render %g",
                 file->theta, want->theta);
    else if (file->sides != want->sides || file->aa != want->aa)
        snprintf(msg, sizeof msg, "other quality settings");
    else
        return ZT_OK;
    char full[ZT_ERROR_MESSAGE_MAX];
    snprintf(full, sizeof full, pre, path);
    return zt_fail(err, ZT_ERR_PARSE, "%s%s", full, msg);
}

static map_axis r_axis(rbuf *rb)
{
    map_axis a;
    a.n = r_i32(rb);
    a.k0 = r_i32(rb);
    a.k1 = r_i32(rb);
    a.grade = r_i32(rb);
    a.w = r_f64(rb);
    a.r = r_f64(rb);
    a.len = r_f64(rb);
    a.edge = NULL;
    return a;
}

static int axis_ok(const map_axis *a, int n)
{
    return a->n == n && a->k0 >= 0 && a->k0 < a->k1 && a->k1 <= a->n && a->grade >= 0 &&
           a->grade <= 16 && (a->grade == 0 || a->k1 - a->k0 >= 2 * a->grade + 2) && a->w > 0 &&
           a->r >= 1.0 && a->r < 16.0 && a->len > 0 && isfinite(a->w) && isfinite(a->len);
}

static zt_status read_maps(zone_forest *f, rbuf *rb, int parts, int sky, const char *path,
                           zt_error *err)
{
    int oom = 0;
    f->map_levels = r_i32(rb);
    f->sky_slot = sky ? f->map_levels : -1; /* as forest_build_maps decides */
    int map_count = r_i32(rb);
    if (rb->short_read)
        return ZT_ERR_PARSE;
    if (map_count != parts || f->map_levels < 0 || f->map_levels > 1024)
        return corrupt(err, path, "bad map count or levels");
    f->maps = calloc((size_t)parts + 1, sizeof(part_map));
    if (!f->maps)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
    f->map_count = parts;
    for (int i = 0; i < parts; i++) {
        part_map *m = &f->maps[i];
        int present = r_i32(rb);
        if (rb->short_read)
            return ZT_ERR_PARSE;
        if (present == 0)
            continue;
        if (present != 1)
            return corrupt(err, path, "bad map flag");
        map_layout *l = &m->layout;
        l->shape = r_i32(rb);
        l->nu = r_i32(rb);
        l->nv = r_i32(rb);
        l->sides = r_i32(rb);
        l->origin = r_v3(rb);
        l->du = r_v3(rb);
        l->dv = r_v3(rb);
        l->au = r_axis(rb);
        l->av = r_axis(rb);
        l->centre = r_v3(rb);
        l->radius = r_f64(rb);
        m->levels = r_i32(rb);
        if (rb->short_read)
            return ZT_ERR_PARSE;
        if (l->shape < SHAPE_SPHERE || l->shape > SHAPE_POINT || l->nu < 1 ||
            l->nu > MAP_DIM_MAX || l->nv < 1 || l->nv > MAP_DIM_MAX || l->sides < 1 ||
            l->sides > 2 || m->levels != f->map_levels + (f->sky_slot >= 0) || m->levels < 1 ||
            !axis_ok(&l->au, l->nu) || !axis_ok(&l->av, l->nv))
            return corrupt(err, path, "bad map layout");
        if (!map_layout_cache(l))
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
        m->texels = r_f32s(rb, mip_values(m, 0), &oom);
        if (m->texels)
            m->weight[0] = r_f32s(rb, mip_weights(m, 0), &oom);
        if (oom)
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
        if (rb->short_read)
            return ZT_ERR_PARSE;
        m->crossings = r_i32(rb);
        if (rb->short_read)
            return ZT_ERR_PARSE;
        if (m->crossings < 0 || m->crossings > MAP_CROSSINGS ||
            (m->crossings > 0 && l->shape != SHAPE_TRIANGLE))
            return corrupt(err, path, "bad crossing count");
        if (m->crossings > 0) {
            size_t cells = (size_t)l->nu * l->nv;
            m->cross = malloc((size_t)m->crossings * sizeof *m->cross);
            m->cut = malloc(cells);
            m->alt_sign = malloc(cells);
            if (!m->cross || !m->cut || !m->alt_sign)
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
            for (int c = 0; c < m->crossings; c++) {
                m->cross[c].n = r_v3(rb);
                m->cross[c].d = r_f64(rb);
                m->cross[c].a = r_v3(rb);
                m->cross[c].b = r_v3(rb);
                m->cross[c].part = r_i32(rb);
                if (m->cross[c].part < 0 || m->cross[c].part >= parts)
                    return corrupt(err, path, "bad crossing");
            }
            for (size_t k = 0; k < cells; k++) {
                int cut = r_i32(rb), sign = r_i32(rb);
                if (rb->short_read)
                    return ZT_ERR_PARSE;
                if (cut < -1 || cut >= m->crossings || (cut >= 0 && sign != 1 && sign != -1) ||
                    (cut < 0 && sign != 0))
                    return corrupt(err, path, "bad cut texel");
                m->cut[k] = (signed char)cut;
                m->alt_sign[k] = (signed char)sign;
            }
            m->alt = r_f32s(rb, mip_values(m, 0), &oom);
            if (m->alt)
                m->alt_weight = r_f32s(rb, mip_weights(m, 0), &oom);
            if (oom)
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
            if (rb->short_read)
                return ZT_ERR_PARSE;
        }
        for (int level = 0; level < m->levels; level++)
            if (!derive_level(m, level))
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
        int details = r_i32(rb);
        if (rb->short_read)
            return ZT_ERR_PARSE;
        /* Per level and side: a caustic's window, the refinement's, and
         * one around each end of each crossing. */
        int most = 2 * f->map_levels * (2 + 2 * m->crossings);
        if (details < 0 || details > most || (details && l->shape == SHAPE_SPHERE))
            return corrupt(err, path, "bad detail window count");
        m->detail = calloc((size_t)details + 1, sizeof(map_detail));
        if (!m->detail)
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
        for (int k = 0; k < details; k++) {
            map_detail *d = &m->detail[k];
            m->details = k + 1; /* freed with the map from here on */
            d->level = r_i32(rb);
            d->side = r_i32(rb);
            d->i0 = r_i32(rb);
            d->j0 = r_i32(rb);
            d->ni = r_i32(rb);
            d->nj = r_i32(rb);
            d->sub = r_i32(rb);
            if (rb->short_read)
                return ZT_ERR_PARSE;
            if (d->level < 1 || d->level >= f->map_levels || d->side < 0 || d->side >= l->sides ||
                d->i0 < 0 || d->ni < 1 || d->ni > l->nu - d->i0 || d->j0 < 0 || d->nj < 1 ||
                d->nj > l->nv - d->j0 || d->sub < 1 || d->sub > 64)
                return corrupt(err, path, "bad detail window");
            int bad = 0;
            d->use = r_flags(rb, (size_t)d->ni * d->nj, &oom, &bad);
            if (oom)
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
            if (rb->short_read)
                return ZT_ERR_PARSE;
            if (bad)
                return corrupt(err, path, "bad detail window");
            d->e = r_f32s(rb, detail_values(d), &oom);
            int has_coarse = r_i32(rb);
            if (rb->short_read)
                return ZT_ERR_PARSE;
            if (has_coarse != 0 && has_coarse != 1)
                return corrupt(err, path, "bad detail window");
            if (d->e && has_coarse)
                d->coarse = r_f32s(rb, (size_t)l->nu * l->nv * 3, &oom);
            int has_split = r_i32(rb);
            if (rb->short_read)
                return ZT_ERR_PARSE;
            if ((has_split != 0 && has_split != 1) || (has_split && (d->coarse || !m->crossings)))
                return corrupt(err, path, "bad detail window");
            if (d->e && has_split) {
                size_t ncell = detail_values(d) / 3;
                d->split = r_flags(rb, ncell, &oom, &bad);
                for (size_t c = 0; d->split && c < ncell; c++)
                    bad |= d->split[c] && !split_allowed(m, d, c);
                if (bad)
                    return corrupt(err, path, "bad detail window");
                d->far = r_f32s(rb, ncell * 6, &oom);
            }
            if (oom)
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
            if (rb->short_read)
                return ZT_ERR_PARSE;
        }
        m->detail_live = 1;
    }
    return ZT_OK;
}

zt_status forest_load(zone_forest *f, const zt_renderer *r, const zone_quality *expect,
                      const char *path, zt_error *err)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return zt_fail(err, ZT_ERR_READ, "cannot open forest file '%s': %s", path,
                       strerror(errno));
    unsigned char *data = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n == cap) {
            cap = cap ? 2 * cap : 1 << 16;
            unsigned char *nd = realloc(data, cap);
            if (!nd) {
                free(data);
                fclose(fp);
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading '%s'", path);
            }
            data = nd;
        }
        size_t got = fread(data + n, 1, cap - n, fp);
        n += got;
        if (got == 0)
            break;
    }
    int read_error = ferror(fp);
    fclose(fp);
    if (read_error) {
        free(data);
        return zt_fail(err, ZT_ERR_READ, "cannot read forest file '%s'", path);
    }

    zt_status st = ZT_OK;
    rbuf rb = {data, n, 0, 0};
    const unsigned char *magic = r_take(&rb, 8);
    if (!magic || memcmp(magic, MAGIC, 8) != 0) {
        st = zt_fail(err, ZT_ERR_PARSE, "'%s' is not a zonetrace forest file (no ZTFOREST "
                     "signature)", path);
        goto done;
    }
    uint32_t version = r_u32(&rb), bom = r_u32(&rb);
    uint64_t size = r_u64(&rb);
    if (rb.short_read) {
        st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' is truncated (%zu bytes)", path, n);
        goto done;
    }
    if (version != FOREST_FILE_VERSION) {
        st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' has format version %u; this build "
                     "reads version %d (make it again with --save-forest)", path, version,
                     FOREST_FILE_VERSION);
        goto done;
    }
    if (bom != BYTE_ORDER_MARK) {
        st = corrupt(err, path, "bad byte-order mark");
        goto done;
    }
    if (size != (uint64_t)n) {
        if ((uint64_t)n < size)
            st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' is truncated (%zu of %llu bytes)",
                         path, n, (unsigned long long)size);
        else
            st = corrupt(err, path, "it is longer than its header says");
        goto done;
    }
    {
        hasher h = {0xcbf29ce484222325ull};
        h_bytes(&h, data, n - 8);
        rbuf tail = {data + n - 8, 8, 0, 0};
        if (h.h != r_u64(&tail)) {
            st = corrupt(err, path, "checksum mismatch");
            goto done;
        }
    }
    uint64_t scene_hash = r_u64(&rb), opt_hash = r_u64(&rb);
    int objects = r_i32(&rb), parts = r_i32(&rb);
    forest_options file;
    memset(&file, 0, sizeof file);
    file.depth = r_i32(&rb);
    file.quality = r_i32(&rb);
    file.cutoff = r_f64(&rb);
    file.lights_off_count = r_i32(&rb);
    for (int i = 0; i < ZT_MAX_LIGHTS_OFF; i++) {
        int v = r_i32(&rb);
        if (i < ZT_MAX_LIGHTS_OFF)
            file.lights_off[i] = v;
    }
    file.gather = r_i32(&rb);
    file.sides = r_i32(&rb);
    file.aa = r_i32(&rb);
    file.texel_divisor = r_f64(&rb);
    file.theta = r_f64(&rb);
    double texel = r_f64(&rb);
    if (rb.short_read || file.lights_off_count < 0 || file.lights_off_count > ZT_MAX_LIGHTS_OFF) {
        st = corrupt(err, path, "bad header");
        goto done;
    }
    const zt_scene *sc = r->scene;
    if (scene_hash != forest_scene_hash(sc)) {
        if (objects != sc->object_count || parts != sc->part_count)
            st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' was made for another scene (%d "
                         "objects, %d parts; this scene has %d objects, %d parts)", path,
                         objects, parts, sc->object_count, sc->part_count);
        else
            st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' was made for another scene (its "
                         "geometry, materials, lights or sky differ)", path);
        goto done;
    }
    forest_options want;
    options_of(&r->options, expect, &want);
    st = check_options(path, &file, &want, err);
    if (st != ZT_OK)
        goto done;
    if (opt_hash != options_hash(&want)) {
        st = corrupt(err, path, "options hash mismatch");
        goto done;
    }

    /* The forest itself. */
    f->q = *expect;
    f->q.texel = texel;
    f->direct.scene = r->scene;
    f->direct.rs = &r->rs;
    f->direct.sides = f->q.sides;
    int zc = r_i32(&rb);
    if (rb.short_read || zc < 0 || (size_t)zc > (n - rb.at) / 40) {
        st = rb.short_read ? ZT_ERR_PARSE : corrupt(err, path, "bad zone count");
        goto done;
    }
    f->zones = malloc(((size_t)zc + 1) * sizeof *f->zones);
    if (!f->zones) {
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
        goto done;
    }
    f->zone_count = f->zone_capacity = zc;
    for (int i = 0; i < zc; i++) {
        zone *z = &f->zones[i];
        z->parent = r_i32(&rb);
        z->source = r_i32(&rb);
        z->root_light = r_i32(&rb);
        int kind = r_i32(&rb), level = r_i32(&rb);
        z->power = r_f32(&rb);
        z->first_child = r_i32(&rb);
        z->child_count = r_i32(&rb);
        z->first_occluder = r_i32(&rb);
        z->occluder_count = r_i32(&rb);
        if (kind < 0 || kind >= ZONE_KINDS || level < 0 || level > 255 || z->parent < -1 ||
            z->parent >= i || z->source < 0 || z->source >= parts || z->root_light < 0 ||
            z->root_light >= parts || z->child_count < 0 || z->first_child < 0 ||
            z->first_child > zc - z->child_count || z->occluder_count < 0 ||
            z->first_occluder < 0) {
            st = corrupt(err, path, "bad zone");
            goto done;
        }
        z->kind = (uint8_t)kind;
        z->level = (uint8_t)level;
    }
    int oc = r_i32(&rb);
    if (rb.short_read || oc < 0 || (size_t)oc > (n - rb.at) / 4) {
        st = rb.short_read ? ZT_ERR_PARSE : corrupt(err, path, "bad occluder count");
        goto done;
    }
    f->occluders = malloc(((size_t)oc + 1) * sizeof *f->occluders);
    if (!f->occluders) {
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
        goto done;
    }
    f->occluder_count = f->occluder_capacity = oc;
    for (int i = 0; i < oc; i++) {
        f->occluders[i] = r_i32(&rb);
        if (f->occluders[i] < 0 || f->occluders[i] >= parts) {
            st = corrupt(err, path, "bad occluder");
            goto done;
        }
    }
    for (int i = 0; i < zc; i++)
        if (f->zones[i].first_occluder > oc - f->zones[i].occluder_count) {
            st = corrupt(err, path, "bad occluder list");
            goto done;
        }
    f->pruned = r_u64(&rb);
    f->rays = r_u64(&rb);
    f->build_seconds = r_f64(&rb); /* informative */
    if (rb.short_read) {
        st = ZT_ERR_PARSE;
        goto done;
    }
    st = read_maps(f, &rb, parts, !f3_is_black(r->rs.sky), path, err);
    if (st == ZT_OK && !rb.short_read && rb.at != n - 8)
        st = corrupt(err, path, "unexpected data after the maps");
done:
    if (st == ZT_ERR_PARSE && rb.short_read)
        st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' is truncated (%zu bytes)", path, n);
    free(data);
    if (st == ZT_OK)
        f->loaded = 1;
    return st;
}

void forest_memory(const zone_forest *f, uint64_t *zones, uint64_t *occluders, uint64_t *maps)
{
    *zones = (uint64_t)f->zone_count * sizeof(zone);
    *occluders = (uint64_t)f->occluder_count * sizeof(int);
    uint64_t mb = (uint64_t)f->map_count * sizeof(part_map);
    for (int i = 0; i < f->map_count; i++) {
        const part_map *m = &f->maps[i];
        if (!m->texels)
            continue;
        for (int k = 0; k < m->mips; k++)
            mb += (mip_values(m, k) + mip_weights(m, k)) * sizeof(float);
        if (m->crossings > 0)
            mb += (mip_values(m, 0) + mip_weights(m, 0)) * sizeof(float) +
                  (size_t)m->layout.nu * m->layout.nv * 2 +
                  (size_t)m->crossings * sizeof *m->cross;
        for (int k = 0; k < m->details; k++)
            mb += sizeof(map_detail) + (size_t)m->detail[k].ni * m->detail[k].nj +
                  (detail_values(&m->detail[k]) * (m->detail[k].split ? 3 : 1) +
                   (m->detail[k].coarse ? mip_values(m, 0) / m->levels / m->layout.sides : 0)) *
                      sizeof(float);
    }
    *maps = mb;
}
