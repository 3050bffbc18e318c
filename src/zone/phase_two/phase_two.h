/* Phase Two of the zone tracer: the image as a sum of per-zone terms.
 *
 * First every pixel gets its sample list: the camera rays that will be
 * shaded, each with its weight in the pixel and its first hit, and the
 * light parts seen somewhere in the pixel (their level-0 light is measured
 * analytically, by exact coverage).  Then the pixel's value is a sum of
 * terms, one per zone that can send light from the surface seen toward the
 * eye (docs/zone-tracer.md):
 *
 *   root zone (light part p)          level 0: coverage of p x emission
 *   root zones of a mesh light        level 0: emission on the samples that
 *                                     see the mesh
 *   diffuse zone (q, level 1)         w_d rho/pi (sum of every light's exact
 *                                     E_direct(x), and the sky's) on samples
 *                                     whose first hit is q
 *   diffuse zone (q, level l >= 2)    w_d rho/pi E_{l-1}(x) from q's nodes,
 *                                     or on a mesh gathered (gather.c)
 *   specular zone (q, kind, l >= 1)   the lobe's share of the level l-1
 *                                     radiance along the reflected (and, for
 *                                     glass, refracted) ray
 *   sky (no zone in the forest)       level 0: the sky on samples that hit
 *                                     nothing.
 *
 * The terms are in forest order (the sky's first).  Both strategies add, for each pixel, the
 * same terms in that order over the same samples with the same function, so
 * their images are identical bit for bit:
 *   pixel by pixel: for each pixel, for each term whose source it sees;
 *   zone by zone:   for each term, for each pixel that sees its source.
 */
#ifndef ZT_ZONE_PHASE_TWO_H
#define ZT_ZONE_PHASE_TWO_H

#include <stddef.h>
#include <stdint.h>

#include "camera/camera.h"
#include "render/prim.h"
#include "zone/zone.h"

/* The samples a pixel has at most but for many surfaces in it (whose
 * extra surfaces add one each): the 16 x 16 shaded on the fine grid, plus
 * one per surface that misses them. */
#define P2_MAX_PIXEL_SAMPLES (16 * 16 + 16)

/* One shaded camera sample. */
typedef struct p2_sample {
    vec3f o, d;     /* the camera ray */
    float t;        /* distance to its first hit */
    int part;       /* primitive first hit, -1: nothing */
    int surface;    /* its surface (zone_surface_of), -1: nothing */
    int light_split; /* its share of the direct light's rays (zone_trace) */
    double w;       /* weight in the pixel (the weights of a pixel sum to 1) */
    zone_gather_slot gather; /* its gathers' directions (zone_trace) */
} p2_sample;

/* The sample lists of one row of pixels. */
typedef struct p2_row {
    p2_sample *samples;
    size_t sample_count, sample_capacity;
    size_t *pixel_first;        /* width + 1 offsets into samples */
    int *lights;                /* light parts seen, per pixel */
    double *light_cover;        /* their measured coverage, or -1: exact */
    size_t light_count, light_capacity;
    size_t *light_first;        /* width + 1 offsets into lights */
    uint32_t *corner;           /* scratch: corner signatures */
    int *corner_part;
    float *corner_t;            /* their first hits' distances (-1: none) */
    uint8_t *kind;              /* each pixel's zt_pixel_kind */
    int width;
} p2_row;

/* Phase Two's time split (zt_render_stats), in thread-seconds: each
 * thread adds its own once it is done. */
typedef struct p2_split {
    double lists, records, shade[ZT_PIXEL_KINDS];
    uint64_t pixels[ZT_PIXEL_KINDS], samples[ZT_PIXEL_KINDS];
} p2_split;

/* What a term needs to know about one pixel. */
typedef struct p2_pixel {
    int x, y;
    const p2_sample *s;
    int n;
    const int *lights;
    const double *light_cover;  /* measured coverage of each, or -1 */
    int nlights;
    int kind;                   /* zt_pixel_kind: how it was sampled */
} p2_pixel;

typedef enum p2_term_type {
    P2_ROOT = 0,    /* level 0 of a light part, by exact pixel coverage */
    P2_SKY,         /* level 0: the sky on samples that hit nothing */
    P2_EMIT,        /* level 0 of a mesh light, on the samples that see it */
    P2_DIRECT,      /* level 1 diffuse: every light exactly, and the sky */
    P2_MAP,         /* level >= 2 diffuse from the receiver's nodes */
    P2_SPECULAR     /* a specular lobe at level >= 1 */
} p2_term_type;

typedef struct p2_term {
    int type;       /* p2_term_type */
    int zone;       /* its zone, -1 for the sky */
    int part;       /* ROOT: the light part; SKY: -1; else the surface seen
                       (zone_surface_of) */
    int kind;       /* zone_kind */
    int level;
} p2_term;

typedef struct p2_terms {
    p2_term *term;
    int count;
    int surfaces;       /* surface count; index `surfaces`: nothing hit */
    int *part_first;    /* surfaces + 2 offsets into part_terms */
    int *part_terms;    /* per surface: its terms, ascending */
    int *root_term;     /* per part: its ROOT term or -1 */
    int sky_term;       /* the SKY term or -1 */
} p2_terms;

