/* Phase Two, step one: the sample list of every pixel.
 *
 * A pixel whose corner and sub-pixel signatures agree sees one smooth
 * surface: its g x g samples are shaded, each with weight 1/g^2 (a mesh's
 * detail takes 8 x 8, and at g = 1 a busy shadow 2 x 2, each 2 x 2 block
 * sharing one point's rays of direct light).  Where they
 * differ, an edge crosses the pixel: a 16 x 16 grid (32 x 32 at quality 3,
 * 64 x 64 from 4) measures the coverage of each surface (group of equal
 * signatures), and each group is shaded on the samples of a sparse 4 x 4
 * (8 x 8 at quality 4, 16 x 16 from 5) subset that fall in it (or on the
 * point nearest its centroid when it misses the subset), weighted by its
 * coverage; from quality 5 the grid's points are quasi-random.  Where
 * a light is seen in a mirror or through glass, where phase_two_marks.c
 * expects a light's small image in a sphere, or where a sample falls in a
 * refined texel (refine.c), the grid is 64 x 64.  Light
 * parts seen at a corner or a sample, or with a vertex in the pixel, are
 * listed for the exact level-0 coverage. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "geom/transmittance.h"
#include "geom/ray_offset.h"
#include "geom/shapes.h"
#include "render/prim.h"
#include "util/r2.h"
#include "util/vec3_convert.h"
#include "zone/light/direct.h"
#include "zone/phase_two/media.h"
#include "zone/phase_two/phase_two.h"

#define FINE_GRID 64   /* the grid where a light is seen by way of a mirror */
#define FINE_SHADE 16  /* and its shaded samples per side */
#define SEEN_MAX 8     /* light parts listed per pixel */
#define CURVED_GRID 2  /* sub-pixel grid of smooth pixels that see a sphere */
/* and of those that may hold a mesh's sub-pixel detail (fine_detail): one
 * mesh is one signature, so its own detail (a stack of fins) shows no
 * edge, and a few samples alias it.  The pixel's samples share one point's
 * rays of direct light (direct_irradiance_split, by rays in any scene of
 * more than 48 primitives), each taking one of the pieces' centres that
 * point would see: the samples are there to find the mesh's gaps, and the
 * pixel's mean sees as many points of the light as one sample alone.  On
 * the engine room at 512 x 512, depth 3: 4 x 4 samples each with their own
 * rays gave 1.64% per pixel in 6.4 s of Phase Two, 8 x 8 with their own
 * 1.47% in 24 s (without the occluder search's early stop), 8 x 8 sharing by
 * 2 x 2 blocks 1.47% in 8.8 s; sharing by the whole pixel (8 x 8, the
 * default) takes 40% less time than by 2 x 2 blocks, for 0.859% -> 0.871%
 * per pixel (1,024-spp reference, its noise taken out; BENCHMARKS.md). */
#define DETAIL_GRID 8
#define DETAIL_SPLIT 3 /* log2(DETAIL_GRID) */
/* Faces of one mesh that turn more than acos(CREASE_COS) apart (as a
 * mesh's sheets end: mesh_sheet.h) meet at a crease: apart in an edge
 * pixel's groups, and a pixel without an edge takes the detail's 8 x 8. */
#define CREASE_COS 0.707f
/* The geometric normal of primitive p at x, turned toward where ray
 * direction d came from. */
static vec3f facing_normal(const rs_part *p, vec3f x, vec3f d)
{
    vec3f ng = shape_normal(p, x);
    return f3_dot(ng, d) > 0.0f ? f3_neg(ng) : ng;
}

/* Specular steps a signature follows.  Fixed, not the render's depth: the
 * images of levels 0..D must use the same samples as the depth-D image,
 * or they would not add up to it. */
#define SIGNATURE_STEPS 16

/* Which point lights light x (normal n, facing the viewer) as bits: a
 * point light's shadow is hard, and a pixel its edge crosses must be
 * measured like any other edge, not shaded from one sample. */
static uint32_t point_light_bits(const rscene *rs, vec3f x, vec3f n, uint64_t *rays)
{
    uint32_t bits = 0;
    vec3f xo = ray_offset(x, n);
    for (int k = 0; k < rs->point_light_count && k < 32; k++) {
        const rs_part *lp = &rs->parts[rs->point_lights[k]];
        vec3f to = f3_sub(lp->p0, xo);
        float dist = f3_length(to);
        if (f3_dot(to, n) > 0.0f && dist > 0.0f) {
            (*rays)++;
            if (accel_transmittance_mean(rs, xo, f3_scale(to, 1.0f / dist), dist,
                                         lp->background) > 0.0f)
                bits |= 1u << k;
        }
    }
    return bits + 1;
}

/* What a camera ray sees, as a number: the parts along its specular chain
 * (the transmitted branch through glass), and which point lights light its
 * diffuse hits.  Sub-pixel samples with the same
 * signature see one smooth surface; differing ones mark an edge.  *first is
 * the ray's first hit; *curved (unless NULL) is set when the chain meets a
 * sphere, *glint (unless NULL) when it ends on a light after a specular step. */
