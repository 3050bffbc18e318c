/* The cut (cut.h). */
#include "zone/transfer/cut.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "geom/transmittance.h"
#include "util/vec3_convert.h"

#define PI 3.14159265358979323846
#define HEAP_MAX 8192
/* A cluster is seen through rays to its descendants this many levels
 * below its children (two rays at 0, four at 1).  The engine room at depth
 * 3, 512 x 512, with cuts of up to 4096 clusters: a quarter fewer rays with
 * two, the error within 0.01 points (1.84% per pixel, 1.21% over 4 x 4
 * blocks); the Cornell box: 0.566% with two against 0.549% with four.
 * Eight rays gained nothing more. */
#define SEEN_DEPTH 0

/* A cluster in the cut.  Its bound on the luminance it may contribute
 * (err, >= 0) and its node are packed into one key, err's bits above the
 * node's complement: a larger key is a larger bound, ties to the lower
 * node (a fixed order), and the heap compares one integer. */
typedef struct cand {
    uint64_t key;
    float est[3];       /* its estimate, in the total */
    int32_t left;       /* the node's (sender_node): its children or */
    int32_t count;      /* elements, without reading it again */
    float seen;         /* the share seen, taken into est; -1 before see(),
                           -2 when it had nothing to see */
} cand;

static uint64_t cand_key(float err, int32_t node)
{
    /* (A bound that is not a number, from light that is not, is opened
     * like an unbounded one.) */
    if (err != err)
        err = INFINITY;
    uint32_t bits = 0;
    if (err > 0)
        memcpy(&bits, &err, sizeof bits);
    return (uint64_t)bits << 32 | (uint32_t)~(uint32_t)node;
}

static float cand_err(const cand *c)
{
    uint32_t bits = (uint32_t)(c->key >> 32);
    float err;
    memcpy(&err, &bits, sizeof err);
    return err;
}

static int32_t cand_node(const cand *c)
{
    return (int32_t)~(uint32_t)c->key;
}

typedef struct gather {
    const sender_tree *t;
    const rscene *rs;
    vec3f xf, nf;
    vec3f xo;           /* ray origin off the surface */
    cut_stats *st;
} gather;

double cut_visible(const rscene *rs, vec3f xo, vec3 to, int background, cut_stats *st)
{
    vec3f d = f3_sub(v3_to_f3(to), xo);
    float dist = f3_length(d);
    if (!(dist > 0.0f))
        return 0;
    st->rays++;
    return accel_transmittance_mean(rs, xo, f3_scale(d, 1.0f / dist), dist * 0.9999f, background);
}

static double lum(const double v[3])
{
    return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
}

static float lumf(const float v[3])
{
    return 0.2126f * v[0] + 0.7152f * v[1] + 0.0722f * v[2];
}

/* Whether element e's sending side faces the receiver (an element facing
 * away is hidden by its own surface, whatever its cluster does). */
static int faces(const gather *g, const float c[3], const float n[3])
{
    return n[0] * (g->xf.x - c[0]) + n[1] * (g->xf.y - c[1]) + n[2] * (g->xf.z - c[2]) > 0;
}

/* The points whose rays say what share of a cluster's power reaches the
 * receiver: its two children's representatives (or its elements'
 * centres), weighted by their power, so that a cluster half hidden counts
 * about half; one ray to its own representative counted it whole or not
 * at all, and blotched the maps beside the Cornell box's blocks (level 2
 * at 128 x 128: 2.77% against 2.35% at the same cut).  Returns how many
 * (each of positive power) and their weights' whole in *wsum. */
typedef struct see_target {
    vec3 to;
    double w;
    int background;
} see_target;

/* Targets seen_targets gives at most: an inner node's descendants, or a
 * leaf's elements (a leaf of more, which only coincident elements make,
 * is taken in runs of this many). */
#define SEE_TARGETS_MAX 8

/* Whether any of leaf elements [first, first + count) faces the receiver:
 * then only those that face it vote (all, when none does). */
static int leaf_any_facing(const gather *g, int first, int count)
{
    int any = 0;
    for (int i = first; i < first + count; i++)
        any |= faces(g, g->t->elems[i].c, g->t->elems[i].n);
    return any;
}

/* The targets of leaf elements [first, first + count), adding their
 * weights to *wsum. */
