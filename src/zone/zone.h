/* The zone tracer's state, shared by its stages: the forest (Phase One's
 * result: the zones and the irradiance at the nodes of every diffuse
 * surface, level by level) and what Phase Two reads from it.
 * docs/zone-tracer.md describes what is computed and why. */
#ifndef ZT_ZONE_ZONE_H
#define ZT_ZONE_ZONE_H

#include <stdint.h>

#include "geom/hit.h"
#include "render/render_internal.h"
#include "light/distant.h"
#include "zone/light/direct.h"
#include "zone/light/occluders.h"
#include "zone/light/sky_portals.h"
#include "zone/maps/photon_map.h"
#include "zone/maps/surface_nodes.h"
#include "zone/transfer/sender_tree.h"

/* The open-surface irradiance table of an environment map: normals every
 * 5.6 degrees (irradiance is the map seen through a cosine lobe, smooth in
 * the normal), each from SKY_TABLE_SAMPLES directions drawn from the map. */
#define ZONE_SKY_TABLE_W 64
#define ZONE_SKY_TABLE_H 32
#define ZONE_SKY_TABLE_SAMPLES 16384

/* Up to this many light primitives, direct light sums them all exactly;
 * beyond (a mesh light), a cut through the light tree chooses which to
 * take exactly and which together. */
#define ZONE_LIGHTS_EXACT 16

/* How light leaves a zone's source. */
typedef enum zone_kind {
    ZONE_EMIT = 0,      /* a root: the light primitive itself */
    ZONE_DIFFUSE,
    ZONE_METALLIC,
    ZONE_MIRROR,
    ZONE_REFRACT,       /* the dielectric lobe: reflected and transmitted */
    ZONE_KINDS
} zone_kind;

/* One zone: the light leaving a source by one kind of interaction, at one
 * level.  A root (level 0) is a light primitive.  Above, there is one zone
 * per surface, lobe and level: light that leaves a surface diffusely has
 * forgotten where it came from, so the diffuse zone of a surface is fed by
 * every zone of the level below (its light is the surface's irradiance at
 * that level); a specular zone passes the level below on along the
 * reflected and refracted rays, so its light keeps a direction. */
typedef struct zone {
    int32_t source;     /* root: the light primitive; else the surface
                           (zone_surface_of) */
    uint8_t kind;       /* zone_kind */
    uint8_t level;
    float power;        /* the power it carries (a bound for specular
                           zones), for --cutoff */
} zone;

/* Surfaces: each part is one; a mesh's triangles of one material (one
 * object of rs) together are one. */
static inline int zone_surface_count(const rscene *rs)
{
    return rs->part_count + rs->object_count;
}
int zone_surface_of(const rscene *rs, int prim);

/* Quality settings derived from --quality. */
typedef struct zone_quality {
    int gather;         /* directions per node for light by specular
                           surfaces and the sky */
    double texel;       /* node spacing h in scene units */
    double texel_divisor; /* h = scene extent / texel_divisor */
    int max_texels;     /* nodes along a plane's core at most */
    int sides;          /* polygon vertices for disks */
    int aa;             /* sub-pixel grid per side */
    double theta;       /* transfer: an element is split above this size
                           over distance */
    double eps;         /* transfer: a cluster's error bound, as a share of
                           the receiver's irradiance */
    int fallback;       /* direct light by rays: light cut into this many
                           triangles where occluders are too many to clip */
    int glint_cuts;     /* a light triangle is cut n x n for its images */
    int edge_grid;      /* coverage grid of a pixel an edge crosses (<= 64) */
    int edge_shade;     /* its shaded subset, per side (divides edge_grid) */
    int cover_quasi;    /* coverage points: 0 the n x n cell centres, 1 the
                           first n^2 of a quasi-random (R2) sequence */
    int probe;          /* signatures per side that look for an edge in a
                           pixel (no more than aa: the samples' own) */
    int photons;        /* caustic photons per light (caustic.h) */
    int mesh_gather_pixel;  /* directions a pixel's samples on a mesh
                               share (gather.c) */
    int mesh_gather_sample; /* and that each of them takes at least */
    int rough_pixel;    /* directions (and light samples) a pixel's
                           samples share at a rough lobe (rough.c) */
    int rough_light_pixel; /* the same for light of level 0 */
    int rough_sample;   /* and that each of them takes at least */
} zone_quality;

/* Environment-map directions a point takes at a time (their cosines, and
 * their rays as packets). */
#define ZONE_SKY_RUN 64

