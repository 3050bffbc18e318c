/* Closed surfaces (closed_surfaces.h). */
#include "zone/phase_one/closed_surfaces.h"

#include <stdlib.h>
#include <string.h>

#include "render/prim.h"

/* One corner: its position's bits and where it came from. */
typedef struct corner {
    uint32_t key[3];
    uint32_t index;
} corner;

static int corner_cmp(const void *a, const void *b)
{
    const corner *p = a, *q = b;
    for (int k = 0; k < 3; k++)
        if (p->key[k] != q->key[k])
            return p->key[k] < q->key[k] ? -1 : 1;
    return 0;
}

static int u64_cmp(const void *a, const void *b)
{
    uint64_t p = *(const uint64_t *)a, q = *(const uint64_t *)b;
    return p < q ? -1 : p > q;
}

/* Whether n triangles, their corners' positions in pos (9 floats each),
 * close: corners at one position are one vertex, and every directed edge
 * appears once with its reverse once.  -1 when out of memory. */
static int triangles_close(const float *pos, size_t n)
{
    if (n < 4)
        return 0;
    size_t nc = 3 * n;
    corner *c = malloc(nc * sizeof *c);
    uint32_t *id = malloc(nc * sizeof *id);
    uint64_t *edge = malloc(nc * sizeof *edge);
    int closed = -1;
    if (!c || !id || !edge)
        goto done;
    for (size_t i = 0; i < nc; i++) {
        /* (+0 and -0 are one position.) */
        for (int k = 0; k < 3; k++) {
            float v = pos[3 * i + k] + 0.0f;
            memcpy(&c[i].key[k], &v, sizeof v);
        }
        c[i].index = (uint32_t)i;
    }
    qsort(c, nc, sizeof *c, corner_cmp);
    uint32_t next = 0;
    for (size_t i = 0; i < nc; i++) {
        if (i > 0 && corner_cmp(&c[i], &c[i - 1]) != 0)
            next++;
        id[c[i].index] = next;
    }
    for (size_t t = 0; t < n; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = id[3 * t + k], b = id[3 * t + (k + 1) % 3];
            edge[3 * t + k] = a << 32 | b;
        }
    qsort(edge, nc, sizeof *edge, u64_cmp);
    closed = 1;
    for (size_t i = 0; i < nc && closed; i++) {
        uint64_t a = edge[i] >> 32, b = edge[i] & 0xffffffffu, rev = b << 32 | a;
        if (a == b || (i > 0 && edge[i] == edge[i - 1]) ||
            !bsearch(&rev, edge, nc, sizeof *edge, u64_cmp))
            closed = 0;
    }
done:
    free(c);
    free(id);
    free(edge);
    return closed;
}

int closed_surfaces_find(closed_surfaces *cs, const zt_scene *sc, const rscene *rs)
{
    cs->object = calloc((size_t)sc->object_count + 1, 1);
    cs->mesh = calloc((size_t)rs->mesh_count + 1, 1);
    int *count = calloc((size_t)sc->object_count + 1, sizeof *count);
    int ok = cs->object && cs->mesh && count;
    for (int i = 0; ok && i < sc->part_count; i++)
        if (sc->parts[i].shape == SHAPE_TRIANGLE)
            count[sc->parts[i].object]++;
    for (int o = 0; ok && o < sc->object_count; o++) {
        if (count[o] < 4)
            continue;
        float *pos = malloc((size_t)count[o] * 9 * sizeof *pos);
        if (!pos) {
            ok = 0;
            break;
        }
        size_t n = 0;
        for (int i = 0; i < sc->part_count; i++) {
            const part *p = &sc->parts[i];
            if (p->shape != SHAPE_TRIANGLE || p->object != o)
                continue;
            for (int k = 0; k < 3; k++) {
                pos[9 * n + 3 * k] = (float)p->p[k].x;
                pos[9 * n + 3 * k + 1] = (float)p->p[k].y;
                pos[9 * n + 3 * k + 2] = (float)p->p[k].z;
            }
            n++;
        }
        int c = triangles_close(pos, n);
        free(pos);
        ok = c >= 0;
        cs->object[o] = c > 0;
    }
    for (int mi = 0; ok && mi < rs->mesh_count; mi++) {
        const mesh *m = rs->meshes[mi].m;
        size_t n = (size_t)m->triangle_count;
        float *pos = malloc((n ? n : 1) * 9 * sizeof *pos);
        if (!pos) {
            ok = 0;
            break;
        }
        for (size_t t = 0; t < n; t++)
            for (int k = 0; k < 3; k++)
                memcpy(&pos[9 * t + 3 * k], m->position + 3 * (size_t)m->index[3 * t + k],
                       3 * sizeof *pos);
        int c = triangles_close(pos, n);
        free(pos);
        ok = c >= 0;
        cs->mesh[mi] = c > 0;
    }
    free(count);
    if (!ok) {
        /* Without memory none is closed: nodes live as they did. */
        closed_surfaces_free(cs);
        return 0;
    }
    return 1;
}

int closed_surfaces_has(const closed_surfaces *cs, const zt_scene *sc, const rscene *rs, int prim)
{
    if (!cs->object || !cs->mesh || prim < 0)
        return 0;
    if (prim < rs->part_count)
        return cs->object[sc->parts[prim].object];
    return cs->mesh[rs_mesh_of(rs, prim) - rs->meshes];
}

void closed_surfaces_free(closed_surfaces *cs)
{
    free(cs->object);
    free(cs->mesh);
    cs->object = cs->mesh = NULL;
}