static int leaf_targets(const gather *g, int first, int count, int any, see_target *out,
                        double *wsum)
{
    const sender_tree *t = g->t;
    int m = 0;
    for (int i = first; i < first + count; i++) {
        double w = sender_elem_power(t, i);
        const float *c = t->elems[i].c;
        if (any && !faces(g, c, t->elems[i].n))
            continue;
        *wsum += w;
        if (w > 0)
            out[m++] = (see_target){v3(c[0], c[1], c[2]), w, t->elems[i].background};
    }
    return m;
}

/* The targets of a cluster (of an inner node or a leaf of at most
 * SEE_TARGETS_MAX elements) into out, their weights' whole in *wsum;
 * returns how many. */
static int seen_targets(const gather *g, const sender_node *node, see_target *out, double *wsum)
{
    const sender_tree *t = g->t;
    *wsum = 0;
    if (node->count > 0) {
        int first = -1 - node->left;
        return leaf_targets(g, first, node->count, leaf_any_facing(g, first, node->count), out,
                            wsum);
    }
    /* Descendants a few levels down where there are any. */
    int32_t kids[2 << SEEN_DEPTH];
    int nk = 0;
    kids[nk++] = node->left;
    kids[nk++] = node->left + 1;
    for (int level = 0; level < SEEN_DEPTH; level++) {
        int32_t next[2 << SEEN_DEPTH];
        int nn = 0;
        for (int k = 0; k < nk; k++) {
            const sender_node *c = &t->nodes[kids[k]];
            if (c->count == 0 && nn + 2 <= (2 << SEEN_DEPTH)) {
                next[nn++] = c->left;
                next[nn++] = c->left + 1;
            } else if (nn < (2 << SEEN_DEPTH)) {
                next[nn++] = kids[k];
            }
        }
        memcpy(kids, next, (size_t)nn * sizeof *kids);
        nk = nn;
    }
    /* A representative facing away from the receiver is hidden by its own
     * surface, whatever the rest of its cluster does: only those facing it
     * vote (all, when none does). */
    int facing[2 << SEEN_DEPTH], any = 0, m = 0;
    for (int k = 0; k < nk; k++) {
        const sender_light *cl = &t->light[kids[k]];
        facing[k] = faces(g, cl->rep, cl->rep_n);
        any |= facing[k] && cl->power > 0;
    }
    for (int k = 0; k < nk; k++) {
        const sender_light *cl = &t->light[kids[k]];
        if (any && !facing[k])
            continue;
        *wsum += cl->power;
        if (cl->power > 0)
            out[m++] = (see_target){v3(cl->rep[0], cl->rep[1], cl->rep[2]), cl->power,
                                    t->nodes[kids[k]].background};
    }
    return m;
}

static double seen_share(gather *g, const sender_node *node)
{
    see_target tg[SEE_TARGETS_MAX];
    double wsum = 0, seen = 0;
    if (node->count <= SEE_TARGETS_MAX) {
        int m = seen_targets(g, node, tg, &wsum);
        for (int i = 0; i < m; i++)
            seen += tg[i].w * cut_visible(g->rs, g->xo, tg[i].to, tg[i].background, g->st);
    } else {
        int first = -1 - node->left, any = leaf_any_facing(g, first, node->count);
        for (int at = first; at < first + node->count; at += SEE_TARGETS_MAX) {
            int run = first + node->count - at;
            int m = leaf_targets(g, at, run < SEE_TARGETS_MAX ? run : SEE_TARGETS_MAX, any, tg,
                                 &wsum);
            for (int i = 0; i < m; i++)
                seen += tg[i].w * cut_visible(g->rs, g->xo, tg[i].to, tg[i].background, g->st);
        }
    }
    return wsum > 0 ? seen / wsum : 0;
}

/* Cluster ni's estimate for the receiver into out; returns its bound.  The
 * cone of directions from box to x, half-angle delta: sin delta = radius /
 * distance. */
