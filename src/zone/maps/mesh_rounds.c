/* Coarse and fine vertex nodes of a mesh (mesh_rounds.h). */
#include "zone/maps/mesh_rounds.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/mesh.h"
#include "zone/maps/mesh_sheet.h"
#include "util/vec3.h"

#define PI 3.14159265358979323846

/* Rounds 0 .. ROUNDS - 2 spread vertices at spacing FIRST_SPACING x h,
 * halved each round (2h down to h/32: the engine room's small parts are a
 * few hundredths of h across); the last round takes the rest. */
#define ROUNDS MESH_ROUNDS
#define FIRST_SPACING 2.0
/* Supports are looked for within this many spacings of the round before. */
#define REACH 3.0
/* The nearest support in each of SECTORS directions around the node; at
 * least MIN_SUPPORTS of them, with no gap between neighbouring ones wider
 * than MAX_GAP (radians: the node inside their hull, no extrapolation). */
#define SECTORS 8
#define MIN_SUPPORTS 3
#define MAX_GAP 3.1
/* One sheet of surface: the walk goes through vertices whose normals are
 * within acos(SAME_NORMAL) of the node's; a support lies within FLAT x its
 * distance of the node's tangent plane and the node of its. */
#define SAME_NORMAL 0.707
#define FLAT 0.35

static double dist2(const float *a, const float *b)
{
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}

static double dotf(const float *a, const float *b)
{
    return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
}

typedef struct cand {
    double d2, angle;
    int32_t u;
} cand;

static int by_distance(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    if (x->d2 != y->d2)
        return x->d2 < y->d2 ? -1 : 1;
    return (x->u > y->u) - (x->u < y->u);
}

static int by_angle(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    return (x->angle > y->angle) - (x->angle < y->angle);
}

/* The tangent frame the sectors and the fit are taken in. */
static void tangents(const float *n, double t[3], double b[3])
{
    vec3 tt, bb;
    v3_frame(v3(n[0], n[1], n[2]), &tt, &bb);
    t[0] = tt.x, t[1] = tt.y, t[2] = tt.z;
    b[0] = bb.x, b[1] = bb.y, b[2] = bb.z;
}

/* Vertex v's supports: vertices of rounds before r on its sheet within
 * `reach`, near its tangent plane, the nearest in each of SECTORS
 * directions around v, written to out.  Returns how many, 0 when they do
 * not surround v. */
static int find_supports(const mesh_adjacency *adj, const float *pos, const float *nrm,
                         const uint8_t *live, const uint8_t *assigned, int32_t base, int32_t v,
                         int r, double reach, sheet_walk *w, int32_t *out)
{
    const float *p = pos + 3 * (size_t)v, *n = nrm + 3 * (size_t)v;
    double t[3], b[3];
    tangents(n, t, b);
    cand c[SECTORS];
    int filled[SECTORS] = {0};
    int reached = mesh_sheet_walk(adj, pos, nrm, v, reach, SAME_NORMAL, NULL, w);
    for (int j = 1; j < reached; j++) {
        int32_t x = w->queue[j];
        const float *q = pos + 3 * (size_t)x, *m = nrm + 3 * (size_t)x;
        double d2 = dist2(q, p);
        if (assigned[x] >= r || !live[base + x] || !(d2 > 0))
            continue;
        float d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double dl = sqrt(d2);
        if (fabs(dotf(n, d)) > FLAT * dl || fabs(dotf(m, d)) > FLAT * dl)
            continue;
        double angle = atan2(d[0] * b[0] + d[1] * b[1] + d[2] * b[2],
                             d[0] * t[0] + d[1] * t[1] + d[2] * t[2]);
        int s = (int)floor((angle + PI) / (2 * PI) * SECTORS);
        s = s < 0 ? 0 : s >= SECTORS ? SECTORS - 1 : s;
        cand k = {d2, angle, x};
        if (!filled[s] || by_distance(&k, &c[s]) < 0)
            c[s] = k;
        filled[s] = 1;
    }
    cand taken[SECTORS];
    int nt = 0;
    for (int s = 0; s < SECTORS; s++)
        if (filled[s])
            taken[nt++] = c[s];
    if (nt < MIN_SUPPORTS)
        return 0;
    qsort(taken, (size_t)nt, sizeof *taken, by_angle);
    for (int i = 0; i < nt; i++) {
        double next = i + 1 < nt ? taken[i + 1].angle : taken[0].angle + 2 * PI;
        if (next - taken[i].angle > MAX_GAP)
            return 0;
    }
    for (int i = 0; i < nt; i++)
        out[i] = base + taken[i].u;
    return nt;
}

