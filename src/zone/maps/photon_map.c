#include "zone/maps/photon_map.h"

#include <stdlib.h>
#include <string.h>

int photon_map_add(photon_map *m, const zone_photon *p)
{
    if (m->count == m->capacity) {
        size_t cap = m->capacity ? 2 * m->capacity : 1024;
        zone_photon *np = realloc(m->p, cap * sizeof *np);
        if (!np)
            return 0;
        m->p = np;
        m->capacity = cap;
    }
    m->p[m->count++] = *p;
    return 1;
}

static void swap_photons(zone_photon *a, zone_photon *b)
{
    zone_photon t = *a;
    *a = *b;
    *b = t;
}

/* Puts the photon of rank k (along `axis`) of p[0..n) at k, smaller ones
 * before it and larger ones after (Hoare's selection, middle pivots: the
 * order depends on the photons alone). */
static void select_rank(zone_photon *p, size_t n, size_t k, int axis)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        float pivot = p[lo + (hi - lo) / 2].x[axis];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (p[i].x[axis] < pivot)
                i++;
            while (p[j].x[axis] > pivot)
                j--;
            if (i <= j) {
                swap_photons(&p[i], &p[j]);
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}

/* The tree over p[lo, hi): its median at the middle, split on the longest
 * axis of the photons' box, each half a tree of its own. */
static void build_tree(zone_photon *p, uint8_t *axis, size_t lo, size_t hi)
{
    while (hi - lo > 1) {
        float bl[3], bh[3];
        for (int a = 0; a < 3; a++)
            bl[a] = bh[a] = p[lo].x[a];
        for (size_t i = lo + 1; i < hi; i++)
            for (int a = 0; a < 3; a++) {
                bl[a] = p[i].x[a] < bl[a] ? p[i].x[a] : bl[a];
                bh[a] = p[i].x[a] > bh[a] ? p[i].x[a] : bh[a];
            }
        int ax = 0;
        for (int a = 1; a < 3; a++)
            if (bh[a] - bl[a] > bh[ax] - bl[ax])
                ax = a;
        size_t mid = lo + (hi - lo) / 2;
        select_rank(p + lo, hi - lo, mid - lo, ax);
        axis[mid] = (uint8_t)ax;
        build_tree(p, axis, lo, mid);
        lo = mid + 1;
    }
}

/* The groups of photons sorted by (level, surface); 0 when out of
 * memory or when they are not in that order. */
static int find_groups(photon_map *m)
{
    free(m->group);
    m->group = NULL;
    m->group_count = 0;
    int groups = 0;
    for (size_t i = 0; i < m->count; i++) {
        const zone_photon *p = &m->p[i], *q = i ? &m->p[i - 1] : NULL;
        if (q && (p->level < q->level || (p->level == q->level && p->surface < q->surface)))
            return 0;
        groups += !q || p->level != q->level || p->surface != q->surface;
    }
    if (groups == 0)
        return 1;
    m->group = malloc((size_t)groups * sizeof *m->group);
    if (!m->group)
        return 0;
    for (size_t i = 0; i < m->count; i++) {
        const zone_photon *p = &m->p[i], *q = i ? &m->p[i - 1] : NULL;
        if (!q || p->level != q->level || p->surface != q->surface)
            m->group[m->group_count++] = (photon_group){p->level, p->surface, i, 0};
        m->group[m->group_count - 1].count++;
    }
    return 1;
}

