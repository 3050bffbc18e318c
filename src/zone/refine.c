/* Refinement of the maps where a bilinear read of texel values cannot
 * follow the light: along the lines where triangles pierce each other and
 * where neighbouring texels differ much.  There the irradiance is computed
 * exactly (E_0 as its texels are, higher levels by the transfer) at the
 * centres of fine cells, and what the bilinear read misses is kept as a
 * detail window (zone_maps.h) that every read adds.  The
 * texels stay as they are; the next level's transfer sends from their
 * means, and from the fine cells where a receiver is close (transfer.c).
 * Pixels read E_1 and up, so E_0's windows go once all levels are built.
 *
 * Only maps whose irradiance is all transfer (no gathers, images in
 * spheres or caustics: scenes of flat diffuse surfaces) are refined, so
 * the exact value and the texels' are the same quantity. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"
#include "zone/refine.h"
#include "zone/transfer.h"

/* Luminance-like weight, only to compare texels. */
static double texel_level(const float *v) { return v[0] + v[1] + v[2]; }

/* Marks the texels of one level and side to refine (1) and returns how
 * many; `mark` has nu x nv entries.  A texel is rough where a crossing
 * cuts it, a neighbour differs by more than `contrast`, or its second
 * difference along an axis exceeds `kink` (shares of the largest). */
static int mark_rough(const part_map *m, int level, int side, double contrast, double kink,
                      unsigned char *mark)
{
    const map_layout *l = &m->layout;
    int nu = l->nu, nv = l->nv, count = 0;
    const float *wt = m->weight[0] + (size_t)side * nv * nu;
    const float *v = m->texels + ((size_t)level * l->sides + side) * (size_t)nv * nu * 3;
    unsigned char *core = calloc((size_t)nu * nv, 1);
    if (!core)
        return -1;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            size_t k = (size_t)j * nu + i;
            /* Far out on a plane the texels widen: steps there are
             * their growth, and matter little. */
            if (wt[k] <= 0 || i < l->au.k0 || i >= l->au.k1 || j < l->av.k0 || j >= l->av.k1)
                continue;
            int rough = m->crossings && m->cut[k] >= 0;
            double a = texel_level(v + 3 * k);
            static const int step_i[4] = {1, -1, 0, 0}, step_j[4] = {0, 0, 1, -1};
            for (int q = 0; q < 4 && !rough; q++) {
                int i2 = i + step_i[q], j2 = j + step_j[q];
                if (i2 < 0 || j2 < 0 || i2 >= nu || j2 >= nv)
                    continue;
                size_t k2 = (size_t)j2 * nu + i2;
                if (wt[k2] <= 0)
                    continue;
                double b = texel_level(v + 3 * k2);
                rough = fabs(a - b) > contrast * fmax(a, b);
            }
            /* A kink bends the texels without a step: where a receiver
             * crosses another surface's plane, that surface's light fades
             * to grazing and rises again on its other face. */
            for (int q = 0; q < 2 && !rough && kink > 0; q++) {
                int ia = i - (q == 0), ib = i + (q == 0), ja = j - (q == 1), jb = j + (q == 1);
                if (ia < 0 || ja < 0 || ib >= nu || jb >= nv)
                    continue;
                size_t ka = (size_t)ja * nu + ia, kb = (size_t)jb * nu + ib;
                if (wt[ka] <= 0 || wt[kb] <= 0)
                    continue;
                double b = texel_level(v + 3 * ka), c = texel_level(v + 3 * kb);
                rough = fabs(b + c - 2 * a) > kink * fmax(a, fmax(b, c));
            }
            core[k] = (unsigned char)rough;
        }
    /* And a ring around: a fine read blends with its neighbour cells, and
     * a texel beside a rough one is read from it bilinearly. */
    memset(mark, 0, (size_t)nu * nv);
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            if (!core[(size_t)j * nu + i])
                continue;
            for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++) {
                    int i2 = i + di, j2 = j + dj;
                    if (i2 < 0 || j2 < 0 || i2 >= nu || j2 >= nv)
                        continue;
                    size_t k2 = (size_t)j2 * nu + i2;
                    if (wt[k2] > 0 && !mark[k2]) {
                        mark[k2] = 1;
                        count++;
                    }
                }
        }
    free(core);
    return count;
}

/* Marks (in `ends`, cleared first) the texels of `mark` around end e (0:
 * a, 1: b) of crossing k, the texel holding it and its eight neighbours,
 * that `taken` does not hold yet, and adds them to `taken`.  Returns how
 * many. */
