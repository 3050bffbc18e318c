/* The sky's light at a point (sky_gather.h). */
#include "zone/light/sky_gather.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/ray_offset.h"
#include "geom/transmittance.h"
#include "light/distant.h"
#include "light/env_map.h"
#include "util/sampler.h"
#include "util/simd4.h"
#include "util/vec3_convert.h"
#include "zone/light/direct.h"
#include "zone/light/sky_portals.h"

#define PI 3.14159265358979323846

/* n directions drawn from the map (a Hammersley set through its own
 * sampling, so that a small bright patch gets its share of them, shifted
 * on the unit square by (s1, s2)), each with its radiance / (density x n);
 * returns how many carry light. */
static int map_directions(const rscene *rs, int n, double s1, double s2, vec3f *dirs,
                          vec3f *weight)
{
    int k = 0;
    for (int i = 0; i < n; i++) {
        uint32_t b = sampler_reverse_bits((uint32_t)i);
        double u1 = (i + 0.5) / n + s1, u2 = b * (1.0 / 4294967296.0) + s2;
        float u[2] = {(float)(u1 - floor(u1)), (float)(u2 - floor(u2))};
        vec3f w, l;
        float pdf = distant_map_sample(&rs->distant, u, &w, &l);
        if (pdf <= 0.0f)
            continue;
        dirs[k] = w;
        weight[k++] = f3_scale(l, 1.0f / (pdf * (float)n));
    }
    return k;
}

static int sky_set_build(zone_sky_set *s, const rscene *rs, int n, double s1, double s2)
{
    s->dirs = malloc((size_t)n * sizeof *s->dirs);
    s->weight = malloc((size_t)n * sizeof *s->weight);
    if (!s->dirs || !s->weight)
        return 0;
    s->count = map_directions(rs, n, s1, s2, s->dirs, s->weight);
    size_t stride = ((size_t)s->count + ZONE_SKY_RUN - 1) / ZONE_SKY_RUN * ZONE_SKY_RUN;
    s->soa_stride = stride;
    s->soa = calloc(6 * (stride ? stride : 1), sizeof *s->soa);
    if (!s->soa)
        return 0;
    for (int k = 0; k < s->count; k++) {
        const float v[6] = {s->dirs[k].x,   s->dirs[k].y,   s->dirs[k].z,
                            s->weight[k].x, s->weight[k].y, s->weight[k].z};
        for (int row = 0; row < 6; row++)
            s->soa[(size_t)row * stride + (size_t)k] = v[row];
    }
    return 1;
}

static void sky_set_free(zone_sky_set *s)
{
    free(s->dirs);
    free(s->weight);
    free(s->soa);
    memset(s, 0, sizeof *s);
}

/* The map's irradiance on an open surface of every normal of the table. */
static int sky_open_table(zone_forest *f, const rscene *rs)
{
    int m = ZONE_SKY_TABLE_SAMPLES;
    f->sky_open = malloc((size_t)ZONE_SKY_TABLE_W * ZONE_SKY_TABLE_H * 3 * sizeof(float));
    vec3f *dirs = malloc((size_t)m * sizeof *dirs), *weight = malloc((size_t)m * sizeof *weight);
    if (!f->sky_open || !dirs || !weight) {
        free(dirs);
        free(weight);
        return 0;
    }
    int count = map_directions(rs, m, 0.0, 0.0, dirs, weight);
    for (int j = 0; j < ZONE_SKY_TABLE_H; j++)
        for (int i = 0; i < ZONE_SKY_TABLE_W; i++) {
            vec3f nrm = env_map_direction((i + 0.5f) / ZONE_SKY_TABLE_W,
                                          (j + 0.5f) / ZONE_SKY_TABLE_H);
            double e[3] = {0, 0, 0};
            for (int k = 0; k < count; k++) {
                float c = f3_dot(nrm, dirs[k]);
                if (c > 0.0f) {
                    e[0] += weight[k].x * c;
                    e[1] += weight[k].y * c;
                    e[2] += weight[k].z * c;
                }
            }
            float *t = f->sky_open + 3 * ((size_t)j * ZONE_SKY_TABLE_W + i);
            for (int ch = 0; ch < 3; ch++)
                t[ch] = (float)e[ch];
        }
    free(dirs);
    free(weight);
    return 1;
}