/* Pixel corners whose camera rays are traced together. */
#define CORNER_RUN 64

static uint32_t signature_from(const rscene *rs, vec3f o, vec3f d, uint64_t *rays,
                               hit *first, int *curved, int *glint, const hit *given)
{
    uint32_t sig = 0x811c9dc5u;
    int inside = -1; /* the refractive object the chain is in */
    for (int k = 0; k <= SIGNATURE_STEPS; k++) {
        hit h = k == 0 && given ? *given : accel_intersect(rs, o, d);
        (*rays)++;
        if (k == 0)
            *first = h;
        /* A mesh's triangles of one material are one surface: the
         * edges between them are not edges of the image. */
        sig = (sig ^ (uint32_t)(h.part < 0 ? 0 : zone_surface_of(rs, h.part) + 1)) * 16777619u;
        if (h.part < 0)
            break;
        rs_part tmp;
        const rs_part *p = rs_prim(rs, h.part, &tmp);
        const rs_object *m = &rs->objects[p->object];
        /* A flat-shaded mesh's creases are edges: its facets join the
         * signature by their plane's direction, so coplanar neighbours (a
         * quad's two triangles) still look like one surface.  A smooth
         * mesh's shading is continuous across its triangles. */
        if (h.part >= rs->part_count && !rs_mesh_of(rs, h.part)->smooth) {
            vec3f gn = shape_normal(p, f3_madd(o, d, h.t));
            uint32_t q = (uint32_t)lrintf(gn.x * 256.0f) * 73856093u ^
                         (uint32_t)lrintf(gn.y * 256.0f) * 19349663u ^
                         (uint32_t)lrintf(gn.z * 256.0f) * 83492791u;
            sig = (sig ^ q) * 16777619u;
        }
        if (curved && p->shape == SHAPE_SPHERE)
            *curved = 1;
        if (p->is_light && k > 0 && glint)
            *glint = 1;
        if (p->is_light)
            break;
        vec3f x = shape_hit_point(p, o, d, h.t);
        vec3f ng = shape_normal(p, x);
        vec3f n = f3_dot(ng, d) < 0.0f ? ng : f3_neg(ng);
        if (m->weight[LOBE_DIFFUSE] > 0.0f && rs->point_light_count)
            sig = (sig ^ point_light_bits(rs, x, n, rays)) * 16777619u;
        /* Partial coverage (alpha): what lies behind is seen too, and its
         * edges are the pixel's. */
        if (__builtin_expect(m->alpha_mode != 0, 0) && rs_coverage_at(rs, h.part, p, m, x) < 1.0f) {
            o = ray_offset(x, f3_neg(n));
            continue;
        }
        if (m->weight[LOBE_DIFFUSE] >= 1.0f)
            break;
        float cos_o = -f3_dot(d, n);
        /* Follow the refracted branch as it bends: a light seen through
         * glass has its edge where the bent ray leaves it, and the coverage
         * grid must find it there.  Entering or leaving is decided by
         * object identity, as in the tracers, so hollow shells work. */
        if (m->thin) {
            /* A pane: the light behind it is seen undeviated, and that is
             * the branch whose edges matter. */
            o = ray_offset(x, f3_neg(n));
            continue;
        }
        int leaving = p->object == inside;
        float eta = leaving ? m->ior : 1.0f / m->ior;
        float sin2_t = eta * eta * (1.0f - cos_o * cos_o);
        if (m->weight[LOBE_REFRACTIVE] > 0.0f && sin2_t < 1.0f) {
            /* The reflected branch is not followed, but a light seen along
             * it (a light's image in the glass) has edges the grid must
             * find: its part joins the signature. */
            vec3f rd = f3_sub(d, f3_scale(n, 2.0f * f3_dot(d, n)));
            hit hr = accel_intersect(rs, ray_offset(x, n), rd);
            (*rays)++;
            rs_part rtmp;
            if (hr.part >= 0 && rs_prim(rs, hr.part, &rtmp)->is_light) {
                sig = (sig ^ (uint32_t)(zone_surface_of(rs, hr.part) + 1) ^ 0x9e3779b9u) *
                      16777619u;
                if (glint)
                    *glint = 1;
            }
            d = media_refract(d, n, cos_o, eta);
            o = ray_offset(x, f3_neg(n));
            inside = leaving ? -1 : p->object;
        } else {
            d = f3_sub(d, f3_scale(n, 2.0f * f3_dot(d, n)));
            o = ray_offset(x, n);
        }
    }
    return sig;
}

/* ... when its first hit is still to be found. */
static uint32_t ray_signature(const rscene *rs, vec3f o, vec3f d, uint64_t *rays, hit *first,
                              int *curved, int *glint)
{
    return signature_from(rs, o, d, rays, first, curved, glint, NULL);
}

typedef struct seen_lights {
    int part[SEEN_MAX];
    double cover[SEEN_MAX]; /* measured coverage, or -1: computed exactly */
    int count;
} seen_lights;

/* Light parts seen in a pixel get their exact coverage; a mesh light's
 * triangles are shaded on the samples instead (a pixel may see many). */