static float estimate(gather *g, int32_t ni, cand *out)
{
    const sender_tree *t = g->t;
    const sender_node *node = &t->nodes[ni];
    const sender_light *l = &t->light[ni];
    out->left = node->left;
    out->count = node->count;
    out->est[0] = out->est[1] = out->est[2] = 0;
    out->seen = -1;
    if (!(l->power > 0.0f))
        return 0;
    /* Single precision throughout: bounds and estimates, not sums. */
    vec3f lo = f3(node->lo[0], node->lo[1], node->lo[2]);
    vec3f hi = f3(node->hi[0], node->hi[1], node->hi[2]);
    vec3f x = g->xf, n = g->nf;
    /* The box against the receiver's horizon: wholly below, nothing.  The
     * corner furthest along n is the highest. */
    float hmax = n.x * ((n.x >= 0 ? hi.x : lo.x) - x.x) + n.y * ((n.y >= 0 ? hi.y : lo.y) - x.y) +
                 n.z * ((n.z >= 0 ? hi.z : lo.z) - x.z);
    float hmin = n.x * ((n.x >= 0 ? lo.x : hi.x) - x.x) + n.y * ((n.y >= 0 ? lo.y : hi.y) - x.y) +
                 n.z * ((n.z >= 0 ? lo.z : hi.z) - x.z);
    float radius = node->radius;
    /* (A cluster on the receiver's own plane, within rounding: nothing.) */
    if (hmax <= 1e-5f * (fabsf(hmin) + 2 * radius + fabsf(lo.x - x.x) + fabsf(lo.y - x.y) +
                         fabsf(lo.z - x.z)))
        return 0;
    vec3f d = f3(f_max0(f_max(lo.x - x.x, x.x - hi.x)), f_max0(f_max(lo.y - x.y, x.y - hi.y)),
                 f_max0(f_max(lo.z - x.z, x.z - hi.z)));
    float dmin2 = f3_dot(d, d);
    if (!(dmin2 > 0)) {
        /* The receiver is inside the box: nothing can be bounded. */
        return INFINITY;
    }
    vec3f c = f3(l->c[0], l->c[1], l->c[2]);
    vec3f w = f3_sub(x, c); /* from the cluster to the receiver */
    float r2 = f3_dot(w, w), r = sqrtf(r2), inv_r = 1.0f / r;
    /* Angles by their cosines and sines (no acos in the loop): the
     * directions from the box to x lie within delta of w; the normals
     * within `cone` of the axis, at angle a from w; b = cone + delta. */
    float sd = r > radius ? radius * inv_r : 1.0f, cd = sqrtf(f_max0(1.0f - sd * sd));
    vec3f ax = f3(node->axis[0], node->axis[1], node->axis[2]);
    float ca = f_clamp1(f3_dot(ax, w) * inv_r), sa = sqrtf(f_max0(1.0f - ca * ca));
    float cc = node->cos_cone, sc = node->sin_cone;
    float cb, sb;
    if (cc < 0 && sd > sc) {
        cb = -1, sb = 0; /* cone + delta past pi */
    } else {
        cb = cc * cd - sc * sd;
        sb = sc * cd + cc * sd;
    }
    /* cos(max(0, a - b)), and whether a - b reaches pi/2. */
    float cos_e_max = ca >= cb ? 1.0f : ca * cb + sa * sb;
    if (ca < cb && cos_e_max <= 0)
        return 0; /* every element faces away */
    float cos_r = -f3_dot(n, w) * inv_r;
    float cr = f_clamp1(cos_r), sr = sqrtf(f_max0(1.0f - cr * cr));
    float cos_r_max = cr >= cd ? 1.0f : f_max0(cr * cd + sr * sd);
    /* Lightcuts' bound: what the cluster could send at most. */
    float err = l->power * cos_e_max * cos_r_max / dmin2;
    if (node->any_way && err > 0) {
        /* Elements facing every way (a sphere light, points): no vector
         * flux stands for them; they are opened down to the leaves. */
        return INFINITY;
    }
    g->st->clusters++;
    if (!(cos_r > 0))
        return err;
    /* Every element facing the receiver: flux x cosine is the vector flux
     * dotted with the direction.  Otherwise elements facing away would
     * subtract: the signed axes' flux instead (sender_light). */
    vec3f u = f3_scale(w, inv_r);
    /* a + b < pi/2: every element faces the receiver. */
    int facing = ca > 0 && cb > 0 && ca * cb - sa * sb > 0;
    float k = cos_r / r2;
    for (int ch = 0; ch < 3; ch++) {
        float dot = l->vflux[ch][0] * u.x + l->vflux[ch][1] * u.y + l->vflux[ch][2] * u.z;
        if (!facing)
            dot = 0.5f * (dot + fabsf(u.x) * l->aflux[ch][0] + fabsf(u.y) * l->aflux[ch][1] +
                          fabsf(u.z) * l->aflux[ch][2]);
        out->est[ch] = f_max0(dot) * k;
    }
    return err;
}

