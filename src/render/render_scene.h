/* The scene as the renderers see it: flat arrays in single precision,
 * built once per render from the scene model, plus the acceleration
 * structure and the table of lights. */
#ifndef ZT_RENDER_RENDER_SCENE_H
#define ZT_RENDER_RENDER_SCENE_H

#include <stdint.h>
#include "scene/scene.h"
#include "util/vec3f.h"

struct accel;

/* One primitive.  The index of a part here equals its index in the scene
 * model, so hits can be traced back to the file.  Mesh triangles are
 * primitives too, but are not stored as rs_part: they are numbered after
 * the parts (prim.h) and an rs_part is made for one when it is needed. */
typedef struct rs_part {
    uint8_t shape;      /* part_shape */
    uint8_t is_light;
    uint8_t culled;     /* backculled: invisible from behind */
    uint8_t background;
    int object;         /* index into rscene.objects */
    int light;          /* index into rscene.lights, or -1 */
    vec3f p0;           /* triangle vertex 0, sphere centre, point */
    vec3f e1, e2;       /* triangle edges p1-p0, p2-p0 */
    vec3f n;            /* triangle/plane unit normal (front side) */
    vec3f tangent, bitangent; /* triangle/plane: f3_basis(n), precomputed
                                 for sampling directions around n */
    float radius;       /* sphere */
    vec3f c_lo;         /* sphere: what p0 and radius leave out of the */
    float r_lo;         /* scene's double values (shape_sphere_double) */
    float offset;       /* plane: n.x = offset */
    float area;         /* triangle/sphere surface area */
    float select_pdf;   /* next-event estimation's probability of choosing
                           it (0: not sampled) */
} rs_part;

/* A model material's maps, read at each hit (render/prim.c): the
 * roughness is `roughness` times channel rough_channel of `rough`, the
 * metallic weight `metallic` times channel metal_channel of `metal` (the
 * rest of the weight then diffuse and refractive by `transmission`), the
 * shading normal bent by the tangent-space `normal` map with its x and y
 * times normal_scale.  A NULL texture: that map is absent. */
typedef struct rs_maps {
    const struct mesh_texture *rough, *metal, *normal;
    int rough_channel, metal_channel;
    float roughness, metallic, transmission, normal_scale;
} rs_maps;

typedef struct rs_object {
    float weight[LOBE_COUNT];
    vec3f color;
    float ior;
    vec3f emission;     /* zero for things and for lights switched off */
    uint8_t is_light;
    uint8_t culled;
    uint8_t background;
    uint8_t lobe_choice; /* more than one lobe has weight: choosing takes a
                            random number */
    uint8_t thin;       /* the refractive lobe is a pane (bsdf_pane) */
    uint8_t rough;      /* a lobe is GGX (material/microfacet.h): alpha > 0
                           and a metallic, reflecting or non-pane
                           refractive weight */
    uint8_t coat;       /* a clear coat lies over the diffuse lobe:
                           specular > 0 and a diffuse weight (bsdf.h) */
    uint8_t alpha_mode; /* ALPHA_MASK or ALPHA_BLEND: the surface covers a
                           share of each hit (rs_coverage_at, prim.h) and
                           light passes by the rest; ALPHA_OPAQUE: all */
    float alpha;        /* GGX alpha = roughness^2 (0: smooth lobes) */
    float specular;     /* the coat's Fresnel scale (material.specular) */
    float alpha_cutoff; /* MASK: coverage below it is a hole */
    float coverage;     /* coverage factor (times the texture's alpha) */
    vec3f tint;         /* a pane's transmission colour */
    const struct mesh_texture *texture; /* base colour, times color; NULL */
    const struct mesh_texture *emissive; /* a light's: emission times its
                                            texel at the point (prim.h);
                                            NULL */
    const rs_maps *maps; /* a model material's maps (NULL: none): weight,
                            alpha and rough are then what the maps give
                            somewhere (weights their mean, alpha the
                            largest), and rs_shade_at gives the material
                            at a hit */
} rs_object;

/* Whether light may cross m's surface undeviated somewhere: a pane or a
 * coverage below 1. */
static inline int rs_passes(const rs_object *m)
{
    return m->thin | m->alpha_mode;
}