/* The shift of mesh nodes' set v: a low-discrepancy sequence over the
 * unit square (the plastic number's R2), so that the sets fall between
 * one another's points. */
static void node_set_shift(int v, double *s1, double *s2)
{
    double a1 = 0.7548776662466927, a2 = 0.5698402909980532;
    *s1 = fmod(v * a1, 1.0);
    *s2 = fmod(v * a2, 1.0);
}

int zone_sky_build(zone_forest *f, const rscene *rs)
{
    int n = f->q.gather, quarter = n / ZONE_MESH_NODE_DIV > 0 ? n / ZONE_MESH_NODE_DIV : 1;
    if (!f->sky)
        return 1;
    /* (Under a map too: a map whose every direction is dark leaves its
     * sets empty, and zone_sky_irradiance then takes the colour's way.) */
    f->node_dirs = zone_gather_directions(quarter);
    f->node_dir_count = quarter;
    if (!f->node_dirs)
        return 0;
    if (!rs->distant.map)
        return 1;
    if (!sky_set_build(&f->sky_set, rs, n, 0.0, 0.0))
        return 0;
    for (int v = 0; v < ZONE_NODE_SKY_SETS; v++) {
        double s1, s2;
        node_set_shift(v, &s1, &s2);
        if (!sky_set_build(&f->node_sky[v], rs, quarter, s1, s2))
            return 0;
    }
    return sky_open_table(f, rs);
}

void zone_sky_free(zone_forest *f)
{
    sky_set_free(&f->sky_set);
    for (int v = 0; v < ZONE_NODE_SKY_SETS; v++)
        sky_set_free(&f->node_sky[v]);
    free(f->sky_open);
    f->sky_open = NULL;
    free(f->node_dirs);
    f->node_dirs = NULL;
    f->node_dir_count = 0;
}

/* The map's irradiance on an open surface of unit normal n: the table
 * read bilinearly between its normals (around in azimuth, clamped at the
 * poles). */
static vec3 sky_open_irradiance(const zone_forest *f, vec3f n)
{
    float u, v;
    env_map_uv(n, &u, &v);
    float fx = u * ZONE_SKY_TABLE_W - 0.5f, fy = v * ZONE_SKY_TABLE_H - 0.5f;
    int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
    float ax = fx - (float)x0, ay = fy - (float)y0;
    vec3 e = v3(0, 0, 0);
    for (int dy = 0; dy < 2; dy++)
        for (int dx = 0; dx < 2; dx++) {
            int xi = ((x0 + dx) % ZONE_SKY_TABLE_W + ZONE_SKY_TABLE_W) % ZONE_SKY_TABLE_W;
            int yi = y0 + dy < 0 ? 0 : (y0 + dy >= ZONE_SKY_TABLE_H ? ZONE_SKY_TABLE_H - 1 : y0 + dy);
            double w = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
            const float *t = f->sky_open + 3 * ((size_t)yi * ZONE_SKY_TABLE_W + xi);
            e = v3_add(e, v3_scale(v3(t[0], t[1], t[2]), w));
        }
    return e;
}

/* The directions of `count` that a point takes: all of them, or for a
 * split point (direct.h) those whose index modulo `stride` is within
 * `width` of its `first`, so that the block's points take them all
 * between them, each direction once, for one point's rays (points
 * `stride` apart share when the block outnumbers them).  Which directions
 * a point takes follows its place in the block, as its pieces of a light
 * do; a point that stands for the 2 x 2 block of points a level finer
 * (DIRECT_SPLIT_BLOCK) takes the four's. */
