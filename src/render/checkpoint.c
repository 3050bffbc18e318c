/* Checkpoint files.  Little-endian throughout, doubles as their IEEE-754
 * bits, so a checkpoint moves between machines and resumes bit for bit:
 *
 *   "ZTCHECK1"            magic and format version
 *   u64 key               checkpoint_key
 *   u32 width, height     the image
 *   u32 samples           per pixel in the sums
 *   u32 0                 reserved
 *   f64 sums[height][width][3]
 *   u64 FNV-1a of everything before it
 */
#include "render/checkpoint.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/atomic_file.h"
#include "render/render_internal.h"
#include "scene/scene_hash.h"
#include "util/error.h"
#include "util/fnv1a.h"

static const char MAGIC[8] = {'Z', 'T', 'C', 'H', 'E', 'C', 'K', '1'};
#define HEADER_BYTES 32

uint64_t checkpoint_key(const zt_scene *scene, const zt_render_options *o)
{
    fnv1a h = {FNV1A_START};
    fnv_u64(&h, scene_hash(scene));
    const zt_camera *c = &scene->camera;
    for (int k = 0; k < 3; k++)
        fnv_f64(&h, c->viewpoint[k]);
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            fnv_f64(&h, c->screen[i][k]);
    fnv_i32(&h, c->width);
    fnv_i32(&h, c->height);
    fnv_u64(&h, o->seed);
    fnv_i32(&h, o->level >= 0 ? o->level : 0);
    fnv_i32(&h, o->level >= 0 ? o->level : o->depth);
    int off[ZT_MAX_LIGHTS_OFF], n = render_lights_off_sorted(o, off);
    for (int i = 0; i < n; i++)
        fnv_i32(&h, off[i]);
    return h.h;
}

static void put_u32(unsigned char *b, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static void put_u64(unsigned char *b, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t get_u32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static uint64_t get_u64(const unsigned char *b)
{
    return (uint64_t)get_u32(b) | (uint64_t)get_u32(b + 4) << 32;
}

static void header(unsigned char *b, uint64_t key, int width, int height, int samples)
{
    memcpy(b, MAGIC, 8);
    put_u64(b + 8, key);
    put_u32(b + 16, (uint32_t)width);
    put_u32(b + 20, (uint32_t)height);
    put_u32(b + 24, (uint32_t)samples);
    put_u32(b + 28, 0);
}

/* The sums go out in blocks of this many doubles. */
#define BLOCK 4096

zt_status checkpoint_write(const char *path, uint64_t key, int width, int height,
                           int samples, const double *sums, zt_error *err)
{
    atomic_file af;
    zt_status st = atomic_file_open(&af, path, err);
    if (st != ZT_OK)
        return st;
    unsigned char head[HEADER_BYTES], block[8 * BLOCK];
    header(head, key, width, height, samples);
    fnv1a h = {FNV1A_START};
    fnv_bytes(&h, head, sizeof head);
    int ok = fwrite(head, 1, sizeof head, af.stream) == sizeof head;
    size_t n = 3 * (size_t)width * (size_t)height;
    for (size_t i = 0; ok && i < n; i += BLOCK) {
        size_t m = n - i < BLOCK ? n - i : BLOCK;
        for (size_t j = 0; j < m; j++) {
            uint64_t u;
            memcpy(&u, &sums[i + j], 8);
            put_u64(block + 8 * j, u);
        }
        fnv_bytes(&h, block, 8 * m);
        ok = fwrite(block, 1, 8 * m, af.stream) == 8 * m;
    }
    unsigned char tail[8];
    put_u64(tail, h.h);
    if (ok)
        ok = fwrite(tail, 1, 8, af.stream) == 8;
    if (!ok) {
        int e = errno;
        atomic_file_abort(&af);
        return zt_fail(err, ZT_ERR_WRITE, "cannot write checkpoint '%s': %s", path, strerror(e));
    }
    return atomic_file_commit(&af, err);
}

static zt_status bad(zt_error *err, const char *path, const char *why)
{
    return zt_fail(err, ZT_ERR_PARSE, "checkpoint '%s': %s", path, why);
}

zt_status checkpoint_read(const char *path, uint64_t key, int width, int height,
                          int max_samples, double *sums, int *samples, zt_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return zt_fail(err, ZT_ERR_READ, "cannot open checkpoint '%s': %s", path, strerror(errno));
    unsigned char head[HEADER_BYTES], block[8 * BLOCK];
    zt_status st = ZT_OK;
    if (fread(head, 1, sizeof head, f) != sizeof head || memcmp(head, MAGIC, 4) != 0) {
        st = bad(err, path, "not a zonetrace checkpoint (or cut short before its header)");
        goto done;
    }
    if (memcmp(head, MAGIC, 8) != 0) {
        st = bad(err, path, "a checkpoint format this version does not read");
        goto done;
    }
    uint32_t w = get_u32(head + 16), hgt = get_u32(head + 20), s = get_u32(head + 24);
    if (w != (uint32_t)width || hgt != (uint32_t)height) {
        st = zt_fail(err, ZT_ERR_PARSE, "checkpoint '%s' is of a %ux%u image, this render is %dx%d",
                     path, w, hgt, width, height);
        goto done;
    }
    if (get_u64(head + 8) != key) {
        st = bad(err, path, "made for another render (the scene, camera, seed, depth, level "
                            "or lights switched off differ)");
        goto done;
    }
    if (s < 1 || s > (uint32_t)max_samples) {
        st = zt_fail(err, ZT_ERR_PARSE, "checkpoint '%s' holds %u samples per pixel, more than "
                     "the %d asked for", path, s, max_samples);
        goto done;
    }
    fnv1a h = {FNV1A_START};
    fnv_bytes(&h, head, sizeof head);
    size_t n = 3 * (size_t)width * (size_t)height;
    for (size_t i = 0; i < n; i += BLOCK) {
        size_t m = n - i < BLOCK ? n - i : BLOCK;
        if (fread(block, 1, 8 * m, f) != 8 * m) {
            st = bad(err, path, "cut short (truncated)");
            goto done;
        }
        fnv_bytes(&h, block, 8 * m);
        for (size_t j = 0; j < m; j++) {
            uint64_t u = get_u64(block + 8 * j);
            memcpy(&sums[i + j], &u, 8);
        }
    }
    unsigned char tail[9];
    size_t got = fread(tail, 1, 9, f);
    if (got < 8) {
        st = bad(err, path, "cut short (truncated)");
        goto done;
    }
    if (got > 8) {
        st = bad(err, path, "has bytes after its end");
        goto done;
    }
    if (get_u64(tail) != h.h) {
        st = bad(err, path, "corrupt (its checksum does not match)");
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        if (!(sums[i] >= 0 && sums[i] < 1e300)) {
            st = bad(err, path, "corrupt (a sum that is negative or not finite)");
            goto done;
        }
    *samples = (int)s;
done:
    fclose(f);
    return st;
}