static void note_light(const rscene *rs, seen_lights *s, int part)
{
    if (part < 0 || part >= rs->part_count || !rs->parts[part].is_light)
        return;
    for (int i = 0; i < s->count; i++)
        if (s->part[i] == part)
            return;
    if (s->count < SEEN_MAX) {
        s->cover[s->count] = -1.0;
        s->part[s->count++] = part;
    }
}

static zone_gather_slot gather_slot(const p2_ctx *c, int px, int py, int index, int count)
{
    zone_gather_slot g = {.pixel = (uint32_t)py * (uint32_t)c->c.width + (uint32_t)px,
                          .index = (uint16_t)index,
                          .count = (uint16_t)count,
                          .sample = (uint16_t)index,
                          .samples = (uint16_t)count};
    return g;
}

static int push_one_sample(const rscene *rs_of_row, p2_row *row, vec3f o, vec3f d, hit h,
                           double w, int light_split, zone_gather_slot gather)
{
    if (row->sample_count == row->sample_capacity) {
        size_t cap = row->sample_capacity ? 2 * row->sample_capacity : 1024;
        p2_sample *ns = realloc(row->samples, cap * sizeof *ns);
        if (!ns)
            return 0;
        row->samples = ns;
        row->sample_capacity = cap;
    }
    p2_sample s = {o, d, h.t, h.part, h.part < 0 ? -1 : zone_surface_of(rs_of_row, h.part),
                   light_split, w, gather};
    row->samples[row->sample_count++] = s;
    return 1;
}

/* Surfaces of partial coverage a camera sample is split at, at most. */
#define COVER_LAYERS 8

/* Pushes the sample of weight w whose ray (o, d) first hits h.  A hit of
 * coverage c < 1 (alpha) makes two: the hit with weight c w, and what the
 * ray meets beyond it with the rest (the same again there). */
static int push_sample(const rscene *rs, p2_row *row, vec3f o, vec3f d, hit h, double w,
                       int light_split, zone_gather_slot gather)
{
    for (int k = 0; rs->alpha_count && h.part >= 0 && k < COVER_LAYERS; k++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, h.part, &tmp);
        const rs_object *m = &rs->objects[p->object];
        if (!m->alpha_mode)
            break;
        vec3f x = shape_hit_point(p, o, d, h.t);
        float c = rs_coverage_at(rs, h.part, p, m, x);
        if (c >= 1.0f)
            break;
        if (!push_one_sample(rs, row, o, d, h, w * c, light_split, gather))
            return 0;
        w *= 1.0 - c;
        vec3f ng = shape_normal(p, x);
        o = ray_offset(x, f3_dot(ng, d) > 0.0f ? ng : f3_neg(ng));
        h = accel_intersect(rs, o, d);
    }
    return push_one_sample(rs, row, o, d, h, w, light_split, gather);
}

static int push_lights(p2_row *row, const seen_lights *s)
{
    if (row->light_count + (size_t)s->count > row->light_capacity) {
        size_t cap = row->light_capacity ? 2 * row->light_capacity : 64;
        while (cap < row->light_count + (size_t)s->count)
            cap *= 2;
        int *nl = realloc(row->lights, cap * sizeof *nl);
        if (!nl)
            return 0;
        row->lights = nl;
        double *nc = realloc(row->light_cover, cap * sizeof *nc);
        if (!nc)
            return 0;
        row->light_cover = nc;
        row->light_capacity = cap;
    }
    for (int i = 0; i < s->count; i++) {
        row->lights[row->light_count] = s->part[i];
        row->light_cover[row->light_count++] = s->cover[i];
    }
    return 1;
}

/* Sample (sx, sy)'s point in its 2^levels x 2^levels block (direct.h):
 * base-4 digits, lowest first, each its cell in the 2 x 2 of one level. */
static int split_index(int sx, int sy, int levels)
{
    int index = 0;
    for (int l = 0; l < levels; l++)
        index |= (((sx >> l) & 1) + 2 * ((sy >> l) & 1)) << (2 * l);
    return index;
}

/* Pushes pixel (px, py)'s g x g samples while they all have signature
 * `first`; sets *edge when one does not, *curved when one meets a sphere.
 * With `split` levels, each 2^split x 2^split block of samples shares the
 * rays of one point's direct light (direct_irradiance_split).  Returns 0
 * when out of memory. */
static int grid_samples(const p2_ctx *c, int px, int py, int g, int split, uint32_t first,
                        seen_lights *lights, p2_row *row, uint64_t *rays, int *edge, int *curved)
{
    const rscene *rs = &c->r->rs;
    vec3f org, dir;
    hit h;
    for (int sy = 0; sy < g; sy++)
        for (int sx = 0; sx < g; sx++) {
            cam_ray(&c->c, (float)px + (sx + 0.5f) / g, (float)py + (sy + 0.5f) / g, &org, &dir);
            if (ray_signature(rs, org, dir, rays, &h, curved, NULL) != first)
                *edge = 1;
            note_light(rs, lights, h.part);
            int ls = split ? DIRECT_SPLIT(split, split_index(sx, sy, split)) : 0;
            if (!*edge &&
                !push_sample(rs, row, org, dir, h, 1.0 / (g * g), ls,
                             gather_slot(c, px, py, sy * g + sx, g * g)))
                return 0;
        }
    return 1;
}