typedef struct sky_part {
    int first, stride, width;
} sky_part;

static sky_part sky_share(int split, int count)
{
    sky_part p = {0, 1, 1};
    if (!split)
        return p;
    int block = (split & DIRECT_SPLIT_BLOCK) != 0;
    int levels = DIRECT_SPLIT_SKY_LEVELS(split) + block;
    int index = DIRECT_SPLIT_INDEX(split) << (2 * block);
    while (levels-- > 0 && p.stride * 4 <= count)
        p.stride *= 4;
    p.first = index % p.stride;
    p.width = block && p.stride >= 4 ? 4 : 1; /* (a stride of 1 takes all) */
    return p;
}

static int sky_takes(const sky_part *p, int k)
{
    int r = k % p->stride - p->first;
    return r >= 0 && r < p->width;
}

/* Sky rays a point sends to the scene at a time (a run of the environment
 * map's directions). */
#define SKY_PACKET ZONE_SKY_RUN

/* The share of the gather's count that a point aims at portals. */
#define SKY_PORTAL_SHARE 2

/* Portal directions waiting for their rays (sky_through_portals). */
typedef struct portal_rays {
    vec3f o;
    int n;
    vec3f d[SKY_PACKET];
    double weight[SKY_PACKET]; /* share x cosine */
    int portal[SKY_PACKET];
} portal_rays;

/* Casts the waiting rays together and adds to *e the light of those
 * whose first pane is their own portal's. */
static void portal_rays_flush(zone_trace *t, portal_rays *pr, vec3 *e)
{
    const zone_forest *f = t->f;
    const rscene *rs = &t->r->rs;
    float far[SKY_PACKET];
    int pane[SKY_PACKET];
    vec3f tr[SKY_PACKET];
    if (!pr->n)
        return;
    for (int i = 0; i < pr->n; i++)
        far[i] = FLT_MAX;
    t->rays += (uint64_t)pr->n;
    accel_transmittance_panes_n(rs, pr->o, pr->d, far, pr->n, 1, tr, pane);
    for (int i = 0; i < pr->n; i++) {
        if (f3_is_black(tr[i]) || pane[i] < 0 || f->portals.of_prim[pane[i]] != pr->portal[i])
            continue;
        vec3f l = f->sky_set.count ? distant_map_radiance(&rs->distant, pr->d[i]) : rs->sky;
        *e = v3_add(*e, v3_scale(f3_to_v3(f3_mul(l, tr[i])), pr->weight[i]));
    }
    pr->n = 0;
}

/* The sky's light through the portals that a point aims at (sky_portals.h):
 * over each, the directions whose first pane is one of its own.  A split
 * point takes its share of them, as of the gather's. */
static vec3 sky_through_portals(zone_trace *t, vec3 n, vec3f o,
                                const sky_portal_pick *picks, int count)
{
    int total = 0;
    for (int i = 0; i < count; i++)
        total += picks[i].count;
    sky_part mine = sky_share(t->light_split, total);
    vec3 e = v3(0, 0, 0);
    portal_rays pr;
    pr.o = o;
    pr.n = 0;
    int k = 0;
    for (int i = 0; i < count; i++) {
        for (int j = 0; j < picks[i].count; j++, k++) {
            if (!sky_takes(&mine, k))
                continue;
            vec3 d;
            double share = sky_portal_view_direction(&picks[i].view, j, picks[i].count, &d);
            double c = v3_dot(n, d);
            if (!(share > 0) || c <= 0)
                continue;
            pr.d[pr.n] = v3_to_f3(d);
            pr.weight[pr.n] = share * c;
            pr.portal[pr.n++] = picks[i].portal;
            if (pr.n == SKY_PACKET)
                portal_rays_flush(t, &pr, &e);
        }
    }
    portal_rays_flush(t, &pr, &e);
    return v3_scale(e, (double)mine.stride / mine.width);
}