/* A mesh of the scene model as the renderers see it: its arrays are the
 * scene's (shared, not copied); its triangles are primitives
 * prim_base .. prim_base + triangle count - 1, and triangle t's object is
 * object_base + its slot (a mesh light has one object for all). */
struct mesh;
typedef struct rs_mesh {
    const struct mesh *m;
    int prim_base;
    int object_base;
    uint8_t is_light;   /* a mesh light: every triangle emits */
    uint8_t culled;
    uint8_t background;
    uint8_t smooth;     /* shading normals from the mesh's vertex normals */
    vec3f *emit_mean;   /* per triangle, the mean emitted radiance of one
                           whose object has an emissive texture (what its
                           power and the zone tracer's light take); NULL
                           when no slot has one */
} rs_mesh;

/* An emitting part that next-event estimation can sample. */
typedef struct rs_light {
    int part;
    float select_pdf;   /* probability of choosing this light */
    float select_cdf;   /* cumulative, for the choice */
} rs_light;

/* The infinite planes of one layer as arrays (one entry per plane, padded
 * to a multiple of PLANE_LANES with planes that are never hit), so that a
 * ray meets all of them in a few vector instructions. */
#define PLANE_LANES 4
typedef struct rs_planes {
    int count, padded;
    float *nx, *ny, *nz, *offset;
    float *culled;   /* 1 for culled planes, else 0 */
    int *part;
} rs_planes;

/* Light from far away besides the constant sky: an environment map and the
 * sun (light/distant.h evaluates and samples them). */
struct env_map;
typedef struct rs_distant {
    int any;              /* a map or a sun */
    const struct env_map *map; /* NULL: none (the scene holds the reference) */
    const struct env_map *sampling; /* the distribution drawn from: the map
                                       itself (a test may swap in another of
                                       the same size to compare) */
    float strength;
    float rot_cos, rot_sin; /* the map's turn about +y */
    int sun;              /* a sun is present */
    vec3f sun_dir, sun_t, sun_b; /* toward the sun, and a frame around it */
    float sun_one_minus_cos; /* 1 - cos of the disc's angular radius */
    float sun_sin2;       /* sin^2 of the angular radius */
    vec3f sun_radiance;   /* irradiance / (pi sin^2 radius) */
    float sun_select;     /* next-event estimation's chance of the sun
                             (against the map) */
} rs_distant;

typedef struct rscene {
    rs_part *parts;
    int part_count;
    rs_mesh *meshes;    /* by prim_base, ascending */
    int mesh_count;
    int prim_count;     /* parts and mesh triangles */
    rs_object *objects; /* the scene model's objects, then the meshes' slots */
    rs_maps *maps;      /* objects' maps, by object (most unused) */
    int object_count;
    rs_light *lights;   /* parts sampled by next-event estimation */
    int light_count;
    int pane_count;     /* objects light may pass: a thin refractive lobe
                           or a coverage below 1 (rs_passes): visibility
                           queries then see through them (transmittance.h) */
    int alpha_count;    /* objects with a coverage (alpha_mode): nearest-hit
                           queries skip their holes (accel.h) */
    int plain;          /* nothing but smooth lobes, untextured, without
                           maps, panes, alpha, smooth meshes or light from
                           far away: the path tracer's loop has a copy
                           compiled without those branches */
    int *point_lights;  /* point-light parts, switched off or not */
    int point_light_count;
    /* Infinite planes of each layer ([0] foreground, [1] background), kept
     * apart from the other primitives as compact arrays: they are tested
     * against every ray. */
    rs_planes planes[2];
    vec3f sky;
    rs_distant distant;
    float light_power;  /* total of the sampled lights' power (select_pdf's
                           denominator) */
    struct accel *accel;
} rscene;

/* Builds the render scene with acceleration structure accel_kind (an
 * accel_kind from geom/accel.h).  lights_off lists light objects (by index
 * among the lights) whose emission is set to zero; they stay in the scene as
 * black surfaces, so the images of single lights add up to the whole. */
zt_status rscene_build(rscene *rs, const zt_scene *scene,
                       const int *lights_off, int lights_off_count,
                       int accel_choice, zt_error *err);

void rscene_free(rscene *rs);

#endif