/* Whether the 2 x 2 block of a detail pixel's samples (h, x, ng: their
 * hits, points and facing normals) lies on one facet of one mesh: the
 * same surface, normals within about 10 degrees, every point within half
 * a sample's spacing of the first's tangent plane (a fin's rim and the
 * floor of the gap beside it face alike but stand apart), and a material
 * without textures or maps (what they vary within the block, four samples
 * read and one would miss: textured_box's images were 25% further from the
 * reference per pixel when its textured faces' blocks were shaded once). */
#define FACET_COS 0.985f
static int one_facet(const rscene *rs, const hit *h, const vec3f *x, const vec3f *ng,
                     const int at[4], float spacing)
{
    if (rs->alpha_count)
        return 0; /* a sample of partial coverage is two (push_sample) */
    int a = at[0];
    int surface = h[a].part >= rs->part_count ? zone_surface_of(rs, h[a].part) : -1;
    if (surface < 0)
        return 0;
    rs_part first;
    const rs_object *m = &rs->objects[rs_prim(rs, h[a].part, &first)->object];
    if (m->texture || m->maps)
        return 0;
    for (int k = 0; k < 4; k++) {
        int b = at[k];
        rs_part tmp;
        if (h[b].part < rs->part_count || rs_prim(rs, h[b].part, &tmp)->is_light ||
            (k > 0 && zone_surface_of(rs, h[b].part) != surface) ||
            f3_dot(ng[b], ng[a]) < FACET_COS ||
            fabsf(f3_dot(ng[a], f3_sub(x[b], x[a]))) > 0.5f * spacing)
            return 0;
    }
    return 1;
}

/* A mesh detail pixel's DETAIL_GRID x DETAIL_GRID samples (grid_samples'
 * rules: all of signature `first`, sharing one point's direct light), but
 * a 2 x 2 block of them on one facet is shaded once, by one of its four
 * with the block's weight (which one turns with the block, so that the
 * pixel's shaded points keep the samples' mean place).  It stands for the
 * four (DIRECT_SPLIT_BLOCK): it takes the light's pieces their rays would
 * take between them, their sky directions and their gathered directions
 * (gather.c), so the pixel sees what its 64 samples see, from fewer
 * points.  The grid is there to find where the mesh's sheets change within
 * the pixel; a block on one facet holds no such change.  On the engine
 * room at 512 x 512 a detail pixel shades 19 points instead of 64, and
 * Phase Two takes 0.87 of its time for 0.779% -> 0.795% per pixel and the
 * same error over 4 x 4 blocks (BENCHMARKS.md). */
static int detail_samples(const p2_ctx *c, int px, int py, uint32_t first, seen_lights *lights,
                          p2_row *row, uint64_t *rays, int *edge, int *curved)
{
    const rscene *rs = &c->r->rs;
    enum { G = DETAIL_GRID, N = DETAIL_GRID * DETAIL_GRID };
    vec3f org[N], dir[N], x[N], ng[N];
    hit h[N], near[N];
    for (int i = 0; i < N; i++) {
        /* Two grid rows' first hits are traced together. */
        if (i % (2 * G) == 0) {
            for (int j = i; j < i + 2 * G; j++)
                cam_ray(&c->c, (float)px + (j % G + 0.5f) / G, (float)py + (j / G + 0.5f) / G,
                        &org[j], &dir[j]);
            accel_intersect_rays(rs, org + i, dir + i, 2 * G, near + i);
        }
        if (signature_from(rs, org[i], dir[i], rays, &h[i], curved, NULL, &near[i]) != first) {
            *edge = 1;
            return 1;
        }
        note_light(rs, lights, h[i].part);
        x[i] = f3_madd(org[i], dir[i], h[i].t);
        rs_part tmp;
        ng[i] = h[i].part >= 0 ? facing_normal(rs_prim(rs, h[i].part, &tmp), x[i], dir[i])
                               : f3_splat(0.0f);
    }
    const double w = 1.0 / N;
    for (int by = 0; by < G / 2; by++)
        for (int bx = 0; bx < G / 2; bx++) {
            int at[4] = {2 * by * G + 2 * bx, 2 * by * G + 2 * bx + 1, (2 * by + 1) * G + 2 * bx,
                         (2 * by + 1) * G + 2 * bx + 1};
            float spacing = c->pixel_angle * (h[at[0]].t + c->screen_dist) / G;
            if (one_facet(rs, h, x, ng, at, spacing)) {
                int i = at[(bx + 2 * by) & 3];
                int ls = DIRECT_SPLIT(DETAIL_SPLIT - 1, split_index(bx, by, DETAIL_SPLIT - 1)) |
                         DIRECT_SPLIT_BLOCK;
                zone_gather_slot slot = gather_slot(c, px, py, i, N);
                slot.block_first = (uint16_t)at[0];
                slot.block_width = G;
                if (!push_sample(rs, row, org[i], dir[i], h[i], 4 * w, ls, slot))
                    return 0;
                continue;
            }
            for (int k = 0; k < 4; k++) {
                int i = at[k];
                int ls = DIRECT_SPLIT(DETAIL_SPLIT, split_index(i % G, i / G, DETAIL_SPLIT));
                if (!push_sample(rs, row, org[i], dir[i], h[i], w, ls,
                                 gather_slot(c, px, py, i, N)))
                    return 0;
            }
        }
    return 1;
}

