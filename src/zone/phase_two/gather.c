/* Diffuse light of levels >= 2 at camera samples on meshes, gathered from
 * the forest instead of read from the mesh's own nodes.
 *
 * A mesh's nodes lie at its vertices and a few per triangle; between them
 * light that has bounced changes faster than they can follow wherever the
 * mesh folds on itself (a stack of fins: from root to rim the light they
 * send each other changes many times within a node's spacing).  Read at
 * the hit points of rays from the sample instead, the same light is
 * integrated over the hemisphere, and the nodes' error is averaged over
 * the many nodes the rays meet.  The rays follow one fixed sequence (Roberts'
 * R2, cosine-weighted), and a pixel's samples take interleaved points of
 * it: each pixel its own stretch, and sample i of n takes points i, i + n,
 * i + 2n, ... of it, so that the pixel as a whole integrates its
 * directions evenly spread.  The image stays deterministic; its error is
 * the quadrature's, which changes from pixel to pixel.
 *
 * The engine room at 512 x 512, depth 3 (docs/zone-tracer.md,
 * BENCHMARKS.md): reading the nodes 1.385% per pixel against the path
 * reference in 37 s; gathering levels 2 and 3, 0.894% in 16.8 s, since the
 * mesh's nodes can then take a quarter of the cut limit (phase_one.c). */

#include <string.h>

#include "geom/accel.h"
#include "geom/ray_offset.h"
#include "material/bsdf.h"
#include "util/r2.h"
#include "util/vec3_convert.h"
#include "zone/zone.h"

/* Directions whose rays are traced together. */
#define GATHER_BATCH 64