/* Whether a vertex already taken lies within r of v on its sheet. */
static int crowded(const mesh_adjacency *adj, const float *pos, const float *nrm,
                   const uint8_t *assigned, int32_t v, double r, sheet_walk *w)
{
    return mesh_sheet_walk(adj, pos, nrm, v, r, SAME_NORMAL, assigned, w) < 0;
}

/* One side of one mesh: nodes base .. base + count - 1. */
static int build_side(mesh_rounds *mr, const surface_nodes *sn, const mesh *m, int32_t base,
                      int32_t *slots, uint8_t *nslots, int threads)
{
    int count = m->vertex_count;
    const float *pos = sn->pos + 3 * (size_t)base, *nrm = sn->nrm + 3 * (size_t)base;
    uint8_t *round = mr->round + base;
    uint8_t *assigned = malloc((size_t)count + 1);
    if (!assigned)
        return 0;
    memset(assigned, 0xff, (size_t)count + 1);
    /* The spread, round by round, in vertex order (a fixed choice). */
    mesh_adjacency adj;
    sheet_walk w0;
    int ok = mesh_adjacency_build(&adj, m);
    ok = sheet_walk_init(&w0, count) && ok;
    double spacing = FIRST_SPACING * sn->h;
    for (int r = 0; r < ROUNDS - 1 && ok; r++, spacing *= 0.5)
        for (int32_t v = 0; v < count; v++)
            if (assigned[v] == 0xff && sn->live[base + v] &&
                !crowded(&adj, pos, nrm, assigned, v, spacing, &w0))
                assigned[v] = (uint8_t)r;
    sheet_walk_free(&w0);
    for (int32_t v = 0; v < count; v++)
        if (assigned[v] == 0xff && sn->live[base + v])
            assigned[v] = ROUNDS - 1;
    /* Supports from the rounds before, round by round. */
    spacing = FIRST_SPACING * sn->h;
    for (int r = 1; r < ROUNDS && ok; r++, spacing *= 0.5) {
        double reach = REACH * spacing; /* the round before's spacing */
#pragma omp parallel num_threads(threads)
        {
            sheet_walk w;
            int have = sheet_walk_init(&w, count);
            if (!have) {
#pragma omp atomic write
                ok = 0;
            }
#pragma omp for schedule(dynamic, 256)
            for (int32_t v = 0; v < count; v++) {
                if (!have || assigned[v] != r)
                    continue;
                int32_t *out = slots + (size_t)(base + v) * SECTORS;
                int k = find_supports(&adj, pos, nrm, sn->live, assigned, base, v, r, reach, &w,
                                      out);
                nslots[base + v] = (uint8_t)k;
                round[v] = k ? (uint8_t)r : 0;
            }
            sheet_walk_free(&w);
        }
    }
    mesh_adjacency_free(&adj);
    free(assigned);
    return ok;
}