/* A mesh's nodes are read only through averages of many: the camera's
 * samples on meshes gather their light from them, and as senders they
 * send by clusters.  So a mesh node's own estimates take this share of a
 * node's effort: its cut's cluster limit, its gather's and its sky's
 * directions (phase_one.c says what each is worth). */
#define ZONE_MESH_NODE_DIV 4
/* The shifted sets of an environment map's directions that mesh nodes
 * take between them (light/sky_gather.h). */
#define ZONE_NODE_SKY_SETS 16

/* The key that sets mesh node k's directions apart from its neighbours'
 * at a level (zone_trace.node_draw; never 0): a 32-bit mix (Wellons'
 * lowbias32) of the two, so that one node's directions differ from level
 * to level too. */
static inline uint32_t zone_node_draw_key(int32_t k, int level)
{
    uint32_t x = (uint32_t)k * 0x9e3779b9u + (uint32_t)level * 0x85ebca6bu;
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x ? x : 1;
}
/* What the key sets: the angle by which the node turns a set about its
 * normal (a shift of the set's azimuth), and which of an environment
 * map's shifted sets it takes (the key's other bits). */
static inline double zone_node_turn(uint32_t key)
{
    return (key & 0xffffff) * (2 * 3.14159265358979323846 / 16777216.0);
}
_Static_assert(ZONE_NODE_SKY_SETS == 16, "zone_node_set takes the key's top 4 bits");
static inline int zone_node_set(uint32_t key)
{
    return (int)(key >> 28);
}

/* Directions drawn from an environment map, each with its radiance /
 * (density x count), also as six rows (x, y, z, then the weight's r, g,
 * b) of soa_stride floats each, padded with zeros to a multiple of
 * ZONE_SKY_RUN: a point's cosines with all of them go four at a time. */
typedef struct zone_sky_set {
    vec3f *dirs, *weight;
    int count;
    float *soa;
    size_t soa_stride;
} zone_sky_set;

typedef struct zone_forest {
    zone *zones;
    int zone_count, zone_capacity;
    uint64_t pruned;
    surface_nodes sn;
    int map_levels;     /* irradiance levels E_0 .. E_{map_levels-1} */
    int top_gathered;   /* the last level left out (0) on the nodes of
                           meshes, whose camera samples gather it from the
                           level below: a forest for one image (phase_one.c) */
    float *e;           /* [level][node][rgb] */
    /* What e holds of light that came from the lights by way of specular
     * surfaces alone (caustic photons, glint images), kept apart where
     * the scene has meshes (whose camera samples gather) and specular
     * lobes: the gathers' rays see all other light, and add this
     * from the sample's own nodes (gather.c).  NULL otherwise. */
    float *c;           /* [level][node][rgb] */
    /* The caustic photons as points, and what the nodes took of them
     * (part of e and c): a camera sample's caustic is read from the one
     * instead of the other (photon_map.h).  Empty and NULL without
     * caustics. */
    photon_map photons;
    float *caustic;     /* [level][node][rgb] */
    /* The sun sent photons too: rays that leave a caustic target count it
     * no more (ZR_CAUSTIC_LIGHT), as they count no light part that sends
     * them. */
    int sun_photons;
    uint64_t photon_estimate; /* bytes the caustic photons were estimated
                                 to take at their peak (caustic.c) */
    occluder_index occ;
    direct_ctx direct;
    sender_tree light_tree; /* the lights, when there are many */
    zone_quality q;
    int need_gather;    /* some light arrives by specular surfaces */
    /* What that light can come from, for aiming (Phase One only, not kept
     * in forest files): the targets' bounding spheres, and whether some
     * specular primitive is no target (a plane). */
    struct specular_target *spec_targets;
    int spec_target_count;
    int spec_unaimable;
    int specular;       /* some object has a metallic, reflecting or
                           refractive lobe */
    int sky;            /* the sky is not black: E_0 gathers it */
    /* An environment map's gather (light/sky_gather.h): directions drawn
     * from it by importance, every one for a camera sample and most nodes,
     * and ZONE_NODE_SKY_SETS shifted sets of a ZONE_MESH_NODE_DIV-th as
     * many for mesh nodes, each of which takes one; and the map's
     * irradiance on an open surface of each normal (a table over the
     * sphere of normals, laid out as the map's texels), which the gather
     * scales by the share of its light that arrives.  Empty without one. */
    zone_sky_set sky_set;
    zone_sky_set node_sky[ZONE_NODE_SKY_SETS];
    float *sky_open;    /* ZONE_SKY_TABLE_W x ZONE_SKY_TABLE_H x rgb */
    /* A sky of one colour: a mesh node's cosine-weighted set about its
     * normal (a ZONE_MESH_NODE_DIV-th of q.gather), turned by its key. */
    vec3 *node_dirs;
    int node_dir_count;
    sky_portals portals; /* the panes, where the sky's gather aims (under a
                            sky) */
    int *glint_spheres; /* spheres that reflect lights as images (glint.h) */
    int glint_count;
    vec3 *dirs;         /* the gather directions (q.gather of them) */
    vec3 *bounce_dirs;  /* the transfer's gather directions (q.gather,
                           bounce_gather.h) */
    uint64_t links;     /* Phase One: clusters and elements the transfer took */
    uint64_t cuts;      /* transfer cuts made (not kept in forest files) */
    uint64_t cuts_capped; /* of which stopped at their size limit */
    uint64_t cuts_shared; /* of which started from a neighbour's cut */
    uint64_t gathers;   /* nodes whose transfer was gathered instead */
    double phase_one_seconds;
    uint64_t rays;
    int loaded;         /* read from a forest file (forest_io.c), not built */
    double build_seconds; /* Phase One time of the build (kept in the file) */
    int images;         /* images rendered from it so far */
    int stopped;        /* zt_stop_reason: why Phase One built fewer levels */
} zone_forest;