/* Scratch for one edge pixel's coverage grid (about 160 KB). */
typedef struct edge_grid {
    uint32_t sig[FINE_GRID * FINE_GRID], group_sig[FINE_GRID * FINE_GRID];
    hit hits[FINE_GRID * FINE_GRID];
    int group_of[FINE_GRID * FINE_GRID], group_count[FINE_GRID * FINE_GRID];
    int group_shaded[FINE_GRID * FINE_GRID];
    int group_next[FINE_GRID * FINE_GRID]; /* the next shaded point's ordinal */
    vec3f group_n[FINE_GRID * FINE_GRID]; /* a mesh group's facing (else 0) */
} edge_grid;

/* Point i of an edge pixel's n x n coverage points, in [0, 1)^2: the
 * centre of cell i, or the i-th point of Roberts' R2 sequence, which lines
 * up with no edge direction. */
static void cover_point(int quasi, int n, int i, float *u, float *v)
{
    if (quasi) {
        double a, b;
        r2_point(i, &a, &b);
        *u = (float)a;
        *v = (float)b;
    } else {
        *u = (i % n + 0.5f) / n;
        *v = (i / n + 0.5f) / n;
    }
}

/* Whether coverage point i is shaded: every (n / shade)-th cell per side,
 * or the first shade^2 points of the sequence. */
static int cover_shaded(int quasi, int n, int shade, int i)
{
    if (quasi)
        return i < shade * shade;
    int step = n / shade, sx = i % n, sy = i / n;
    return sx % step == step / 2 && sy % step == step / 2;
}

/* Samples of an edge pixel from n x n coverage points, shaded on a
 * shade x shade subset.  *glint is set when some sub-pixel sees a light by
 * way of a specular surface, *rim when a light and a sphere are both seen
 * first.  With `measure`, the lights' coverage is taken from the grid. */