typedef struct p2_ctx {
    const zt_renderer *r;
    const zone_forest *f;
    cam c;
    int lo, hi;         /* levels rendered */
    int g;              /* sub-pixel grid of smooth pixels */
    /* A pixel's angular width (its width on the screen over the screen's
     * distance from the viewpoint) and that distance: a pixel is
     * pixel_angle x (t + screen_dist) wide at a hit t beyond the screen. */
    float pixel_angle, screen_dist;
    p2_terms terms;
    const struct p2_marks *marks; /* what the pixels' own rays may miss */
    const struct zone_gather_cache *cache; /* gathers at pixel centres */
    p2_split *split;    /* where the time goes; NULL: not measured */
} p2_ctx;

/* What the pixels' own rays may miss, found from the eye
 * (phase_two_marks.c). */
typedef struct p2_marks {
    unsigned char *fine;    /* per pixel: a light's image in a mirror, metal
                               or glass sphere may fall here, too small for
                               the signatures: take the fine grid */
    unsigned char *vertex;  /* per pixel: a triangle's vertex falls here; its
                               tip can lie between every signature, so the
                               pixel takes the edge grid */
    uint64_t *tips;         /* (pixel << 32 | light part), sorted: a vertex
                               of the light part falls in the pixel */
    size_t tip_count, tip_capacity;
} p2_marks;
/* Returns 0 when out of memory. */
int p2_marks_build(p2_marks *m, const p2_ctx *c);
void p2_marks_free(p2_marks *m);
/* The light parts with a vertex in pixel (an index y * width + x): sets
 * *tips to their entries (part = entry & 0xffffffff), returns how many. */
int p2_marks_tips(const p2_marks *m, size_t pixel, const uint64_t **tips);

/* Sample lists (phase_two_samples.c).  Returns 0 when out of memory. */
int p2_row_build(const p2_ctx *c, int y, p2_row *row, uint64_t *rays);
void p2_row_free(p2_row *row);
static inline void p2_row_pixel(const p2_row *row, int x, int y, p2_pixel *px)
{
    px->x = x;
    px->y = y;
    px->s = row->samples + row->pixel_first[x];
    px->n = (int)(row->pixel_first[x + 1] - row->pixel_first[x]);
    /* A row with no light samples has NULL lists (no offset may be added
     * to a null pointer, even zero). */
    px->lights = row->lights ? row->lights + row->light_first[x] : NULL;
    px->light_cover = row->light_cover ? row->light_cover + row->light_first[x] : NULL;
    px->nlights = (int)(row->light_first[x + 1] - row->light_first[x]);
    px->kind = row->kind[x];
}

/* The first hit of a camera sample, as zone_radiance sees it. */
typedef struct p2_surface {
    rs_part tmp;
    const rs_part *p;
    const rs_object *m;
    vec3f xf, nf;       /* the point and the geometric normal facing the ray */
    vec3 x, n, color;   /* n: the shading normal */
    int back;
    rs_shade sh;        /* m may point into it (a material with maps) */
} p2_surface;
void p2_surface_of(const rscene *rs, const p2_sample *s, p2_surface *sf);

/* Gathers shared between neighbouring pixels (gather_cache.c): at each
 * pixel's centre, when it sees a mesh's diffuse surface, the gathers of
 * the levels the image reads (E_first .. E_first+levels-1), where they
 * were taken and how far their rays went. */
struct zone_gather_cache {
    int width, height;
    int first, levels;
    vec3f *x, *n;           /* per pixel: the record's point and geometric
                               normal (facing the eye) */
    float *r;               /* its rays' harmonic mean distance (INFINITY:
                               every ray escaped); 0: no record */
    float *e;               /* per pixel and level: the gathered irradiance */
};
/* Builds the records (none when the image gathers nothing: the cache
 * stays empty); split over processes, each builds its rows' and they are
 * exchanged. */
zt_status p2_gather_cache_build(struct zone_gather_cache *gc, const p2_ctx *c, uint64_t *rays,
                                zt_error *err);
void p2_gather_cache_free(struct zone_gather_cache *gc);

/* Terms (phase_two_terms.c). */
zt_status p2_terms_build(p2_terms *t, const zone_forest *f, const zt_renderer *r, int lo,
                         int hi, zt_error *err);
void p2_terms_free(p2_terms *t);
/* Adds term k's share of pixel px to acc (the one place where pixel values
 * are summed, for both strategies). */
void p2_apply(const p2_ctx *c, zone_trace *t, int k, const p2_pixel *px, double acc[3]);
/* The pixel shaded the way the renderer did before terms existed: one
 * zone_radiance call over levels lo..hi per sample, plus the level-0
 * coverage of the lights seen.  For tests: the sum of the terms must equal
 * it up to float rounding. */
void p2_reference(const p2_ctx *c, zone_trace *t, const p2_pixel *px, double acc[3]);

/* The strategies (phase_two_render.c): add the image to sum. */
zt_status p2_render_pixels(const p2_ctx *c, zt_image *sum, uint64_t *rays, zt_error *err);
zt_status p2_render_zones(const p2_ctx *c, zt_image *sum, uint64_t *rays, zt_error *err);
/* The preview (preview.c): one sample per pixel, shaded from the nodes. */
zt_status p2_render_preview(const p2_ctx *c, zt_image *sum, uint64_t *rays, zt_error *err);

zt_status p2_render_reference(const p2_ctx *c, zt_image *sum, uint64_t *rays, zt_error *err);

/* For tests: renders r's image into sum with the reference shading above
 * (zone method only). */
zt_status zone_accumulate_reference(zt_renderer *r, zt_image *sum, zt_error *err);

#endif
