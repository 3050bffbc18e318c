/* The forest file: save and load (format in docs/zone-tracer.md).
 *
 * Everything is written byte by byte in little-endian order, so files move
 * between machines; doubles and floats as their IEEE-754 bit patterns, so a
 * loaded forest is the built one bit for bit and renders the same images. */
#define _POSIX_C_SOURCE 200809L /* mkstemp, fdopen */
#include "zone/io/forest_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scene/mesh.h"
#include "scene/scene_hash.h"
#include "util/fnv1a.h"
#include "util/error.h"
#include "zone/phase_one/node_life.h"

static const char MAGIC[8] = {'Z', 'T', 'F', 'O', 'R', 'E', 'S', 'T'};
#define BYTE_ORDER_MARK 0x01020304u

/* The options that shape the forest, in a canonical form. */
typedef struct forest_options {
    int depth;          /* effective: the level when one is given */
    int quality;
    double cutoff;
    int lights_off_count;
    int lights_off[ZT_MAX_LIGHTS_OFF]; /* ascending, distinct */
    int gather, sides, aa, fallback;
    double texel_divisor, theta, eps;
} forest_options;

static void options_of(const zt_render_options *o, const zone_quality *q, forest_options *fo)
{
    memset(fo, 0, sizeof *fo);
    fo->depth = o->level >= 0 ? o->level : o->depth;
    fo->quality = o->quality;
    fo->cutoff = o->cutoff;
    fo->lights_off_count = render_lights_off_sorted(o, fo->lights_off);
    fo->gather = q->gather;
    fo->sides = q->sides;
    fo->aa = q->aa;
    fo->texel_divisor = q->texel_divisor;
    fo->theta = q->theta;
    fo->eps = q->eps;
    fo->fallback = q->fallback;
}