/* Whether the gather's rays along d[0..n) (n <= SKY_PACKET) reach the
 * sky, and with what, into tr: 0 where the portals' estimate takes the
 * direction (sky_portals_claim: that light is theirs).  The rays leave o
 * together (packets). */
static void sky_gather_rays(zone_trace *t, vec3f o, const vec3f *d, int n,
                            const sky_portal_pick *picks, int count, vec3f *tr)
{
    float far[SKY_PACKET];
    int pane[SKY_PACKET];
    for (int i = 0; i < n; i++)
        far[i] = FLT_MAX;
    t->rays += (uint64_t)n;
    accel_transmittance_panes_n(&t->r->rs, o, d, far, n, 1, tr, count ? pane : NULL);
    if (count)
        for (int i = 0; i < n; i++)
            if (pane[i] >= 0 &&
                sky_portals_claim(picks, count, t->f->portals.of_prim[pane[i]], f3_to_v3(d[i])))
                tr[i] = f3_splat(0.0f);
}

/* The cosines of the environment map's directions k0 .. k0 + ZONE_SKY_RUN
 * - 1 with n (0 below the horizon, and for the padding past the last)
 * into c, their weights times them added to all's lanes (r, g, b). */
static void sky_cosines(const zone_sky_set *set, vec3f n, int k0, float *c, f4 all[3])
{
    size_t s = set->soa_stride;
    const float *x = set->soa + k0, *y = x + s, *z = y + s, *wr = z + s, *wg = wr + s,
                *wb = wg + s;
    f4 nx = f4_splat(n.x), ny = f4_splat(n.y), nz = f4_splat(n.z), zero = f4_splat(0.0f);
    for (int j = 0; j < ZONE_SKY_RUN; j += 4) {
        f4 dx, dy, dz, r, g, b;
        memcpy(&dx, x + j, sizeof dx);
        memcpy(&dy, y + j, sizeof dy);
        memcpy(&dz, z + j, sizeof dz);
        memcpy(&r, wr + j, sizeof r);
        memcpy(&g, wg + j, sizeof g);
        memcpy(&b, wb + j, sizeof b);
        f4 cj = f4_max(nx * dx + ny * dy + nz * dz, zero);
        memcpy(c + j, &cj, sizeof cj);
        all[0] += r * cj;
        all[1] += g * cj;
        all[2] += b * cj;
    }
}

/* What the map's directions of `set` above the horizon of n (the split
 * point's share of them) find arriving from o: the sum of weight x cosine
 * x transmittance, standing for all of them; their whole weight x cosine
 * into *sum (which costs no ray). */
static vec3f map_seen(zone_trace *t, const zone_sky_set *set, vec3f n, vec3f o,
                      const sky_portal_pick *picks, int picked, vec3f *sum)
{
    vec3f seen = f3_splat(0.0f);
    sky_part share = sky_share(t->light_split, set->count);
    f4 all[3] = {f4_splat(0.0f), f4_splat(0.0f), f4_splat(0.0f)};
    vec3f dir[ZONE_SKY_RUN], tr[ZONE_SKY_RUN];
    float cosine[ZONE_SKY_RUN];
    int kept[ZONE_SKY_RUN];
    for (int k0 = 0; k0 < set->count; k0 += ZONE_SKY_RUN) {
        sky_cosines(set, n, k0, cosine, all);
        int rays = 0, end = set->count - k0 < ZONE_SKY_RUN ? set->count - k0 : ZONE_SKY_RUN;
        for (int j = 0; j < end; j++)
            if (cosine[j] > 0.0f && sky_takes(&share, k0 + j)) {
                dir[rays] = set->dirs[k0 + j];
                kept[rays++] = j;
            }
        sky_gather_rays(t, o, dir, rays, picks, picked, tr);
        for (int i = 0; i < rays; i++)
            if (!f3_is_black(tr[i]))
                seen = f3_madd(seen, f3_mul(set->weight[k0 + kept[i]], tr[i]), cosine[kept[i]]);
    }
    *sum = f3(f4_hsum(all[0]), f4_hsum(all[1]), f4_hsum(all[2]));
    /* A split point's share of the directions stands for all of them: the
     * block's points together see what one point's would. */
    return f3_scale(seen, (float)share.stride / (float)share.width);
}