static int edge_samples(const p2_ctx *c, int px, int py, int n, int shade, edge_grid *e,
                        seen_lights *lights, p2_row *row, uint64_t *rays, int *glint,
                        int *rim, int measure)
{
    int saw_light = 0, saw_sphere = 0;
    const rscene *rs = &c->r->rs;
    const int cells = n * n, quasi = c->f->q.cover_quasi;
    /* A mesh's group is shaded as a detail pixel is (its own sub-pixel
     * detail shows no edge, as a shadow across a sunlit sill): on the 8 x 8
     * subset, its points sharing one point's light rays and sky directions
     * (by their ordinal in the group, below).  Its gathers are shared by
     * 2 x 2 blocks only, reading the pixels' gather records as the 4 x 4
     * subset's points do. */
    const int mesh_shade =
        shade < DETAIL_GRID && (quasi || n % DETAIL_GRID == 0) ? DETAIL_GRID : shade;
    int groups = 0;
    vec3f org, dir;
    float u, v;
    for (int i = 0; i < cells; i++) {
        int via = 0;
        cover_point(quasi, n, i, &u, &v);
        cam_ray(&c->c, (float)px + u, (float)py + v, &org, &dir);
        e->sig[i] = ray_signature(rs, org, dir, rays, &e->hits[i], NULL, &via);
        *glint |= via;
        note_light(rs, lights, e->hits[i].part);
        if (e->hits[i].part >= 0) {
            rs_part tmp;
            const rs_part *hp = rs_prim(rs, e->hits[i].part, &tmp);
            saw_light |= hp->is_light;
            saw_sphere |= !hp->is_light && hp->shape == SHAPE_SPHERE;
        }
        /* A mesh's faces that turn apart by a crease are groups of their
         * own (its signature is one): the light on either side may differ
         * by a step (a sunlit sill above a shaded wall), and each side's
         * coverage is then measured instead of guessed from the subset's
         * few samples that fall on it. */
        int mesh = e->hits[i].part >= rs->part_count;
        rs_part tmp;
        vec3f ng = mesh ? facing_normal(rs_prim(rs, e->hits[i].part, &tmp),
                                        f3_madd(org, dir, e->hits[i].t), dir)
                        : f3_splat(0.0f);
        int k = 0;
        while (k < groups && (e->group_sig[k] != e->sig[i] ||
                              (mesh && f3_dot(e->group_n[k], ng) < CREASE_COS)))
            k++;
        if (k == groups) {
            e->group_sig[k] = e->sig[i];
            e->group_count[k] = 0;
            e->group_shaded[k] = 0;
            e->group_next[k] = 0;
            e->group_n[k] = ng;
            groups++;
        }
        e->group_of[i] = k;
        e->group_count[k]++;
        if (cover_shaded(quasi, n, mesh ? mesh_shade : shade, i))
            e->group_shaded[k]++;
    }
    *rim = saw_light && saw_sphere;
    if (measure)
        for (int l = 0; l < lights->count; l++) {
            int count = 0;
            for (int i = 0; i < cells; i++)
                count += e->hits[i].part == lights->part[l];
            lights->cover[l] = (double)count / cells;
        }
    /* The subset's samples, weighted by their group's coverage. */
    size_t first_sample = row->sample_count;
    for (int i = 0; i < cells; i++) {
        int k = e->group_of[i];
        int detail = e->hits[i].part >= rs->part_count && mesh_shade > shade;
        if (!cover_shaded(quasi, n, detail ? mesh_shade : shade, i))
            continue;
        cover_point(quasi, n, i, &u, &v);
        cam_ray(&c->c, (float)px + u, (float)py + v, &org, &dir);
        double w = (double)e->group_count[k] / ((double)e->group_shaded[k] * cells);
        int ls = 0;
        zone_gather_slot slot = gather_slot(c, px, py, 0, 1);
        if (detail) {
            int step = n / DETAIL_GRID;
            int sx = quasi ? i % DETAIL_GRID : i % n / step;
            int sy = quasi ? i / DETAIL_GRID : i / n / step;
            int place = split_index(sx, sy, DETAIL_SPLIT);
            /* The group's points in turn (ordinal o of its m) take the
             * light's pieces and the sky's directions that points 0..m-1
             * of a block take: the group as a whole sees one point's
             * directions, whatever part of the pixel it covers, each
             * point 1/4^k of them (4^k <= m; points 4^k apart share). */
            int m = e->group_shaded[k], o = e->group_next[k]++, sky = 0;
            while (sky < DETAIL_SPLIT && (4 << (2 * sky)) <= m)
                sky++;
            ls = DIRECT_SPLIT_SKY(DETAIL_SPLIT, sky, o);
            slot = gather_slot(c, px, py, place % 4, 4);
        }
        if (!push_sample(rs, row, org, dir, e->hits[i], w, ls, slot))
            return 0;
    }
    /* Surfaces too small to meet the subset: the point nearest their
     * centroid (their first point lies on their rim, where what they show
     * can differ most from their mean). */
    for (int k = 0; k < groups; k++) {
        if (e->group_shaded[k])
            continue;
        double cx = 0, cy = 0;
        for (int i = 0; i < cells; i++)
            if (e->group_of[i] == k) {
                cover_point(quasi, n, i, &u, &v);
                cx += u;
                cy += v;
            }
        cx /= e->group_count[k];
        cy /= e->group_count[k];
        int best = -1;
        double best_d2 = 1e300;
        for (int i = 0; i < cells; i++) {
            if (e->group_of[i] != k)
                continue;
            cover_point(quasi, n, i, &u, &v);
            double dx = u - cx, dy = v - cy, d2 = dx * dx + dy * dy;
            if (d2 < best_d2) {
                best = i;
                best_d2 = d2;
            }
        }
        cover_point(quasi, n, best, &u, &v);
        cam_ray(&c->c, (float)px + u, (float)py + v, &org, &dir);
        if (!push_sample(rs, row, org, dir, e->hits[best], (double)e->group_count[k] / cells, 0,
                         gather_slot(c, px, py, 0, 1)))
            return 0;
    }
    /* Each sample's place among the pixel's (its gathers keep a whole set
     * of their own). */
    size_t n_pushed = row->sample_count - first_sample;
    for (size_t i = 0; i < n_pushed; i++) {
        row->samples[first_sample + i].gather.sample = (uint16_t)i;
        row->samples[first_sample + i].gather.samples = (uint16_t)n_pushed;
    }
    return 1;
}

/* Whether a pixel that sees one mesh may hold its sub-pixel detail: the
 * distances at its corners and sample spread by more than DETAIL_STEPS
 * times the pixel's width there, as where a stack of fins shows its gaps
 * (and where a surface is tilted more than about 20 degrees from the view),
 * or a crease crosses it (a corner's face turns from the sample's by more
 * than acos(CREASE_COS)), where the light may step from one face to the
 * other.
 * On the engine room's level 1 at 512 x 512 against a 512-spp path image:
 * 3 pixel widths 9.1% per pixel, 1 width 7.4%, half a width 4.3% (0.96%
 * over 4 x 4 blocks; without the test 12.1%), for 1.23 times the job's time.
 * The creases took the whole image at depth 3 from 0.828% to 0.760% per
 * pixel (BENCHMARKS.md). */