static int mark_end(const part_map *m, int k, int e, const unsigned char *mark,
                    unsigned char *taken, unsigned char *ends)
{
    const map_layout *l = &m->layout;
    int nu = l->nu, nv = l->nv, count = 0;
    memset(ends, 0, (size_t)nu * nv);
    double u, v;
    map_coords(l, e ? m->cross[k].b : m->cross[k].a, &u, &v);
    int ic = (int)floor(u + 0.5), jc = (int)floor(v + 0.5);
    for (int j = jc - 1; j <= jc + 1; j++)
        for (int i = ic - 1; i <= ic + 1; i++) {
            if (i < 0 || j < 0 || i >= nu || j >= nv)
                continue;
            size_t t = (size_t)j * nu + i;
            if (mark[t] && !taken[t]) {
                ends[t] = taken[t] = 1;
                count++;
            }
        }
    return count;
}

/* The centre of fine cell (su, sv) of texel (i, j), its side's normal. */
static void cell_point(const map_layout *l, int i, int j, int su, int sv, int sub, int side,
                       vec3 *x, vec3 *n)
{
    vec3 p;
    map_texel_point(l, i, j, &p, n);
    *x = map_cell_centre(l, i, j, su, sv, sub);
    if (side)
        *n = v3_scale(*n, -1);
}

/* The texels the bilinear read of the marked texels' fine cells leans on
 * (those texels and a ring around), computed again with the cells' piece
 * size `theta`, in a copy of the map (`same`, sharing all else).  A cell's
 * detail is then what that read misses of its value at the same piece
 * size, and the coarser transfer's own error, which is smooth (a piece
 * sends its mean light, while the part a receiver sees of it is lit
 * otherwise than the part hidden), cancels instead of entering the detail.
 * Cells at 2 theta measured against the texels themselves (theta) left
 * triangletest's level 2 about 1% dark over refined texels.  Returns 0
 * when out of memory (having freed what it took). */
static int same_size_texels(zone_forest *f, const zt_renderer *r, int part, int level, int side,
                            const unsigned char *mark, int i0, int j0, int i1, int j1,
                            double theta, part_map *same, uint64_t *rays)
{
    const part_map *m = &f->maps[part];
    const map_layout *l = &m->layout;
    int nu = l->nu, nv = l->nv;
    size_t plane = (size_t)nv * nu * 3, at = ((size_t)level * l->sides + side) * plane;
    size_t total = (size_t)m->levels * l->sides * plane;
    *same = *m;
    same->details = 0;
    same->detail_live = 0;
    same->texels = malloc(total * sizeof(float));
    same->alt = m->alt ? malloc(total * sizeof(float)) : NULL;
    if (!same->texels || (m->alt && !same->alt)) {
        free(same->texels);
        free(same->alt);
        return 0;
    }
    memcpy(same->texels, m->texels, total * sizeof(float));
    if (m->alt)
        memcpy(same->alt, m->alt, total * sizeof(float));
    same->mip[0] = same->texels;
    i0 = i0 > 0 ? i0 - 1 : 0, j0 = j0 > 0 ? j0 - 1 : 0;
    i1 = i1 + 1 < nu ? i1 + 1 : nu - 1, j1 = j1 + 1 < nv ? j1 + 1 : nv - 1;
    uint64_t count = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(render_thread_count(r->options.threads)) reduction(+ : count)
    for (int j = j0; j <= j1; j++) {
        zone_trace t = {f, r, 0, 0.0f};
        for (int i = i0; i <= i1; i++) {
            size_t k = (size_t)j * nu + i, ka = (size_t)side * nv * nu + k;
            /* A cell's read leans on the texels around its own only. */
            int near = 0;
            for (int b = j - 1; b <= j + 1 && !near; b++)
                for (int a = i - 1; a <= i + 1 && !near; a++)
                    near = a >= 0 && b >= 0 && a < nu && b < nv && mark[(size_t)b * nu + a];
            if (!near)
                continue;
            vec3 x, n;
            if (m->weight[0][ka] > 0) {
                map_texel_eval_point(m, i, j, side, &x, &n);
                vec3 e = transfer_irradiance(&t, part, x, n, level, theta);
                float *v = same->texels + at + 3 * k;
                v[0] = (float)e.x, v[1] = (float)e.y, v[2] = (float)e.z;
            }
            if (m->alt && m->cut[k] >= 0 && m->alt_weight[ka] > 0) {
                map_texel_alt_point(m, i, j, side, &x, &n);
                vec3 e = transfer_irradiance(&t, part, x, n, level, theta);
                float *v = same->alt + at + 3 * k;
                v[0] = (float)e.x, v[1] = (float)e.y, v[2] = (float)e.z;
            }
        }
        count += t.rays;
    }
    *rays += count;
    return 1;
}