vec3 zone_gather_irradiance(zone_trace *t, vec3f x, vec3f nf, vec3 n, int level,
                            double *inv_dist)
{
    int count = t->gather.count > 1 ? t->gather.count : 1;
    int index = t->gather.count > 1 ? t->gather.index : 0;
    /* The pixel's directions (q.mesh_gather_pixel), at least
     * q.mesh_gather_sample a sample.  On the engine room at quality 2 (one
     * saved forest): 16 a pixel and 1 each 0.981% per pixel, 32 0.953%, 64
     * 0.949%; 32 and 2 each (the quality's: a mesh-detail pixel's 64
     * samples take 128) 0.894% for 0.6 s more of Phase Two; 128 (2 each)
     * 0.880% and 256 (4 each) 0.840% for 1.7 s and 4.6 s more. */
    const zone_quality *q = &t->f->q;
    int per_sample = q->mesh_gather_pixel / count;
    int k_max = per_sample > q->mesh_gather_sample ? per_sample : q->mesh_gather_sample;
    /* The pixel's stretch of the sequence: neighbours take different
     * directions, so that the quadrature's error changes from pixel to
     * pixel rather than biasing a whole region alike, and a region's mean
     * converges as one long sequence. */
    double first = (double)t->gather.pixel * count * k_max + index + 1;
    vec3 tt, bb;
    v3_frame(n, &tt, &bb);
    shading_frame frame = {v3_to_f3(tt), v3_to_f3(bb), v3_to_f3(n)};
    vec3f o = ray_offset(x, nf);
    /* The gathered rays see level-1 light from the nodes (no exact direct
     * light at their hits: the integral smooths what the nodes blur). */
    int save = t->light_split;
    t->light_split = 0;
    /* Rough lobes its rays meet take one direction each. */
    zone_gather_slot slot = t->gather;
    double share = t->sample_share;
    t->gather = (zone_gather_slot){0};
    t->sample_share = 0.0;
    /* The hits this sample's gather of the level before found, or room to
     * keep this one's for the level after. */
    hit *kept = NULL;
    int reuse = 0;
    zone_gather_memo *memo = t->memo;
    /* Only a camera sample's own gather keeps its hits (samples > 0): a
     * rough lobe's or a coat's direction that meets a mesh gathers there
     * too, and would take sample 0's room. */
    /* A sample shaded for a 2 x 2 block (samples.c) takes the four
     * samples' directions, and keeps their hits where theirs would be: the
     * pixel's other samples are elsewhere. */
    int members = slot.block_width ? 4 : 1;
    /* Each member's place in the pixel's stretch and its room in the memo
     * (a detail pixel's samples are numbered alike in both). */
    int member[4] = {index, 0, 0, 0}, room[4] = {slot.sample, 0, 0, 0};
    if (slot.block_width) {
        member[0] = slot.block_first;
        member[1] = slot.block_first + 1;
        member[2] = slot.block_first + slot.block_width;
        member[3] = slot.block_first + slot.block_width + 1;
        memcpy(room, member, sizeof room);
    }
    int top = room[members - 1]; /* the last member's room is the highest */
    if (memo && slot.samples > 0 && top < ZONE_MEMO_SAMPLES &&
        ((size_t)top + 1) * (size_t)k_max <= ZONE_MEMO_HITS) {
        if (memo->pixel != slot.pixel) {
            memo->pixel = slot.pixel;
            memset(memo->have, 0, sizeof memo->have);
        }
        kept = memo->hits;
        vec3f was = memo->origin[slot.sample];
        reuse = memo->have[slot.sample] && was.x == o.x && was.y == o.y && was.z == o.z;
        memo->have[slot.sample] = 1;
        memo->origin[slot.sample] = o;
    }
    vec3 sum = v3(0, 0, 0);
    double inv_sum = 0;
    int total = members * k_max;
    for (int j0 = 0; j0 < total; j0 += GATHER_BATCH) {
        /* A batch's directions first, their rays traced together (packets
         * from one point) unless the memo has their hits already. */
        vec3f d[GATHER_BATCH];
        hit own[GATHER_BATCH];
        hit *h[GATHER_BATCH];
        int n = total - j0 < GATHER_BATCH ? total - j0 : GATHER_BATCH, m = 0;
        for (int j = j0; j < j0 + n; j++) {
            int k = j % k_max;
            double u, v;
            r2_point(first - index + member[j / k_max] + (double)count * k, &u, &v);
            const float uv[2] = {(float)u, (float)v};
            vec3f dj = bsdf_cosine_hemisphere(&frame, uv);
            /* Below the geometric surface (a shading normal tilts the
             * frame): no light from there. */
            if (f3_dot(dj, nf) <= 0.0f)
                continue;
            d[m] = f3_normalize(dj);
            h[m++] = kept ? &kept[(size_t)room[j / k_max] * k_max + k] : NULL;
        }
        int trace = !kept || !reuse;
        if (trace) {
            accel_intersect_n(&t->r->rs, o, d, m, own);
            t->rays += (uint64_t)m;
        }
        for (int i = 0; i < m; i++) {
            if (!h[i])
                h[i] = &own[i];
            else if (trace)
                *h[i] = own[i];
            t->first_hit = h[i];
            if (inv_dist && h[i]->part >= 0 && h[i]->t > 0.0f)
                inv_sum += 1.0 / h[i]->t;
            sum = v3_add(sum, zone_radiance(t, o, d[i], level, level,
                                            ZR_NO_GLINT | ZR_NO_CAUSTIC, NULL, 0));
        }
    }
    t->light_split = save;
    t->gather = slot;
    t->sample_share = share;
    if (inv_dist)
        *inv_dist = inv_sum / (members * k_max);
    return v3_scale(sum, 3.14159265358979 / (members * k_max));
}

vec3 zone_mesh_irradiance(zone_trace *t, vec3f x, vec3f nf, vec3 n, int level, int prim,
                          int side)
{
    vec3 e;
    if (!zone_gather_cache_read(t, x, nf, level, &e))
        e = zone_gather_irradiance(t, x, nf, n, level, NULL);
    return v3_add(e, zone_specular_map_read(t->f, &t->r->rs, level, prim, side, f3_to_v3(x)));
}