#define DETAIL_STEPS 0.5f
static int fine_detail(const p2_ctx *c, const float ct[4], const int cp[4], const p2_sample *s,
                       size_t n)
{
    const rscene *rs = &c->r->rs;
    if (n == 0 || s[0].part < rs->part_count)
        return 0;
    float lo = s[0].t, hi = s[0].t;
    for (int k = 0; k < 4; k++) {
        if (ct[k] < 0)
            return 0;
        lo = fminf(lo, ct[k]);
        hi = fmaxf(hi, ct[k]);
    }
    if (hi - lo > DETAIL_STEPS * c->pixel_angle * (s[0].t + c->screen_dist))
        return 1;
    /* Both faces turned toward the eye along the sample's ray (a pixel's
     * rays are near enough parallel); a mesh's primitives are triangles,
     * whose normal is the same at every point. */
    rs_part tmp;
    vec3f ns = facing_normal(rs_prim(rs, s[0].part, &tmp), f3_madd(s[0].o, s[0].d, s[0].t), s[0].d);
    for (int k = 0; k < 4; k++) {
        if (cp[k] == s[0].part || cp[k] < rs->part_count)
            continue;
        vec3f nk = facing_normal(rs_prim(rs, cp[k], &tmp), f3_madd(s[0].o, s[0].d, ct[k]), s[0].d);
        if (f3_dot(ns, nk) < CREASE_COS)
            return 1;
    }
    return 0;
}

/* Whether sample s sees a diffuse surface that some light (switched on or
 * off: the images of single lights use the same samples) lights through
 * more occluders than direct light clips, so that it is seen by rays: a
 * shadow that busy (the engine room's fins on its floor) can change within
 * a pixel, so the pixel takes 2 x 2 samples sharing one point's rays.
 * Not made with a light tree (many light parts): a loop over them all
 * per pixel would cost more than the samples. */
static int busy_shadow(const p2_ctx *c, const p2_sample *s)
{
    const rscene *rs = &c->r->rs;
    if (s->part < 0 || c->f->light_tree.elem_count > 0 ||
        c->f->direct.occ->prim_count <= DIRECT_MAX_OCCLUDERS)
        return 0;
    rs_part tmp;
    const rs_part *p = rs_prim(rs, s->part, &tmp);
    if (p->is_light || !(rs->objects[p->object].weight[LOBE_DIFFUSE] > 0.0f))
        return 0;
    vec3f x = f3_madd(s->o, s->d, s->t), ng = facing_normal(p, x, s->d);
    for (int i = 0; i < rs->light_count; i++)
        if (direct_by_rays(&c->f->direct, rs->lights[i].part, f3_to_v3(x), f3_to_v3(ng)))
            return 1;
    return 0;
}

/* The samples of pixel (px, py) given its corner signatures. */
static int pixel_samples(const p2_ctx *c, int px, int py, const uint32_t corners[4],
                         const float ct[4], const int cp[4], seen_lights *lights, p2_row *row,
                         edge_grid **scratch, uint64_t *rays)
{
    row->kind[px] = ZT_PIXEL_ONE;
    int g = c->g;
    uint32_t first = corners[0];
    int edge = corners[1] != first || corners[2] != first || corners[3] != first ||
               (c->marks && c->marks->vertex[(size_t)py * c->c.width + px]);
    /* A light's image may fall here, too small for the signatures. */
    int marked = c->marks && c->marks->fine[(size_t)py * c->c.width + px];
    size_t start = row->sample_count;
    int curved = 0;
    int probe = c->f->q.probe;
    if (!edge && !marked && probe > g) {
        /* More signatures than samples: a thin surface or a sliver of
         * light between shadows can pass between the g x g samples. */
        const rscene *rs = &c->r->rs;
        for (int k = 0; k < probe * probe && !edge; k++) {
            vec3f org, dir;
            hit h;
            cam_ray(&c->c, (float)px + (k % probe + 0.5f) / probe,
                    (float)py + (k / probe + 0.5f) / probe, &org, &dir);
            edge = ray_signature(rs, org, dir, rays, &h, NULL, NULL) != first;
        }
    }
    if (!grid_samples(c, px, py, g, 0, first, lights, row, rays, &edge, &curved))
        return 0;
    if (!edge && curved && g < CURVED_GRID) {
        /* A sphere on the way: what the pixel sees (a reflection, a
         * refraction, shading over a curved surface) changes within it
         * faster than one sample can tell. */
        row->sample_count = start;
        row->kind[px] = ZT_PIXEL_CURVED;
        if (!grid_samples(c, px, py, CURVED_GRID, 0, first, lights, row, rays, &edge, &curved))
            return 0;
    }
    if (!edge && !marked && g < DETAIL_GRID &&
        fine_detail(c, ct, cp, row->samples + start, row->sample_count - start)) {
        row->sample_count = start;
        row->kind[px] = ZT_PIXEL_DETAIL;
        if (!detail_samples(c, px, py, first, lights, row, rays, &edge, &curved))
            return 0;
    }
    if (!edge && !marked && g == 1 && row->sample_count - start == 1 &&
        busy_shadow(c, &row->samples[start])) {
        row->sample_count = start;
        row->kind[px] = ZT_PIXEL_SHADOW;
        if (!grid_samples(c, px, py, 2, 1, first, lights, row, rays, &edge, &curved))
            return 0;
    }
    if (!edge && !marked)
        return 1;
    row->sample_count = start;
    row->kind[px] = ZT_PIXEL_EDGE;

    if (!*scratch && !(*scratch = malloc(sizeof(edge_grid))))
        return 0;
    int glint = 0, rim = 0;
    if (!edge_samples(c, px, py, c->f->q.edge_grid, c->f->q.edge_shade, *scratch, lights, row,
                      rays, &glint, &rim, 0))
        return 0;
    if (glint || rim || marked) {
        /* A light seen in a mirror or through glass: its image is the
         * brightest thing around and often a few sub-pixels wide, so its
         * coverage is measured on a grid 16 times as fine, and shaded on
         * 16 times as many samples (near a sphere's rim what it shows
         * swings fast).  A light beside a sphere: the exact coverage
         * outlines the sphere by a polygon, the grid by rays; the two would
         * leave slivers between them, so both come from the fine grid. */
        row->sample_count = start;
        row->kind[px] = ZT_PIXEL_FINE;
        if (!edge_samples(c, px, py, FINE_GRID, FINE_SHADE, *scratch, lights, row, rays, &glint,
                          &rim, rim))
            return 0;
    }
    return 1;
}