static void evaluate(gather *g, int32_t ni, cand *out)
{
    out->key = cand_key(estimate(g, ni, out), ni);
}

/* Visibility into a candidate's estimate (rays), once. */
static void see(gather *g, cand *c, double total[3])
{
    if (c->seen != -1)
        return;
    c->seen = -2;
    if (!(lumf(c->est) > 0))
        return;
    double s = seen_share(g, &g->t->nodes[cand_node(c)]);
    c->seen = (float)s;
    for (int ch = 0; ch < 3; ch++) {
        float e = (float)(c->est[ch] * s);
        total[ch] += (double)e - c->est[ch];
        c->est[ch] = e;
    }
}


/* Rays see_all casts together. */
#define SEE_BATCH 64

/* A batch of candidates' rays: each candidate's targets, in order. */
typedef struct see_batch {
    int rays, owners;
    vec3f dir[SEE_BATCH];
    float dist[SEE_BATCH];
    unsigned char bg[SEE_BATCH], cast[SEE_BATCH];
    float seen[SEE_BATCH];
    double w[SEE_BATCH];
    int owner_first[SEE_BATCH + 1];
    cand *owner[SEE_BATCH];
    double owner_wsum[SEE_BATCH];
} see_batch;

/* Casts the batch's rays (packets from the receiver, by layer of their
 * targets) and gives each candidate its share seen, in order, as see()
 * would; a ray's answer is cut_visible's (what panes on the way pass). */
static void see_flush(gather *g, see_batch *b, double total[3])
{
    if (!b->owners)
        return;
    for (int layer = 0; layer < 2; layer++) {
        vec3f dir[SEE_BATCH], tr[SEE_BATCH];
        float dist[SEE_BATCH];
        int idx[SEE_BATCH], m = 0;
        for (int i = 0; i < b->rays; i++)
            if (b->bg[i] == layer && b->cast[i]) {
                idx[m] = i;
                dir[m] = b->dir[i];
                dist[m++] = b->dist[i];
            }
        if (!m)
            continue;
        accel_transmittance_panes_n(g->rs, g->xo, dir, dist, m, layer, tr, NULL);
        for (int k = 0; k < m; k++)
            b->seen[idx[k]] = g->rs->pane_count ? (tr[k].x + tr[k].y + tr[k].z) * (1.0f / 3.0f)
                                                : tr[k].x;
    }
    b->owner_first[b->owners] = b->rays;
    for (int o = 0; o < b->owners; o++) {
        double seen = 0;
        for (int i = b->owner_first[o]; i < b->owner_first[o + 1]; i++)
            seen += b->w[i] * (b->cast[i] ? (double)b->seen[i] : 0.0);
        double sh = b->owner_wsum[o] > 0 ? seen / b->owner_wsum[o] : 0;
        cand *c = b->owner[o];
        c->seen = (float)sh;
        for (int ch = 0; ch < 3; ch++) {
            float e = (float)(c->est[ch] * sh);
            total[ch] += (double)e - c->est[ch];
            c->est[ch] = e;
        }
    }
    b->rays = b->owners = 0;
}