int photon_map_build(photon_map *m, photon_map *parts, int count, int levels, int surfaces)
{
    photon_map_free(m);
    /* Counts per (level, surface), then each photon to its place in the
     * parts' order: a stable bucket sort, as deterministic as that order. */
    size_t keys = (size_t)levels * (size_t)surfaces, total = 0;
    size_t *at = calloc(keys + 1, sizeof *at);
    if (!at)
        return 0;
    for (int k = 0; k < count; k++)
        for (size_t i = 0; i < parts[k].count; i++) {
            const zone_photon *p = &parts[k].p[i];
            if (p->level < levels && p->surface >= 0 && p->surface < surfaces) {
                at[(size_t)p->level * (size_t)surfaces + (size_t)p->surface]++;
                total++;
            }
        }
    m->p = malloc((total + 1) * sizeof *m->p);
    m->axis = calloc(total + 1, 1);
    if (!m->p || !m->axis) {
        free(at);
        return 0;
    }
    m->count = m->capacity = total;
    for (size_t j = 0, sum = 0; j < keys; j++) {
        size_t c = at[j];
        at[j] = sum;
        sum += c;
    }
    for (int k = 0; k < count; k++) {
        for (size_t i = 0; i < parts[k].count; i++) {
            const zone_photon *p = &parts[k].p[i];
            if (p->level < levels && p->surface >= 0 && p->surface < surfaces)
                m->p[at[(size_t)p->level * (size_t)surfaces + (size_t)p->surface]++] = *p;
        }
        if (&parts[k] != m) {
            free(parts[k].p);
            parts[k].p = NULL;
            parts[k].count = parts[k].capacity = 0;
        }
    }
    free(at);
    if (!find_groups(m))
        return 0;
    for (int g = 0; g < m->group_count; g++)
        build_tree(m->p, m->axis, m->group[g].first, m->group[g].first + m->group[g].count);
    return 1;
}

int photon_map_adopt(photon_map *m)
{
    for (size_t i = 0; i < m->count; i++)
        if (m->axis[i] > 2)
            return 0;
    for (size_t i = 1; i < m->count; i++)
        if (m->p[i].level < m->p[i - 1].level ||
            (m->p[i].level == m->p[i - 1].level && m->p[i].surface < m->p[i - 1].surface))
            return 0;
    return find_groups(m) ? 1 : -1;
}

/* The k nearest so far: a max-heap on the squared distance. */
typedef struct nearest {
    float d2[PHOTON_MAP_K];
    const zone_photon *p[PHOTON_MAP_K];
    int n;
    float bound;    /* squared radius searched: r_max^2, then the k-th's */
    float x[3];
    float nf[3];
} nearest;

/* Moves entry i of the full heap down to its place. */
static void sift_down(nearest *h, int i)
{
    float d2 = h->d2[i];
    const zone_photon *p = h->p[i];
    for (;;) {
        int c = 2 * i + 1;
        if (c >= PHOTON_MAP_K)
            break;
        if (c + 1 < PHOTON_MAP_K && h->d2[c + 1] > h->d2[c])
            c++;
        if (h->d2[c] <= d2)
            break;
        h->d2[i] = h->d2[c];
        h->p[i] = h->p[c];
        i = c;
    }
    h->d2[i] = d2;
    h->p[i] = p;
}

/* The first k are only kept (where photons are sparse, fewer than k lie
 * within the reach and no order is needed), and made a heap when the k-th
 * comes; from then on a nearer one replaces the farthest. */
static void heap_offer(nearest *h, const zone_photon *p, float d2)
{
    if (h->n < PHOTON_MAP_K) {
        h->d2[h->n] = d2;
        h->p[h->n++] = p;
        if (h->n < PHOTON_MAP_K)
            return;
        for (int i = PHOTON_MAP_K / 2 - 1; i >= 0; i--)
            sift_down(h, i);
    } else {
        h->d2[0] = d2;
        h->p[0] = p;
        sift_down(h, 0);
    }
    h->bound = h->d2[0];
}

/* Whether photon p lies within the searched disc, on the same side
 * (normals within 60 degrees); *d2 its squared distance. */
static int within(const nearest *h, const zone_photon *p, float *d2)
{
    float dx = h->x[0] - p->x[0], dy = h->x[1] - p->x[1], dz = h->x[2] - p->x[2];
    *d2 = dx * dx + dy * dy + dz * dz;
    return *d2 < h->bound && h->nf[0] * p->n[0] + h->nf[1] * p->n[1] + h->nf[2] * p->n[2] > 63.5f;
}

