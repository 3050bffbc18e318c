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
#include <math.h>

#include "geom/ray_offset.h"
#include "util/vec3_convert.h"
#include "zone/zone.h"


/* Point j of the R2 sequence, in [0, 1)^2. */
static void r2_point(double j, double *u, double *v)
{
    const double a1 = 0.75487766624669276005; /* 1 / g, g^3 = g + 1 */
    const double a2 = 0.56984029099805326591; /* 1 / g^2 */
    *u = fmod(0.5 + a1 * j, 1.0);
    *v = fmod(0.5 + a2 * j, 1.0);
}

vec3 zone_gather_irradiance(zone_trace *t, vec3f x, vec3f nf, vec3 n, int level)
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
    vec3 tt, bb, nfd = f3_to_v3(nf);
    v3_frame(n, &tt, &bb);
    vec3f o = ray_offset(x, nf);
    /* The gathered rays see level-1 light from the nodes (no exact direct
     * light at their hits: the integral smooths what the nodes blur). */
    int save = t->light_split;
    t->light_split = 0;
    vec3 sum = v3(0, 0, 0);
    for (int k = 0; k < k_max; k++) {
        double u, v;
        r2_point(first + (double)count * k, &u, &v);
        double r = sqrt(u), phi = 6.28318530717958648 * v;
        vec3 d = v3_add(v3_add(v3_scale(tt, r * cos(phi)), v3_scale(bb, r * sin(phi))),
                        v3_scale(n, sqrt(1.0 - u)));
        /* Below the geometric surface (a shading normal tilts the frame):
         * no light from there. */
        if (v3_dot(d, nfd) <= 0)
            continue;
        sum = v3_add(sum, zone_radiance(t, o, v3_to_f3(v3_normalize(d)), level, level,
                                        ZR_NO_GLINT | ZR_NO_CAUSTIC, NULL, 0));
    }
    t->light_split = save;
    return v3_scale(sum, 3.14159265358979 / k_max);
}