vec3 zone_sky_irradiance(zone_trace *t, vec3 x, vec3 n)
{
    const zone_forest *f = t->f;
    const rscene *rs = &t->r->rs;
    vec3f nf = v3_to_f3(n), o = ray_offset(v3_to_f3(x), nf);
    sky_portal_pick picks[SKY_PORTAL_PICKS_MAX];
    int picked = f->portals.count
                     ? sky_portals_pick(&f->portals, x, n, f->q.gather / SKY_PORTAL_SHARE, picks)
                     : 0;
    vec3 portals = picked ? sky_through_portals(t, n, o, picks, picked) : v3(0, 0, 0);
    if (f->sky_set.count) {
        /* An environment map: the open-surface irradiance of the normal,
         * times the share of it that the importance-drawn directions find
         * arriving (a ratio estimate: exact where nothing is in the way;
         * the share's whole is taken over every direction, which costs no
         * ray).  A mesh node takes the shifted set its key names. */
        const zone_sky_set *set =
            t->node_draw ? &f->node_sky[zone_node_set(t->node_draw)] : &f->sky_set;
        vec3f sum, seen = map_seen(t, set, nf, o, picks, picked, &sum);
        /* A quarter set may hold no direction above the node's horizon
         * (a normal turned from where the map's light is): the whole set
         * then measures, or the node would take the open surface's light
         * unshadowed. */
        if (set != &f->sky_set && sum.x <= 0.0f && sum.y <= 0.0f && sum.z <= 0.0f)
            seen = map_seen(t, &f->sky_set, nf, o, picks, picked, &sum);
        vec3 open = sky_open_irradiance(f, nf);
        return v3_add(portals, v3(sum.x > 0.0f ? open.x * seen.x / sum.x : open.x,
                                  sum.y > 0.0f ? open.y * seen.y / sum.y : open.y,
                                  sum.z > 0.0f ? open.z * seen.z / sum.z : open.z));
    }
    /* A sky of one colour: the fixed set about the normal, or a mesh
     * node's quarter set, turned about it by the node's key. */
    const vec3 *dirs = t->node_draw ? f->node_dirs : f->dirs;
    int count = t->node_draw ? f->node_dir_count : f->q.gather;
    vec3 tt, bb;
    v3_frame(n, &tt, &bb);
    if (t->node_draw)
        v3_turn_frame(&tt, &bb, zone_node_turn(t->node_draw));
    vec3f open = f3_splat(0.0f);
    sky_part share = sky_share(t->light_split, count);
    int taken = 0;
    vec3f dir[SKY_PACKET], tr[SKY_PACKET];
    for (int k = share.first; k < count;) {
        int rays = 0;
        for (; k < count && rays < SKY_PACKET; k++) {
            if (!sky_takes(&share, k))
                continue;
            const vec3 *dk = &dirs[k];
            vec3 d = v3_add(v3_add(v3_scale(tt, dk->x), v3_scale(bb, dk->y)), v3_scale(n, dk->z));
            dir[rays++] = v3_to_f3(d);
        }
        sky_gather_rays(t, o, dir, rays, picks, picked, tr);
        for (int i = 0; i < rays; i++)
            open = f3_add(open, tr[i]);
        taken += rays;
    }
    /* Each channel as sky x (pi x count / n): open holds whole counts
     * unless a pane is in the way. */
    return v3_add(portals, v3(rs->sky.x * (PI * open.x / taken), rs->sky.y * (PI * open.y / taken),
                              rs->sky.z * (PI * open.z / taken)));
}