static void search(const photon_map *m, nearest *h, size_t lo, size_t hi)
{
    while (hi > lo) {
        size_t mid = lo + (hi - lo) / 2;
        const zone_photon *p = &m->p[mid];
        float d2;
        /* Once k are held the bound is the k-th's: nearer ones replace it. */
        if (within(h, p, &d2))
            heap_offer(h, p, d2);
        if (hi - lo == 1)
            return;
        int ax = m->axis[mid];
        float d = h->x[ax] - p->x[ax];
        size_t near_lo = d < 0 ? lo : mid + 1, near_hi = d < 0 ? mid : hi;
        size_t far_lo = d < 0 ? mid + 1 : lo, far_hi = d < 0 ? hi : mid;
        search(m, h, near_lo, near_hi);
        if (d * d >= h->bound)
            return;
        lo = far_lo;
        hi = far_hi;
    }
}

/* The flux of every photon within sqrt(h->bound) of h->x, weighed by
 * Epanechnikov's kernel over that disc (before its normalisation), and
 * how many there are. */
static size_t sum_within(const photon_map *m, const nearest *h, size_t lo, size_t hi, double e[3])
{
    size_t n = 0;
    while (hi > lo) {
        size_t mid = lo + (hi - lo) / 2;
        const zone_photon *p = &m->p[mid];
        float d2;
        if (within(h, p, &d2)) {
            double w = 1.0 - d2 / h->bound;
            for (int c = 0; c < 3; c++)
                e[c] += w * p->flux[c];
            n++;
        }
        if (hi - lo == 1)
            break;
        int ax = m->axis[mid];
        float d = h->x[ax] - p->x[ax];
        size_t near_lo = d < 0 ? lo : mid + 1, near_hi = d < 0 ? mid : hi;
        n += sum_within(m, h, near_lo, near_hi, e);
        if (d * d >= h->bound)
            break;
        lo = d < 0 ? mid + 1 : lo;
        hi = d < 0 ? hi : mid;
    }
    return n;
}

vec3 photon_map_irradiance(const photon_map *m, int level, int surface, vec3 x, vec3 nf,
                           double r_min, double r_max)
{
    int a = 0, b = m->group_count;
    while (a < b) {
        int c = (a + b) / 2;
        const photon_group *g = &m->group[c];
        if (g->level < level || (g->level == level && g->surface < surface))
            a = c + 1;
        else
            b = c;
    }
    if (a == m->group_count || m->group[a].level != level || m->group[a].surface != surface ||
        !(r_max > 0))
        return v3(0, 0, 0);
    const photon_group *g = &m->group[a];
    nearest h;
    h.n = 0;
    h.bound = (float)(r_max * r_max);
    h.x[0] = (float)x.x;
    h.x[1] = (float)x.y;
    h.x[2] = (float)x.z;
    h.nf[0] = (float)nf.x;
    h.nf[1] = (float)nf.y;
    h.nf[2] = (float)nf.z;
    double e[3] = {0, 0, 0}, r2;
    size_t lo = g->first, hi = g->first + g->count;
    if (r_min > 0) {
        /* At least k photons within the footprint (or the reach, if
         * that is smaller): all of them over it. */
        r2 = r_min < r_max ? r_min * r_min : r_max * r_max;
        h.bound = (float)r2;
        if (sum_within(m, &h, lo, hi, e) >= PHOTON_MAP_K) {
            double k = 2.0 / (3.14159265358979323846 * r2);
            return v3(e[0] * k, e[1] * k, e[2] * k);
        }
        e[0] = e[1] = e[2] = 0;
        h.bound = (float)(r_max * r_max);
    }
    /* Else the k nearest within the reach. */
    search(m, &h, lo, hi);
    r2 = h.n == PHOTON_MAP_K ? h.d2[0] : r_max * r_max;
    for (int i = 0; i < h.n; i++) {
        double w = 1.0 - h.d2[i] / r2;
        for (int c = 0; c < 3; c++)
            e[c] += w * h.p[i]->flux[c];
    }
    if (!(r2 > 0))
        return v3(0, 0, 0);
    double k = 2.0 / (3.14159265358979323846 * r2);
    return v3(e[0] * k, e[1] * k, e[2] * k);
}

void photon_map_free(photon_map *m)
{
    free(m->p);
    free(m->group);
    free(m->axis);
    memset(m, 0, sizeof *m);
}