/* A new window over the box of the marked texels, `sub` cells a side,
 * zeroed, at level -1 while its cells are filled (so that reads, on other
 * threads too, leave it out).  NULL when none is marked or out of memory
 * (*failed says which). */
static map_detail *add_window(part_map *m, int side, const unsigned char *mark, int sub,
                              int *failed)
{
    const map_layout *l = &m->layout;
    int nu = l->nu, nv = l->nv;
    int i0 = nu, i1 = -1, j0 = nv, j1 = -1;
    *failed = 0;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++)
            if (mark[(size_t)j * nu + i]) {
                i0 = i < i0 ? i : i0, i1 = i > i1 ? i : i1;
                j0 = j < j0 ? j : j0, j1 = j > j1 ? j : j1;
            }
    if (i1 < 0)
        return NULL;
    int ni = i1 - i0 + 1, nj = j1 - j0 + 1;
    *failed = 1;
    map_detail *nd = realloc(m->detail, (size_t)(m->details + 1) * sizeof *nd);
    if (!nd)
        return NULL;
    m->detail = nd;
    map_detail *d = &m->detail[m->details++];
    *d = (map_detail){-1, side, i0, j0, ni, nj, sub, NULL, NULL, NULL, NULL, NULL};
    d->use = malloc((size_t)ni * nj);
    d->e = calloc((size_t)ni * nj * sub * sub * 3, sizeof(float));
    if (!d->use || !d->e)
        return NULL;
    for (int j = 0; j < nj; j++)
        for (int i = 0; i < ni; i++)
            d->use[(size_t)j * ni + i] = mark[(size_t)(j0 + j) * nu + i0 + i];
    *failed = 0;
    return d;
}

/* Window d's cells in its marked texels: the exact irradiance (E_0 as
 * its texels are, higher levels by the transfer at `theta`) less what
 * `read` (the map the cells complete) gives there.  A cell a crossing
 * passes through gets a second value, the same at its part beyond the
 * crossing: the light jumps there, and beside a crossing's end the cells
 * on the far side, which a read would take instead, lie further off while
 * the light changes fastest.  Returns 0 when out of memory. */
static int fill_cells(zone_forest *f, const zt_renderer *r, int part, int level, int side,
                      map_detail *d, const part_map *read, double theta, uint64_t *rays)
{
    const part_map *m = &f->maps[part];
    const map_layout *l = &m->layout;
    int sub = d->sub, fu = d->ni * sub, rows = d->nj * sub;
    size_t cells = (size_t)fu * rows;
    int any_cut = 0;
    for (int j = 0; j < d->nj && m->crossings; j++)
        for (int i = 0; i < d->ni; i++)
            any_cut |= d->use[(size_t)j * d->ni + i] &&
                       m->cut[(size_t)(d->j0 + j) * l->nu + d->i0 + i] >= 0;
    if (any_cut) {
        d->split = calloc(cells, 1);
        d->far = calloc(cells * 6, sizeof(float));
        if (!d->split || !d->far)
            return 0;
    }
    uint64_t count = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(render_thread_count(r->options.threads)) reduction(+ : count)
    for (int b = 0; b < rows; b++) {
        zone_trace t = {f, r, 0, 0.0f};
        int j = d->j0 + b / sub, sv = b % sub;
        for (int a = 0; a < fu; a++) {
            int i = d->i0 + a / sub, su = a % sub;
            if (!d->use[(size_t)(b / sub) * d->ni + a / sub])
                continue;
            vec3 x, n;
            cell_point(l, i, j, su, sv, sub, side, &x, &n);
            vec3 exact = level == 0 ? forest_direct_at(&t, part, x, n)
                                    : transfer_irradiance(&t, part, x, n, level, theta);
            vec3 got = map_lookup_wide(read, level, side, x, 0.0);
            float *e = d->e + 3 * ((size_t)b * fu + a);
            e[0] = (float)(exact.x - got.x);
            e[1] = (float)(exact.y - got.y);
            e[2] = (float)(exact.z - got.z);
            vec3 y;
            if (!d->split || !map_cell_split(m, i, j, su, sv, sub, &y))
                continue;
            exact = level == 0 ? forest_direct_at(&t, part, y, n)
                               : transfer_irradiance(&t, part, y, n, level, theta);
            got = map_lookup_wide(read, level, side, y, 0.0);
            float *g = d->far + 6 * ((size_t)b * fu + a);
            g[0] = (float)(exact.x - got.x);
            g[1] = (float)(exact.y - got.y);
            g[2] = (float)(exact.z - got.z);
            g[3] = (float)y.x, g[4] = (float)y.y, g[5] = (float)y.z;
            d->split[(size_t)b * fu + a] = 1;
        }
        count += t.rays;
    }
    *rays += count;
    return 1;
}

