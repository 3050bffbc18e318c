/* A mesh's sheets of surface (mesh_sheet.h). */
#include "zone/maps/mesh_sheet.h"

#include <stdlib.h>
#include <string.h>

/* Vertex indices ordered by position (their coordinates' bits; +0 and -0
 * are one), ties by index. */
typedef struct vertex_key {
    uint32_t key[3];
    int32_t v;
} vertex_key;

static int vertex_key_cmp(const void *a, const void *b)
{
    const vertex_key *p = a, *q = b;
    for (int k = 0; k < 3; k++)
        if (p->key[k] != q->key[k])
            return p->key[k] < q->key[k] ? -1 : 1;
    return (p->v > q->v) - (p->v < q->v);
}

/* For each vertex, the next one at the same position (a ring), or itself
 * when it is alone there: files split a vertex wherever its normal or
 * texture coordinates change (every corner of a faceted model, a seam of
 * its texture), and the copies are one point of the surface.  NULL when
 * out of memory. */
static int32_t *position_rings(const mesh *m)
{
    int vc = m->vertex_count;
    vertex_key *k = malloc(((size_t)vc + 1) * sizeof *k);
    int32_t *ring = malloc(((size_t)vc + 1) * sizeof *ring);
    if (!k || !ring) {
        free(k);
        free(ring);
        return NULL;
    }
    for (int v = 0; v < vc; v++) {
        for (int c = 0; c < 3; c++) {
            float x = m->position[3 * (size_t)v + c] + 0.0f;
            memcpy(&k[v].key[c], &x, sizeof x);
        }
        k[v].v = v;
    }
    qsort(k, (size_t)vc, sizeof *k, vertex_key_cmp);
    for (int i = 0; i < vc;) {
        int j = i + 1;
        while (j < vc && !memcmp(k[j].key, k[i].key, sizeof k[i].key))
            j++;
        for (int a = i; a < j; a++)
            ring[k[a].v] = k[a + 1 < j ? a + 1 : i].v;
        i = j;
    }
    free(k);
    return ring;
}

int mesh_adjacency_build(mesh_adjacency *a, const mesh *m)
{
    int vc = m->vertex_count;
    a->first = calloc((size_t)vc + 2, sizeof *a->first);
    int32_t *ring = position_rings(m);
    if (!a->first || !ring) {
        free(ring);
        a->list = NULL;
        return 0;
    }
    /* A vertex's neighbours: the other ends of its edges, and its copies
     * at the same position. */
    size_t copies = 0;
    for (int v = 0; v < vc; v++)
        for (int32_t u = ring[v]; u != v; u = ring[u]) {
            a->first[v + 1]++;
            copies++;
        }
    a->list = malloc(((size_t)m->triangle_count * 6 + copies + 1) * sizeof *a->list);
    if (!a->list) {
        free(ring);
        return 0;
    }
    for (int t = 0; t < m->triangle_count; t++)
        for (int e = 0; e < 3; e++)
            a->first[m->index[3 * t + e] + 1] += 2;
    for (int v = 0; v < vc; v++)
        a->first[v + 1] += a->first[v];
    int32_t *fill = malloc(((size_t)vc + 1) * sizeof *fill);
    if (!fill) {
        free(ring);
        return 0;
    }
    memcpy(fill, a->first, (size_t)vc * sizeof *fill);
    for (int v = 0; v < vc; v++)
        for (int32_t u = ring[v]; u != v; u = ring[u])
            a->list[fill[v]++] = u;
    free(ring);
    for (int t = 0; t < m->triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t v = m->index[3 * t + e];
            a->list[fill[v]++] = (int32_t)m->index[3 * t + (e + 1) % 3];
            a->list[fill[v]++] = (int32_t)m->index[3 * t + (e + 2) % 3];
        }
    free(fill);
    return 1;
}

void mesh_adjacency_free(mesh_adjacency *a)
{
    free(a->first);
    free(a->list);
    a->first = a->list = NULL;
}

int sheet_walk_init(sheet_walk *w, int32_t count)
{
    w->stamp = calloc((size_t)count + 1, sizeof *w->stamp);
    w->queue = malloc(((size_t)count + 1) * sizeof *w->queue);
    w->id = 0;
    return w->stamp && w->queue;
}

void sheet_walk_free(sheet_walk *w)
{
    free(w->stamp);
    free(w->queue);
    w->stamp = w->queue = NULL;
}

static double dist2(const float *a, const float *b)
{
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}

static double dotf(const float *a, const float *b)
{
    return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
}

int mesh_sheet_walk(const mesh_adjacency *adj, const float *pos, const float *nrm, int32_t v,
                    double reach, double min_cos, const uint8_t *taken, sheet_walk *w)
{
    const float *p = pos + 3 * (size_t)v, *n = nrm + 3 * (size_t)v;
    int head = 0, tail = 0;
    w->id++;
    w->stamp[v] = w->id;
    w->queue[tail++] = v;
    while (head < tail) {
        int32_t u = w->queue[head++];
        for (int32_t i = adj->first[u]; i < adj->first[u + 1]; i++) {
            int32_t x = adj->list[i];
            if (w->stamp[x] == w->id)
                continue;
            w->stamp[x] = w->id;
            if (dist2(pos + 3 * (size_t)x, p) > reach * reach ||
                dotf(n, nrm + 3 * (size_t)x) < min_cos)
                continue;
            if (taken && taken[x] != 0xff)
                return -1;
            w->queue[tail++] = x;
        }
    }
    return tail;
}