int mesh_rounds_build(mesh_rounds *mr, const surface_nodes *sn, const rscene *rs, int threads)
{
    memset(mr, 0, sizeof *mr);
    int any = 0;
    for (int k = 0; k < sn->mesh_count; k++)
        any |= sn->vertex_first[k] >= 0;
    if (!any)
        return 1;
    size_t nc = (size_t)sn->node_count;
    mr->round = calloc(nc + 1, 1);
    mr->first = calloc(nc + 1, sizeof *mr->first);
    int32_t *slots = malloc((nc + 1) * SECTORS * sizeof *slots);
    uint8_t *nslots = calloc(nc + 1, 1);
    int ok = mr->round && mr->first && slots && nslots;
    for (int k = 0; k < sn->mesh_count && ok; k++) {
        if (sn->vertex_first[k] < 0)
            continue;
        const rs_mesh *mm = &rs->meshes[k];
        int vc = mm->m->vertex_count, sides = mm->culled ? 1 : 2;
        for (int s = 0; s < sides && ok; s++)
            ok = build_side(mr, sn, mm->m, sn->vertex_first[k] + s * vc, slots, nslots, threads);
    }
    size_t total = 0;
    for (size_t k = 0; ok && k < nc; k++) {
        mr->first[k] = (int32_t)total;
        total += mr->round[k] ? nslots[k] : 0;
    }
    if (ok) {
        mr->first[nc] = (int32_t)total;
        mr->support = malloc((total + 1) * sizeof *mr->support);
        ok = mr->support != NULL;
    }
    for (size_t k = 0; ok && k < nc; k++)
        if (mr->round[k])
            memcpy(mr->support + mr->first[k], slots + k * SECTORS,
                   nslots[k] * sizeof *mr->support);
    free(slots);
    free(nslots);
    if (!ok)
        mesh_rounds_free(mr);
    return ok;
}

void mesh_rounds_free(mesh_rounds *mr)
{
    free(mr->round);
    free(mr->first);
    free(mr->support);
    memset(mr, 0, sizeof *mr);
}

int mesh_rounds_read(const mesh_rounds *mr, const surface_nodes *sn, const float *v, int32_t k,
                     double smooth, float out[3])
{
    int32_t a = mr->first[k], m = mr->first[k + 1] - a;
    const int32_t *s = mr->support + a;
    const float *p = sn->pos + 3 * (size_t)k, *n = sn->nrm + 3 * (size_t)k;
    double t[3], b[3];
    tangents(n, t, b);
    /* Weighted least squares for e = c0 + c1 u + c2 w in the tangent
     * plane, weights 1 / distance^2 (the near supports count most). */
    double row[SECTORS][3], wt[SECTORS], M[3][3] = {{0}}, rhs[3][3] = {{0}};
    for (int i = 0; i < m; i++) {
        const float *q = sn->pos + 3 * (size_t)s[i];
        double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        row[i][0] = 1;
        row[i][1] = d[0] * t[0] + d[1] * t[1] + d[2] * t[2];
        row[i][2] = d[0] * b[0] + d[1] * b[1] + d[2] * b[2];
        wt[i] = 1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int x = 0; x < 3; x++) {
            for (int y = 0; y < 3; y++)
                M[x][y] += wt[i] * row[i][x] * row[i][y];
            for (int ch = 0; ch < 3; ch++)
                rhs[ch][x] += wt[i] * row[i][x] * v[3 * (size_t)s[i] + ch];
        }
    }
    /* Cramer's rule on the 3 x 3 normal equations. */
    double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                 M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                 M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
    double scale = M[0][0] * M[1][1] * M[2][2];
    if (!(fabs(det) > 1e-9 * fabs(scale)))
        return 0;
    double inv[3][3];
    for (int x = 0; x < 3; x++)
        for (int y = 0; y < 3; y++) {
            int x1 = (y + 1) % 3, x2 = (y + 2) % 3, y1 = (x + 1) % 3, y2 = (x + 2) % 3;
            inv[x][y] = (M[x1][y1] * M[x2][y2] - M[x1][y2] * M[x2][y1]) / det;
        }
    for (int ch = 0; ch < 3; ch++) {
        double c[3], top = 0, lo = INFINITY, hi = -INFINITY;
        for (int x = 0; x < 3; x++)
            c[x] = inv[x][0] * rhs[ch][0] + inv[x][1] * rhs[ch][1] + inv[x][2] * rhs[ch][2];
        for (int i = 0; i < m; i++) {
            double e = v[3 * (size_t)s[i] + ch];
            top = fmax(top, e);
            lo = fmin(lo, e);
            hi = fmax(hi, e);
        }
        for (int i = 0; i < m; i++) {
            double fit = c[0] + c[1] * row[i][1] + c[2] * row[i][2];
            if (fabs(fit - v[3 * (size_t)s[i] + ch]) > smooth * top)
                return 0;
        }
        out[ch] = (float)fmin(hi, fmax(lo, c[0]));
    }
    return 1;
}