int p2_row_build(const p2_ctx *c, int y, p2_row *row, uint64_t *rays)
{
    const rscene *rs = &c->r->rs;
    int w = c->c.width, w1 = w + 1;
    if (!row->pixel_first) {
        row->width = w;
        row->pixel_first = malloc((size_t)w1 * sizeof *row->pixel_first);
        row->light_first = malloc((size_t)w1 * sizeof *row->light_first);
        row->corner = malloc(2 * (size_t)w1 * sizeof *row->corner);
        row->corner_part = malloc(2 * (size_t)w1 * sizeof *row->corner_part);
        row->corner_t = malloc(2 * (size_t)w1 * sizeof *row->corner_t);
        row->kind = malloc((size_t)w);
        if (!row->pixel_first || !row->light_first || !row->corner || !row->corner_part ||
            !row->corner_t || !row->kind)
            return 0;
    }
    row->sample_count = 0;
    row->light_count = 0;
    /* Edge pixels' grids: scratch for this row only, as the zone strategy
     * keeps every row of the image. */
    edge_grid *scratch = NULL;
    /* Signatures at the pixel corners of this row (top and bottom), the
     * first hits of a run of neighbouring corners traced together. */
    for (int k0 = 0; k0 < 2 * w1; k0 += CORNER_RUN) {
        int n = 2 * w1 - k0 < CORNER_RUN ? 2 * w1 - k0 : CORNER_RUN;
        vec3f org[CORNER_RUN], dir[CORNER_RUN];
        hit first[CORNER_RUN];
        for (int i = 0; i < n; i++)
            cam_ray(&c->c, (float)((k0 + i) % w1), (float)(y + (k0 + i) / w1), &org[i], &dir[i]);
        accel_intersect_rays(rs, org, dir, n, first);
        for (int i = 0; i < n; i++) {
            hit h;
            row->corner[k0 + i] = signature_from(rs, org[i], dir[i], rays, &h, NULL, NULL,
                                                 &first[i]);
            row->corner_part[k0 + i] = h.part;
            row->corner_t[k0 + i] = h.part < 0 ? -1.0f : h.t;
        }
    }
    for (int x = 0; x < w; x++) {
        uint32_t cs[4] = {row->corner[x], row->corner[x + 1], row->corner[w1 + x],
                          row->corner[w1 + x + 1]};
        seen_lights lights = {{0}, {0}, 0};
        note_light(rs, &lights, row->corner_part[x]);
        note_light(rs, &lights, row->corner_part[x + 1]);
        note_light(rs, &lights, row->corner_part[w1 + x]);
        note_light(rs, &lights, row->corner_part[w1 + x + 1]);
        if (c->marks) {
            const uint64_t *tips;
            int n = p2_marks_tips(c->marks, (size_t)y * w + x, &tips);
            for (int k = 0; k < n; k++)
                note_light(rs, &lights, (int)(tips[k] & 0xffffffffu));
        }
        row->pixel_first[x] = row->sample_count;
        row->light_first[x] = row->light_count;
        const float ct[4] = {row->corner_t[x], row->corner_t[x + 1], row->corner_t[w1 + x],
                             row->corner_t[w1 + x + 1]};
        const int cp[4] = {row->corner_part[x], row->corner_part[x + 1],
                           row->corner_part[w1 + x], row->corner_part[w1 + x + 1]};
        if (!pixel_samples(c, x, y, cs, ct, cp, &lights, row, &scratch, rays) ||
            !push_lights(row, &lights)) {
            free(scratch);
            return 0;
        }
    }
    free(scratch);
    row->pixel_first[w] = row->sample_count;
    row->light_first[w] = row->light_count;
    return 1;
}

void p2_row_free(p2_row *row)
{
    free(row->samples);
    free(row->pixel_first);
    free(row->lights);
    free(row->light_cover);
    free(row->light_first);
    free(row->corner);
    free(row->corner_part);
    free(row->corner_t);
    free(row->kind);
    memset(row, 0, sizeof *row);
}