/* Level l's irradiance at node k. */
static inline float *zone_e(const zone_forest *f, int level, int32_t k)
{
    return f->e + ((size_t)level * (size_t)f->sn.node_count + (size_t)k) * 3;
}

/* The quality settings of --quality q for scene sc (rs compiled from it). */
zone_quality zone_quality_for(const zt_scene *sc, const rscene *rs, int q);

/* The scene's core: the box of the finite primitives and of the corners
 * where three planes meet; independent of the camera. */
void zone_scene_bounds(const zt_scene *sc, const rscene *rs, vec3 *lo, vec3 *hi);

/* Phase One (phase_one/phase_one.c): the nodes, their irradiance level by
 * level, and the zones. */
/* When the time limit or an interrupt (r->deadline, options.stop) cuts it
 * short, the levels built set r->options.depth and f->stopped says why. */
zt_status zone_phase_one(zone_forest *f, zt_renderer *r, zt_error *err);
/* The zones from the irradiance (phase_one/forest.c). */
zt_status zone_forest_zones(zone_forest *f, const zt_renderer *r, zt_error *err);
/* What the forest holds besides its zones and levels, rebuilt the same on
 * load: nodes, occluders, gather directions, glint spheres. */
zt_status zone_forest_frame(zone_forest *f, const zt_renderer *r, zt_error *err);
void zone_forest_free(zone_forest *f);
/* The fixed gather directions (cosine-weighted, around +z). */
vec3 *zone_gather_directions(int n);

/* Radiance arriving along a ray with levels lo..hi (flags below). */
/* Where a camera sample's gathers take their directions (gather.c): its
 * pixel's own stretch of one sequence, shared out among the pixel's
 * samples of one grid. */
typedef struct zone_gather_slot {
    uint32_t pixel;         /* y * width + x */
    uint16_t index, count;  /* the sample's place among them; 0, 0: none */
    uint16_t sample, samples; /* its place among all of the pixel's samples
                                 (an edge pixel's too): rough lobes share
                                 the pixel's stretch by it (rough.c) */
    /* A sample shaded for the 2 x 2 block of a grid `block_width` wide
     * whose first (top left) is sample block_first: it takes the four's
     * directions (gather.c).  block_width 0: itself alone. */
    uint16_t block_first;
    uint8_t block_width;
} zone_gather_slot;