/* see() for every candidate of c[0..count), their rays cast together. */
static void see_all(gather *g, cand *c, int count, double total[3])
{
    see_batch b;
    b.rays = b.owners = 0;
    for (int h = 0; h < count; h++) {
        if (c[h].seen != -1 || !(lumf(c[h].est) > 0)) {
            if (c[h].seen == -1)
                c[h].seen = -2;
            continue;
        }
        const sender_node *node = &g->t->nodes[cand_node(&c[h])];
        if (node->count > SEE_TARGETS_MAX) {
            /* (Its rays one by one, after the batch's: the same order.) */
            see_flush(g, &b, total);
            see(g, &c[h], total);
            continue;
        }
        see_target tg[SEE_TARGETS_MAX];
        double wsum;
        int m = seen_targets(g, node, tg, &wsum);
        /* (A candidate may bring no ray: a leaf whose facing elements are
         * dark.  The batch is full at SEE_BATCH candidates too.) */
        if (b.rays + m > SEE_BATCH || b.owners == SEE_BATCH)
            see_flush(g, &b, total);
        c[h].seen = -2;
        b.owner[b.owners] = &c[h];
        b.owner_wsum[b.owners] = wsum;
        b.owner_first[b.owners++] = b.rays;
        for (int i = 0; i < m; i++) {
            vec3f d = f3_sub(v3_to_f3(tg[i].to), g->xo);
            float dist = f3_length(d);
            b.w[b.rays] = tg[i].w;
            b.bg[b.rays] = (unsigned char)tg[i].background;
            b.cast[b.rays] = dist > 0.0f;
            if (dist > 0.0f) {
                g->st->rays++;
                b.dir[b.rays] = f3_scale(d, 1.0f / dist);
                b.dist[b.rays] = dist * 0.9999f;
            }
            b.rays++;
        }
    }
    see_flush(g, &b, total);
}

/* A max-heap on err, ties to the lower node index (a fixed order). */
static int above(const cand *a, const cand *b)
{
    return a->key > b->key;
}

static void heap_push(cand *h, int *n, cand c)
{
    int i = (*n)++;
    while (i > 0) {
        int p = (i - 1) / 2;
        if (!above(&c, &h[p]))
            break;
        h[i] = h[p];
        i = p;
    }
    h[i] = c;
}

/* Puts `last` at i or below, the subtrees below i being heaps. */
static void heap_sift(cand *h, int n, int i, cand last)
{
    for (;;) {
        int l = 2 * i + 1, r = l + 1, m = i;
        const cand *best = &last;
        if (l < n && above(&h[l], best)) {
            m = l;
            best = &h[l];
        }
        if (r < n && above(&h[r], best))
            m = r;
        if (m == i)
            break;
        h[i] = h[m];
        i = m;
    }
    h[i] = last;
}

static cand heap_pop(cand *h, int *n)
{
    cand top = h[0], last = h[--*n];
    heap_sift(h, *n, 0, last);
    return top;
}

/* What a cut leaves for a nearby receiver (cut_record). */
static void record(cut_record *rec, int32_t node, float seen)
{
    if (!rec || rec->failed)
        return;
    if (rec->n == rec->cap) {
        int cap = rec->cap ? 2 * rec->cap : 1024;
        cut_entry *e = realloc(rec->e, (size_t)cap * sizeof *e);
        if (!e) {
            rec->failed = 1;
            return;
        }
        rec->e = e;
        rec->cap = cap;
    }
    rec->e[rec->n++] = (cut_entry){node, seen};
}

/* A cut's state: the clusters in it, in a heap by bound; the sum of their
 * estimates and of the elements taken exactly. */
typedef struct cut_state {
    cand heap[HEAP_MAX];
    int hn;
    double total[3], exact[3];
} cut_state;

/* A leaf's elements, exactly. */
static void take_exactly(gather *g, int32_t left, int32_t count, vec3 x, vec3 n,
                         const cut_params *c, cut_state *s, double whole)
{
    int first = -1 - left;
    for (int i = first; i < first + count; i++) {
        g->st->clusters++;
        c->leaf(c->user, i, x, n, whole, s->exact, g->st);
    }
}

/* Opens the worst cluster while its bound exceeds eps times the total (or
 * the floor), at most max_cut times; then every cluster left is seen, and
 * the cut is recorded in rec (if any). */