static uint64_t options_hash(const forest_options *fo)
{
    fnv1a h = {FNV1A_START};
    fnv_i32(&h, fo->depth);
    fnv_i32(&h, fo->quality);
    fnv_f64(&h, fo->cutoff);
    fnv_i32(&h, fo->lights_off_count);
    for (int i = 0; i < fo->lights_off_count; i++)
        fnv_i32(&h, fo->lights_off[i]);
    fnv_i32(&h, fo->gather);
    fnv_i32(&h, fo->sides);
    fnv_i32(&h, fo->aa);
    fnv_f64(&h, fo->texel_divisor);
    fnv_f64(&h, fo->theta);
    fnv_f64(&h, fo->eps);
    fnv_i32(&h, fo->fallback);
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

static void w_f32s(wbuf *w, const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        w_f32(w, v[i]);
}

static void write_header(wbuf *w, const zone_forest *f, const zt_renderer *r,
                         const forest_options *fo)
{
    w_bytes(w, MAGIC, 8);
    w_u32(w, FOREST_FILE_VERSION);
    w_u32(w, BYTE_ORDER_MARK);
    w_u64(w, 0); /* file size, patched at the end */
    w_u64(w, scene_hash(r->scene));
    w_u64(w, options_hash(fo));
    w_i32(w, r->scene->object_count);
    w_i32(w, r->scene->part_count);
    w_i32(w, r->rs.prim_count);
    w_i32(w, fo->depth);
    w_i32(w, fo->quality);
    w_f64(w, fo->cutoff);
    w_i32(w, fo->lights_off_count);
    for (int i = 0; i < ZT_MAX_LIGHTS_OFF; i++)
        w_i32(w, i < fo->lights_off_count ? fo->lights_off[i] : -1);
    w_i32(w, fo->gather);
    w_i32(w, fo->sides);
    w_i32(w, fo->aa);
    w_i32(w, fo->fallback);
    w_f64(w, fo->texel_divisor);
    w_f64(w, fo->theta);
    w_f64(w, fo->eps);
    w_f64(w, f->q.texel);
}

zt_status forest_save(const zone_forest *f, const zt_renderer *r, const char *path,
                      zt_error *err)
{
    forest_options fo;
    options_of(&r->options, &f->q, &fo);
    wbuf w = {0};
    write_header(&w, f, r, &fo);
    w_i32(&w, f->zone_count);
    for (int i = 0; i < f->zone_count; i++) {
        const zone *z = &f->zones[i];
        w_i32(&w, z->source);
        w_i32(&w, z->kind);
        w_i32(&w, z->level);
        w_f32(&w, z->power);
    }
    w_u64(&w, f->pruned);
    w_u64(&w, f->rays);
    w_u64(&w, f->links);
    w_f64(&w, f->build_seconds);
    /* The nodes: which are live and where (Phase One may have moved some
     * off a wall), and the irradiance of every level. */
    w_i32(&w, f->map_levels);
    w_i32(&w, f->sn.node_count);
    if (f->map_levels > 0) {
        w_bytes(&w, f->sn.live, (size_t)f->sn.node_count);
        w_f32s(&w, f->sn.pos, (size_t)f->sn.node_count * 3);
        w_f32s(&w, f->e, (size_t)f->map_levels * f->sn.node_count * 3);
        /* The caustics' and glints' part, where it is kept apart. */
        w_i32(&w, f->c != NULL);
        if (f->c)
            w_f32s(&w, f->c, (size_t)f->map_levels * f->sn.node_count * 3);
        /* The caustic photons in their trees' order, and what the nodes
         * took of them. */
        w_i32(&w, (f->caustic != NULL) | (f->sun_photons ? 2 : 0));
        if (f->caustic) {
            w_f32s(&w, f->caustic, (size_t)f->map_levels * f->sn.node_count * 3);
            /* Levels a time limit left unbuilt are not kept: their photons
             * are the trees' last (by level). */
            size_t kept = 0;
            while (kept < f->photons.count && f->photons.p[kept].level < f->map_levels)
                kept++;
            w_u64(&w, kept);
            for (size_t i = 0; i < kept; i++) {
                const zone_photon *p = &f->photons.p[i];
                w_f32s(&w, p->x, 3);
                w_f32s(&w, p->flux, 3);
                w_i32(&w, p->surface);
                w_bytes(&w, p->n, 3);
                w_bytes(&w, &p->level, 1);
                w_bytes(&w, &f->photons.axis[i], 1);
            }
        }
    }
    uint64_t size = (uint64_t)w.n + 8;
    if (!w.failed)
        for (int i = 0; i < 8; i++)
            w.b[16 + i] = (unsigned char)(size >> (8 * i));
    fnv1a h = {FNV1A_START};
    if (!w.failed)
        fnv_bytes(&h, w.b, w.n);
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
    if (((const zone_forest *)r->forest)->top_gathered)
        return zt_fail(err, ZT_ERR_ARGUMENT,
                       "this forest was built for one image (zt_render) and cannot be saved");
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
    else if (memcmp(&file->eps, &want->eps, sizeof(double)) != 0)
        snprintf(msg, sizeof msg, "transfer error bound %g, this render %g", file->eps,
                 want->eps);
    else if (file->sides != want->sides || file->aa != want->aa ||
             file->fallback != want->fallback)
        snprintf(msg, sizeof msg, "other quality settings");
    else
        return ZT_OK;
    char full[ZT_ERROR_MESSAGE_MAX];
    snprintf(full, sizeof full, pre, path);
    return zt_fail(err, ZT_ERR_PARSE, "%s%s", full, msg);
}

/* Bytes of one photon in the file. */
#define PHOTON_BYTES 30

/* The caustic photons and the nodes' part of them, if the file has them. */
static zt_status read_photons(zone_forest *f, const rscene *rs, rbuf *rb, const char *path,
                              zt_error *err)
{
    int has = r_i32(rb);
    if (rb->short_read)
        return ZT_ERR_PARSE;
    if (has < 0 || has > 3)
        return corrupt(err, path, "bad caustic flag");
    f->sun_photons = has >> 1;
    if (!(has & 1))
        return ZT_OK;
    size_t n = (size_t)f->map_levels * (size_t)f->sn.node_count * 3;
    int oom = 0;
    f->caustic = r_f32s(rb, n, &oom);
    uint64_t count = r_u64(rb);
    if (oom)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
    if (rb->short_read)
        return ZT_ERR_PARSE;
    if (count > (rb->n - rb->at) / PHOTON_BYTES)
        return corrupt(err, path, "more caustic photons than the file holds");
    for (size_t i = 0; i < n; i++)
        if (!isfinite(f->caustic[i]))
            return corrupt(err, path, "bad caustic values");
    photon_map *m = &f->photons;
    m->p = malloc(((size_t)count + 1) * sizeof *m->p);
    m->axis = malloc((size_t)count + 1);
    if (!m->p || !m->axis)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
    m->count = m->capacity = (size_t)count;
    int surfaces = rs->part_count + rs->object_count;
    for (size_t i = 0; i < m->count; i++) {
        zone_photon *p = &m->p[i];
        int bad = 0;
        for (int k = 0; k < 3; k++) {
            p->x[k] = r_f32(rb);
            bad |= !isfinite(p->x[k]);
        }
        for (int k = 0; k < 3; k++) {
            p->flux[k] = r_f32(rb);
            bad |= !(p->flux[k] >= 0.0f && p->flux[k] < INFINITY);
        }
        p->surface = r_i32(rb);
        const unsigned char *b = r_take(rb, 5);
        if (!b)
            return ZT_ERR_PARSE;
        memcpy(p->n, b, 3);
        p->level = b[3];
        m->axis[i] = b[4];
        if (bad || p->surface < 0 || p->surface >= surfaces || p->level < 1 ||
            p->level >= f->map_levels)
            return corrupt(err, path, "bad caustic photons");
    }
    int adopted = photon_map_adopt(m);
    if (adopted < 0)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
    if (adopted == 0)
        return corrupt(err, path, "caustic photons out of order");
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
        fnv1a h = {FNV1A_START};
        fnv_bytes(&h, data, n - 8);
        rbuf tail = {data + n - 8, 8, 0, 0};
        if (h.h != r_u64(&tail)) {
            st = corrupt(err, path, "checksum mismatch");
            goto done;
        }
    }
    uint64_t file_scene_hash = r_u64(&rb), opt_hash = r_u64(&rb);
    int objects = r_i32(&rb), parts = r_i32(&rb), prims = r_i32(&rb);
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
    file.fallback = r_i32(&rb);
    file.texel_divisor = r_f64(&rb);
    file.theta = r_f64(&rb);
    file.eps = r_f64(&rb);
    double texel = r_f64(&rb);
    if (rb.short_read || file.lights_off_count < 0 || file.lights_off_count > ZT_MAX_LIGHTS_OFF) {
        st = corrupt(err, path, "bad header");
        goto done;
    }
    const zt_scene *sc = r->scene;
    if (file_scene_hash != scene_hash(sc)) {
        if (objects != sc->object_count || parts != sc->part_count || prims != r->rs.prim_count)
            st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' was made for another scene (%d "
                         "objects, %d primitives; this scene has %d objects, %d primitives)",
                         path, objects, prims, sc->object_count, r->rs.prim_count);
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

    /* The forest itself: the frame is made again from the scene, the rest
     * read and checked. */
    f->q = *expect;
    f->q.texel = texel;
    int zc = r_i32(&rb);
    if (rb.short_read || zc < 0 || (size_t)zc > (n - rb.at) / 16) {
        st = rb.short_read ? ZT_ERR_PARSE : corrupt(err, path, "bad zone count");
        goto done;
    }
    f->zones = malloc(((size_t)zc + 1) * sizeof *f->zones);
    if (!f->zones) {
        st = zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
        goto done;
    }
    f->zone_count = f->zone_capacity = zc;
    int surfaces = zone_surface_count(&r->rs);
    for (int i = 0; i < zc; i++) {
        zone *z = &f->zones[i];
        z->source = r_i32(&rb);
        int kind = r_i32(&rb), level = r_i32(&rb);
        z->power = r_f32(&rb);
        int limit = kind == ZONE_EMIT ? r->rs.prim_count : surfaces;
        if (kind < 0 || kind >= ZONE_KINDS || level < 0 || level > 255 || z->source < 0 ||
            z->source >= limit || (kind == ZONE_EMIT && level != 0) ||
            (level == 0 && kind != ZONE_EMIT && kind != ZONE_REFRACT) || !(z->power >= 0)) {
            st = corrupt(err, path, "bad zone");
            goto done;
        }
        z->kind = (uint8_t)kind;
        z->level = (uint8_t)level;
    }
    f->pruned = r_u64(&rb);
    f->rays = r_u64(&rb);
    f->links = r_u64(&rb);
    f->build_seconds = r_f64(&rb); /* informative */
    int levels = r_i32(&rb), nodes = r_i32(&rb);
    if (rb.short_read) {
        st = ZT_ERR_PARSE;
        goto done;
    }
    st = zone_forest_frame(f, r, err);
    if (st != ZT_OK)
        goto done;
    if (levels != (file.depth >= 2 ? file.depth : 0) || nodes != f->sn.node_count) {
        st = corrupt(err, path, "its nodes do not match the scene's");
        goto done;
    }
    f->map_levels = levels;
    if (levels > 0) {
        size_t nn = (size_t)nodes;
        const unsigned char *live = r_take(&rb, nn);
        int oom = 0;
        float *pos = r_f32s(&rb, nn * 3, &oom);
        f->e = r_f32s(&rb, (size_t)levels * nn * 3, &oom);
        int apart = r_i32(&rb);
        if (apart == 1)
            f->c = r_f32s(&rb, (size_t)levels * nn * 3, &oom);
        if (oom) {
            free(pos);
            st = zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
            goto done;
        }
        /* Kept apart exactly when this build keeps it (phase_one.c). */
        int want = f->specular && r->rs.mesh_count > 0;
        if (!live || !pos || !f->e || apart != want || (apart && !f->c)) {
            free(pos);
            st = apart != want && live && pos && f->e
                     ? corrupt(err, path, "its caustic maps do not match the scene's")
                     : ZT_ERR_PARSE;
            goto done;
        }
        float *reach = node_life_reach(&f->sn, &r->rs);
        if (!reach) {
            free(pos);
            st = zt_fail(err, ZT_ERR_MEMORY, "out of memory reading the forest");
            goto done;
        }
        int bad = 0;
        for (size_t k = 0; k < nn; k++) {
            bad |= live[k] > 1;
            for (int a = 0; a < 3; a++)
                bad |= !(fabsf(pos[3 * k + a] - f->sn.pos[3 * k + a]) <=
                         reach[k] + 1e-6f * fabsf(f->sn.pos[3 * k + a]));
        }
        free(reach);
        for (size_t k = 0; k < (size_t)levels * nn * 3; k++)
            bad |= !isfinite(f->e[k]) || (f->c && !isfinite(f->c[k]));
        if (bad) {
            free(pos);
            st = corrupt(err, path, "bad node values");
            goto done;
        }
        memcpy(f->sn.live, live, nn);
        memcpy(f->sn.pos, pos, nn * 3 * sizeof(float));
        free(pos);
        st = read_photons(f, &r->rs, &rb, path, err);
        if (st != ZT_OK)
            goto done;
    }
    if (!rb.short_read && rb.at != n - 8)
        st = corrupt(err, path, "unexpected data after the nodes");
done:
    if (st == ZT_ERR_PARSE && rb.short_read)
        st = zt_fail(err, ZT_ERR_PARSE, "forest file '%s' is truncated (%zu bytes)", path, n);
    free(data);
    if (st == ZT_OK)
        f->loaded = 1;
    return st;
}

uint64_t forest_memory(const zone_forest *f)
{
    const surface_nodes *sn = &f->sn;
    uint64_t b = (uint64_t)f->zone_count * sizeof(zone);
    b += (uint64_t)sn->node_count * (6 * sizeof(float) + sizeof(int32_t) + 1);
    b += (uint64_t)sn->prim_count * sizeof(node_prim);
    b += (uint64_t)f->map_levels * sn->node_count * 3 * sizeof(float);
    b += (uint64_t)f->occ.node_count * sizeof(occ_node) + (uint64_t)f->occ.prim_count * 4;
    if (f->portals.of_prim)
        b += (uint64_t)f->portals.count * sizeof(sky_portal) +
             (uint64_t)f->portals.prim_count * sizeof(int32_t);
    if (f->c)
        b += (uint64_t)f->map_levels * sn->node_count * 3 * sizeof(float);
    if (f->caustic)
        b += (uint64_t)f->map_levels * sn->node_count * 3 * sizeof(float) +
             (uint64_t)f->photons.count * (sizeof(zone_photon) + 1) +
             (uint64_t)f->photons.group_count * sizeof(photon_group);
    return b;
}