typedef struct zone_trace {
    const zone_forest *f;
    const zt_renderer *r;
    uint64_t rays;
    /* Exact direct light at a camera sample that shares the fallback's
     * rays with its neighbours (direct_irradiance_split), 0: alone. */
    int light_split;
    /* Set by Phase One at a mesh node (ZONE_MESH_NODE_DIV): the key that
     * sets its sky's and its gather's directions apart from its
     * neighbours' (zone_node_draw_key); 0: every direction, as is. */
    uint32_t node_draw;
    zone_gather_slot gather; /* the camera sample's (zone_mesh_irradiance
                                and its rough lobes' directions) */
    /* Gathers at the pixels' centres that a camera sample's may take
     * instead of its own (phase_two/gather_cache.c); NULL: none. */
    const struct zone_gather_cache *cache;
    /* Set by a rough lobe for the next ray it traces (zone_radiance resets
     * it): the lobe's density of that direction, and the point it left, so
     * that the light it meets is weighed against the lobe's light samples
     * (rough.c); 0: no weighing. */
    float mis_pdf;
    vec3f mis_from;
    /* The camera sample's weight in its pixel (rough.c shares the pixel's
     * directions by it); 0 on rays that are not a camera sample's. */
    double sample_share;
    /* Set by a camera sample's rough lobe for the rays of its directions:
     * the direction's point of the sequence, which a second rough lobe on
     * the way takes in another set of numbers (rough.c); 0: none. */
    int rough_nested;
    double rough_j;
    /* Set by a gather for the next ray zone_radiance traces: its first hit,
     * already found (zone_radiance resets it); NULL: trace it. */
    const hit *first_hit;
    /* The gathers' first hits of the pixel being shaded, kept for its next
     * level's terms (the pixel strategy's; NULL: none kept). */
    struct zone_gather_memo *memo;
    /* A camera path's eye and the angle a pixel spans there: a pixel's
     * footprint at x is about pixel_angle |x - eye| wide (the caustics'
     * density is read over it, zone_caustic_read); 0: no footprint. */
    vec3f eye;
    float pixel_angle;
} zone_trace;

/* A pixel's gathered rays' first hits: its level-2 and level-3 terms gather
 * along the same directions from the same samples (gather.c), so the second
 * takes the first's hits instead of tracing them again. */
#define ZONE_MEMO_SAMPLES 288 /* at least P2_MAX_PIXEL_SAMPLES */
#define ZONE_MEMO_HITS 1024
typedef struct zone_gather_memo {
    uint32_t pixel;                     /* whose samples; UINT32_MAX: none */
    uint8_t have[ZONE_MEMO_SAMPLES];    /* a sample's hits are kept */
    vec3f origin[ZONE_MEMO_SAMPLES];    /* from where (a gather elsewhere on
                                           its specular chain differs) */
    hit hits[ZONE_MEMO_HITS];
} zone_gather_memo;

/* Irradiance of level `level` at point x (normal n) on side `side` of
 * primitive prim, read from the nodes. */
vec3 zone_map_read(const zone_forest *f, const rscene *rs, int level, int prim, int side, vec3 x);
/* e plus the irradiance of levels first..last at x, added level by level (the
 * same sums as that many zone_map_read calls), the nodes' weights found
 * once. */
vec3 zone_map_read_levels(const zone_forest *f, const rscene *rs, int first, int last, int prim,
                          int side, vec3 x, vec3 e);
/* The same from the light by way of specular surfaces alone (f->c; 0
 * where it is not kept apart). */
vec3 zone_specular_map_read(const zone_forest *f, const rscene *rs, int level, int prim,
                            int side, vec3 x);

/* The surface a photon on prim counts for: a mesh's material, or a part;
 * the triangle parts of one thing together (a quad's two triangles: the
 * photons' discs must not end at the diagonal), the normals keeping its
 * faces apart. */
int zone_photon_surface(const rscene *rs, int prim);

/* What a camera path reads of the caustics of levels first..last at x
 * (facing normal nf) on side `side` of prim, beyond the nodes': the
 * photons' density there less what the nodes took of them (0 without
 * caustics).  Added to the nodes' irradiance, the caustic is the photons'
 * own, at their resolution or at a pixel's footprint, whichever is coarser
 * (photon_map.h). */
vec3 zone_caustic_read(const zone_trace *t, int first, int last, int prim, int side, vec3 x,
                       vec3 nf);

/* The radiance of an escaping ray in direction d: the sky's colour or map,
 * and the sun. */
static inline vec3f zone_background(const rscene *rs, vec3f d)
{
    return rs->distant.any ? f3_add(rs->sky, distant_radiance(&rs->distant, d)) : rs->sky;
}

/* The direct irradiance of every light (exact, direct.c; a light cut when
 * there are many) at x (normal n) on primitive `receiver`, without the
 * sky's. */
vec3 zone_lights_at(zone_trace *t, int receiver, vec3 x, vec3 n);

/* Whether a camera path's diffuse light of levels >= 2 at primitive prim
 * is gathered (zone_mesh_irradiance) rather than read from its nodes. */
static inline int zone_gathers(const rscene *rs, int prim)
{
    return prim >= rs->part_count;
}
/* Irradiance of level `level` (>= 1) at x on a mesh (nf: the geometric
 * normal on the side seen, n: the shading normal), gathered from the
 * forest over cosine-weighted directions: the level's radiance where they
 * meet the scene (phase_two/gather.c).  *inv_dist, if not NULL, gets the
 * mean over the directions of 1 / the distance their rays went. */