/* The windows of one level and side: the marked texels' cells, then (from
 * the quality that asks for them) finer cells around the ends of
 * crossings. */
static int refine_window(zone_forest *f, const zt_renderer *r, int part, int level, int side,
                         const unsigned char *mark, uint64_t *rays)
{
    part_map *m = &f->maps[part];
    int failed;
    map_detail *d = add_window(m, side, mark, f->q.refine_sub, &failed);
    if (!d)
        return !failed;
    /* E_0's cells are exact, as its texels are: they are read against the
     * map itself. */
    double theta = f->q.refine_theta * f->q.theta;
    part_map same = *m;
    same.details = 0;
    same.detail_live = 0;
    if (level > 0 && !same_size_texels(f, r, part, level, side, mark, d->i0, d->j0,
                                       d->i0 + d->ni - 1, d->j0 + d->nj - 1, theta, &same, rays))
        return 0;
    int ok = fill_cells(f, r, part, level, side, d, &same, theta, rays);
    d->level = level;
    /* Then a window of finer cells around each end of a crossing (ends
     * close together share texels: each texel goes to the first), which
     * complete the read with the windows before them. */
    if (ok && f->q.refine_end_sub > f->q.refine_sub && m->crossings > 0) {
        size_t cells = (size_t)m->layout.nu * m->layout.nv;
        unsigned char *taken = calloc(cells * 2, 1), *ends = taken + cells;
        ok = taken != NULL;
        for (int k = 0; ok && k < m->crossings; k++)
            for (int e = 0; ok && e < 2; e++) {
                if (!mark_end(m, k, e, mark, taken, ends))
                    continue;
                map_detail *d2 = add_window(m, side, ends, f->q.refine_end_sub, &failed);
                ok = !failed;
                if (!d2)
                    continue;
                same.detail = m->detail;
                same.details = m->details;
                same.detail_live = 1;
                ok = fill_cells(f, r, part, level, side, d2, &same, theta, rays);
                d2->level = level;
            }
        free(taken);
    }
    if (level > 0) {
        free(same.texels);
        free(same.alt);
    }
    return ok;
}

int refine_level(zone_forest *f, const zt_renderer *r, int level)
{
    if (f->q.refine_sub <= 0 || f->need_gather || f->glint_count || level >= f->map_levels)
        return 1;
    uint64_t rays = 0;
    for (int p = 0; p < f->map_count; p++) {
        part_map *m = &f->maps[p];
        if (!m->texels || m->layout.shape == SHAPE_SPHERE)
            continue;
        const map_layout *l = &m->layout;
        unsigned char *mark = malloc((size_t)l->nu * l->nv);
        if (!mark)
            return 0;
        for (int side = 0; side < l->sides; side++) {
            int n = mark_rough(m, level, side, f->q.refine_contrast, f->q.refine_kink, mark);
            if (n < 0 || (n > 0 && !refine_window(f, r, p, level, side, mark, &rays))) {
                free(mark);
                return 0;
            }
        }
        free(mark);
        m->detail_live = m->details > 0;
    }
    f->rays += rays;
    return 1;
}

void refine_drop_level0(zone_forest *f)
{
    for (int p = 0; p < f->map_count; p++) {
        part_map *m = &f->maps[p];
        int kept = 0;
        for (int k = 0; k < m->details; k++) {
            map_detail *d = &m->detail[k];
            if (d->level == 0 && !d->coarse) {
                free(d->use);
                free(d->e);
                free(d->split);
                free(d->far);
                continue;
            }
            m->detail[kept++] = *d;
        }
        m->details = kept;
        m->detail_live = kept > 0;
        if (!kept) {
            free(m->detail);
            m->detail = NULL;
        }
    }
}
