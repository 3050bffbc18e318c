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

static uint32_t root(uint32_t *up, uint32_t v)
{
    while (up[v] != v) {
        up[v] = up[up[v]];
        v = up[v];
    }
    return v;
}

/* For n triangles, their corners' positions in pos (9 floats each): which
 * lie on a closed piece, into closed[t].  Corners at one position are one
 * vertex; triangles sharing a vertex are one piece; a piece is closed when
 * each of its directed edges appears once and its reverse once.  0 when
 * out of memory. */
static int close_pieces(const float *pos, size_t n, uint8_t *closed)
{
    size_t nc = 3 * n;
    corner *c = malloc((nc ? nc : 1) * sizeof *c);
    uint32_t *id = malloc((nc ? nc : 1) * sizeof *id);
    uint32_t *up = malloc((nc ? nc : 1) * sizeof *up);
    uint64_t *edge = malloc((nc ? nc : 1) * sizeof *edge);
    uint8_t *bad = calloc(nc ? nc : 1, 1);
    int ok = c && id && up && edge && bad;
    if (ok) {
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
        for (uint32_t v = 0; v <= next && v < nc; v++)
            up[v] = v;
        for (size_t t = 0; t < n; t++)
            for (int k = 1; k < 3; k++) {
                uint32_t a = root(up, id[3 * t]), b = root(up, id[3 * t + k]);
                if (a != b)
                    up[a < b ? b : a] = a < b ? a : b;
            }
        for (size_t t = 0; t < n; t++)
            for (int k = 0; k < 3; k++) {
                uint64_t a = id[3 * t + k], b = id[3 * t + (k + 1) % 3];
                edge[3 * t + k] = a << 32 | b;
            }
        qsort(edge, nc, sizeof *edge, u64_cmp);
        for (size_t i = 0; i < nc; i++) {
            uint64_t a = edge[i] >> 32, b = edge[i] & 0xffffffffu, rev = b << 32 | a;
            if (a == b || (i > 0 && edge[i] == edge[i - 1]) ||
                (i + 1 < nc && edge[i] == edge[i + 1]) ||
                !bsearch(&rev, edge, nc, sizeof *edge, u64_cmp))
                bad[root(up, (uint32_t)a)] = 1;
        }
        for (size_t t = 0; t < n; t++)
            closed[t] = !bad[root(up, id[3 * t])];
    }
    free(c);
    free(id);
    free(up);
    free(edge);
    free(bad);
    return ok;
}

int closed_surfaces_find(closed_surfaces *cs, const zt_scene *sc, const rscene *rs)
{
    int prims = rs->part_count;
    for (int mi = 0; mi < rs->mesh_count; mi++) {
        int end = rs->meshes[mi].prim_base + rs->meshes[mi].m->triangle_count;
        prims = end > prims ? end : prims;
    }
    cs->prim = calloc((size_t)prims + 1, 1);
    /* A thing's triangle parts, grouped by object in one pass: first[o] ..
     * first[o + 1] in `of`. */
    int *first = calloc((size_t)sc->object_count + 1, sizeof *first);
    int *fill = malloc(((size_t)sc->object_count + 1) * sizeof *fill);
    int *of = malloc(((size_t)rs->part_count + 1) * sizeof *of);
    int ok = cs->prim && first && fill && of;
    for (int i = 0; ok && i < rs->part_count; i++)
        if (sc->parts[i].shape == SHAPE_TRIANGLE)
            first[sc->parts[i].object + 1]++;
    for (int o = 0; ok && o < sc->object_count; o++) {
        first[o + 1] += first[o];
        fill[o] = first[o];
    }
    for (int i = 0; ok && i < rs->part_count; i++)
        if (sc->parts[i].shape == SHAPE_TRIANGLE)
            of[fill[sc->parts[i].object]++] = i;
    for (int o = 0; ok && o < sc->object_count; o++) {
        int n = first[o + 1] - first[o];
        if (n < 4)
            continue;
        float *pos = malloc((size_t)n * 9 * sizeof *pos);
        uint8_t *closed = malloc((size_t)n);
        ok = pos && closed;
        for (int t = 0; ok && t < n; t++) {
            const part *p = &sc->parts[of[first[o] + t]];
            for (int k = 0; k < 3; k++) {
                pos[9 * t + 3 * k] = (float)p->p[k].x;
                pos[9 * t + 3 * k + 1] = (float)p->p[k].y;
                pos[9 * t + 3 * k + 2] = (float)p->p[k].z;
            }
        }
        ok = ok && close_pieces(pos, (size_t)n, closed);
        for (int t = 0; ok && t < n; t++)
            cs->prim[of[first[o] + t]] = closed[t];
        free(pos);
        free(closed);
    }
    free(first);
    free(fill);
    free(of);
    /* A mesh's, piece by piece. */
    for (int mi = 0; ok && mi < rs->mesh_count; mi++) {
        const mesh *m = rs->meshes[mi].m;
        size_t n = (size_t)m->triangle_count;
        float *pos = malloc((n ? n : 1) * 9 * sizeof *pos);
        ok = pos != NULL;
        for (size_t t = 0; ok && t < n; t++)
            for (int k = 0; k < 3; k++)
                memcpy(&pos[9 * t + 3 * k], m->position + 3 * (size_t)m->index[3 * t + k],
                       3 * sizeof *pos);
        ok = ok && close_pieces(pos, n, cs->prim + rs->meshes[mi].prim_base);
        free(pos);
    }
    if (!ok) {
        /* Without memory none is closed: nodes live as they did. */
        closed_surfaces_free(cs);
        return 0;
    }
    return 1;
}

int closed_surfaces_has(const closed_surfaces *cs, int prim)
{
    return cs->prim && prim >= 0 && cs->prim[prim];
}

void closed_surfaces_free(closed_surfaces *cs)
{
    free(cs->prim);
    cs->prim = NULL;
}