vec3 zone_gather_irradiance(zone_trace *t, vec3f x, vec3f nf, vec3 n, int level,
                            double *inv_dist);
/* The same at a camera path's point x on side `side` of mesh primitive
 * prim, with the light kept apart from gathers (zone_specular_map_read)
 * added: from the gathers at nearby pixels' centres where they hold for x
 * (zone_gather_cache_read), else gathered at x. */
vec3 zone_mesh_irradiance(zone_trace *t, vec3f x, vec3f nf, vec3 n, int level, int prim,
                          int side);
/* The gathers at the centres of the pixels around the camera sample's
 * pixel that hold for x (normal nf), blended: returns 0 when none does. */
int zone_gather_cache_read(const zone_trace *t, vec3f x, vec3f nf, int level, vec3 *e);

enum {
    ZR_EXACT_DIRECT = 1, /* level 1 from the analytic direct term, not maps */
    ZR_NO_EMISSION = 2,  /* lights hit by this very ray count nothing (the
                            camera's level 0 is measured analytically) */
    ZR_SKIP_DIFFUSE = 4, /* the diffuse lobe of the surface hit by this very
                            ray counts nothing (the transfer covers it) */
    ZR_NO_GLINT = 8,     /* a light seen in a glint sphere (glint.h) by this
                            very ray counts nothing (its image covers it) */
    ZR_NO_CAUSTIC = 16,  /* a light reached after one or more specular events
                            and no diffuse one, the last of them off a
                            caustic target (caustic.h), counts nothing if it
                            sends photons (a triangle or sphere, the sun):
                            they carry it */
    ZR_CAUSTIC_LIGHT = 32, /* set by zone_radiance under ZR_NO_CAUSTIC: this
                            very ray left a caustic target */
    ZR_WHOLE_HIT = 64,   /* the surface hit by this very ray counts whole,
                            its coverage (alpha) being the caller's: Phase
                            Two's samples are split at it (samples.c) */
    ZR_BLURRED = 128,    /* the path passed a rough lobe: caustics it meets
                            are read from the nodes, not the photons (the
                            lobe blurs them more than the nodes do) */
    ZR_SMOOTH_COAT = 256 /* a coat reflects its irradiance as a white
                            diffuse surface of albedo s E(cos_o) would,
                            without rays (the preview: no grain) */
};
vec3 zone_radiance(zone_trace *t, vec3f o, vec3f d, int lo, int hi,
                   int flags, const int *media, int media_count);

/* A surface a ray has met, as its rough lobes see it. */
typedef struct zone_rough_at {
    const rs_object *m;
    int part;
    vec3f x;            /* the hit point */
    vec3f ng;           /* the geometric normal, facing the ray's side */
    vec3f ns;           /* the shading normal, on the same side */
    vec3 color;         /* the albedo there (textured) */
    vec3f d;            /* the arriving ray's direction */
    float eta_i, eta_t; /* the indices on the ray's side and beyond */
    int object;         /* the part's object (media.h's identity) */
    int entering;       /* whether the ray enters it */
    const int *media;   /* the glass the ray is in (media.h) */
    int media_count;
    float budget;       /* the share of a camera sample's directions to
                           take (0: all of them) */
} zone_rough_at;

/* The radiance that the rough lobes of s->m among `lobes` (a mask of
 * 1 << LOBE_k) send back along the ray, of the levels lo..hi arriving at
 * the surface (one below the levels they pass on): the lobe sampled over
 * fixed directions, and light of level 0 also by light samples, the two
 * weighed by multiple importance sampling (phase_two/rough.c). */
vec3 zone_rough_radiance(zone_trace *t, const zone_rough_at *s, unsigned lobes, int lo, int hi,
                         int flags);
/* The light of levels lo..hi that a coat (bsdf.h) on a ray's way sends
 * back along it: one of its directions, taken with probability s E(cos_o)
 * (its share of evenly arriving light) by a hash of the point and the
 * arriving direction, and weighed by its inverse: unbiased, for a ray in
 * about s E(cos_o) (phase_two/rough.c).  s->color is ignored (white). */
vec3 zone_coat_on_the_way(zone_trace *t, const zone_rough_at *s, int lo, int hi, int flags);

/* One direction *wi from s's rough lobes, chosen by a hash of the point
 * and the arriving direction, and *value, their f cos over its density
 * (the colour apart): how a caustic photon goes on.  0: none. */
int zone_rough_scatter(const zone_rough_at *s, vec3f *wi, vec3f *value);

#endif