static vec3 refine(gather *g, cut_state *s, vec3 x, vec3 n, const cut_params *c,
                   cut_record *rec)
{
    const sender_tree *t = g->t;
    cut_stats *st = g->st;
    cand *heap = s->heap;
    double *total = s->total;
    int cut = 0;
    /* A cluster's rays are cast only when it may stay in the cut (its
     * bound within the limit when it is made, or at the end): about half
     * the clusters made are opened again, and their rays were wasted. */
    while (s->hn > 0) {
        double limit = c->eps * dmax(lum(total) + lum(s->exact), c->floor);
        if (cand_err(&heap[0]) <= limit)
            break;
        if (cut >= c->max_cut && cand_err(&heap[0]) < INFINITY) {
            st->capped++;
            break;
        }
        cand top = heap_pop(heap, &s->hn);
        double whole = lum(total) + lum(s->exact);
        /* The next clusters to open are near the heap's top: their
         * children's records, from anywhere in the tree, are fetched while
         * this one's are weighed. */
        for (int h = 0; h < 3 && h < s->hn; h++)
            if (heap[h].count == 0) {
                __builtin_prefetch(&t->nodes[heap[h].left]);
                __builtin_prefetch(&t->nodes[heap[h].left + 1]);
                __builtin_prefetch(&t->light[heap[h].left]);
                __builtin_prefetch(&t->light[heap[h].left + 1]);
            }
        for (int ch = 0; ch < 3; ch++)
            total[ch] -= top.est[ch];
        if (top.count > 0) {
            take_exactly(g, top.left, top.count, x, n, c, s, whole);
            record(rec, cand_node(&top), CUT_EXACT);
            continue;
        }
        cut++;
        for (int k = 0; k < 2; k++) {
            cand ch;
            evaluate(g, top.left + k, &ch);
            if (!(cand_err(&ch) > 0) && !(lumf(ch.est) > 0))
                continue;
            for (int q = 0; q < 3; q++)
                total[q] += ch.est[q];
            if (cand_err(&ch) <= limit || s->hn >= HEAP_MAX)
                see(g, &ch, total);
            if (s->hn >= HEAP_MAX) {
                /* No room: it stays as estimated (it is in). */
                record(rec, top.left + k, ch.seen);
                continue;
            }
            heap_push(heap, &s->hn, ch);
        }
    }
    see_all(g, heap, s->hn, total);
    for (int h = 0; h < s->hn; h++)
        record(rec, cand_node(&heap[h]), heap[h].seen);
    return v3(dmax(0.0, total[0] + s->exact[0]), dmax(0.0, total[1] + s->exact[1]),
              dmax(0.0, total[2] + s->exact[2]));
}

vec3 cut_gather(const sender_tree *t, const rscene *rs, vec3 x, vec3 n, vec3f xo,
                const cut_params *c, cut_stats *st, cut_record *rec)
{
    if (rec) {
        rec->n = 0;
        rec->failed = 0;
    }
    if (t->node_count == 0 || !(t->total_power > 0))
        return v3(0, 0, 0);
    gather g = {t, rs, v3_to_f3(x), v3_to_f3(n), xo, st};
    cut_state s;
    s.hn = 0;
    cand root;
    evaluate(&g, 0, &root);
    for (int ch = 0; ch < 3; ch++) {
        s.total[ch] = root.est[ch];
        s.exact[ch] = 0;
    }
    if (cand_err(&root) > 0 || lumf(root.est) > 0)
        heap_push(s.heap, &s.hn, root);
    return refine(&g, &s, x, n, c, rec);
}

vec3 cut_resume(const sender_tree *t, const rscene *rs, vec3 x, vec3 n, vec3f xo,
                const cut_record *from, const cut_params *c, cut_stats *st)
{
    if (t->node_count == 0 || !(t->total_power > 0))
        return v3(0, 0, 0);
    gather g = {t, rs, v3_to_f3(x), v3_to_f3(n), xo, st};
    cut_state s;
    s.hn = 0;
    for (int ch = 0; ch < 3; ch++)
        s.total[ch] = s.exact[ch] = 0;
    for (int i = 0; i < from->n; i++) {
        const cut_entry *e = &from->e[i];
        const sender_node *node = &t->nodes[e->node];
        if (e->seen == CUT_EXACT) {
            take_exactly(&g, node->left, node->count, x, n, c, &s, 0.0);
            continue;
        }
        cand ch;
        evaluate(&g, e->node, &ch);
        if (!(cand_err(&ch) > 0) && !(lumf(ch.est) > 0))
            continue;
        if (e->seen >= 0) {
            /* The nearby receiver's rays stand for this one's. */
            for (int q = 0; q < 3; q++)
                ch.est[q] *= e->seen;
            ch.seen = e->seen;
        }
        for (int q = 0; q < 3; q++)
            s.total[q] += ch.est[q];
        if (s.hn < HEAP_MAX)
            s.heap[s.hn++] = ch;
        else
            see(&g, &ch, s.total);
    }
    for (int i = s.hn / 2 - 1; i >= 0; i--)
        heap_sift(s.heap, s.hn, i, s.heap[i]);
    return refine(&g, &s, x, n, c, NULL);
}
