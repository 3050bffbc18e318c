/* The scene model inside the library: objects (lights and things, each with
 * one or more parts) and the camera.  The loader builds it; the renderers
 * compile it into their own fast representations. */
#ifndef ZT_SCENE_SCENE_H
#define ZT_SCENE_SCENE_H

#include "zonetrace/scene.h"
#include "util/vec3.h"

typedef enum lobe {
    LOBE_DIFFUSE = 0,
    LOBE_METALLIC = 1,
    LOBE_REFLECTING = 2,
    LOBE_REFRACTIVE = 3,
    LOBE_COUNT = 4
} lobe;

typedef struct material {
    double weight[LOBE_COUNT]; /* each in [0,1], summing to 1 */
    vec3 color;                /* albedo of every lobe, each channel in [0,1] */
    double ior;                /* "refractiveindex", > 0, default 1 */
    int thin;                  /* the refractive lobe is a thin pane: light
                                  crosses it undeviated (docs/light-transport.md) */
    vec3 tint;                 /* a pane's transmission colour */
    double roughness;          /* of the metallic, reflecting and refractive
                                  lobes, in [0,1]; 0 smooth (GGX above) */
    double specular;           /* a clear coat over the diffuse lobe, in
                                  [0,1]: its Fresnel's scale (F0 = 0.04 x
                                  it), at the roughness; 0 none */
    int alpha_mode;            /* ALPHA_OPAQUE (alpha ignored), ALPHA_MASK or
                                  ALPHA_BLEND: glTF's alphaMode */
    double alpha_cutoff;       /* MASK: coverage below it is a hole, in [0,1] */
    double coverage;           /* the coverage factor (glTF's base colour
                                  alpha), times a texture's alpha; unused
                                  when opaque */
} material;

/* How a material's coverage (alpha) is read (docs/light-transport.md). */
enum { ALPHA_OPAQUE = 0, ALPHA_MASK = 1, ALPHA_BLEND = 2 };

typedef enum part_shape {
    SHAPE_SPHERE = 0,
    SHAPE_PLANE = 1,
    SHAPE_TRIANGLE = 2,
    SHAPE_POINT = 3
} part_shape;

typedef struct part {
    part_shape shape;
    int object;     /* index into scene->objects */
    vec3 p[3];      /* triangle: vertices (front face counter-clockwise);
                       sphere: centre in p[0]; point: position in p[0] */
    double radius;  /* sphere */
    vec3 normal;    /* plane: unit normal; the plane is normal.x = offset */
    double offset;
    int line;       /* line in the scene file where the part starts (0: unknown) */
} part;

typedef struct object {
    int is_light;
    int index;       /* position among the lights or among the things */
    int background;  /* hidden by any foreground hit on the same ray */
    int backculled;  /* invisible (and, for lights, dark) from behind */
    material mat;    /* things only */
    vec3 emission;   /* lights only: radiance (area lights) or intensity (points) */
    int first_part;  /* parts are contiguous: first_part .. first_part+part_count-1 */
    int part_count;
    int mesh;        /* index into scene->meshes, -1: none.  A mesh object's
                        triangles are the mesh's (part_count is 0); a mesh
                        thing takes its materials from the mesh's slots, a
                        mesh light is all light triangles of its emission */
    int line;
} object;

struct mesh;
struct env_map;

/* The sun: a disc of directions of uniform radiance, far away. */
typedef struct sun_light {
    int present;
    vec3 direction;  /* unit, toward the sun */
    vec3 irradiance; /* on a surface facing the sun, per channel */
    double angle;    /* angular diameter in radians, > 0 */
} sun_light;

struct zt_scene {
    object *objects;
    int object_count, object_capacity;
    part *parts;
    int part_count, part_capacity;
    struct mesh **meshes;    /* shared with copies of the scene (mesh.h) */
    int mesh_count, mesh_capacity;
    int light_count, thing_count;
    vec3 sky;        /* constant radiance of the background, black by default */
    int has_sky;     /* the file has a sky item (a colour or a map) */
    /* Light from far away besides the constant sky: an environment map (from
     * a file or a sky model; shared with copies of the scene), times
     * sky_strength, turned by sky_rotate radians about +y; and the sun. */
    struct env_map *sky_map;
    double sky_strength;
    double sky_rotate;
    sun_light sun;
    int has_camera;
    zt_camera camera;
};

/* A new empty scene (black sky, no camera), or NULL when out of memory. */
zt_scene *scene_create(void);

/* Appends an object; returns its index in scene->objects or -1 when out of
 * memory.  The object's index, first_part and part_count are filled in. */
int scene_add_object(zt_scene *scene, const object *obj);

/* Appends a part to the last object added; returns the part's index or -1
 * when out of memory. */
int scene_add_part(zt_scene *scene, const part *p);

/* Appends a mesh object (a thing, or a light when is_light) owning one
 * reference to m; returns the object's index or -1 when out of memory (m
 * is then not taken). */
int scene_add_mesh_object(zt_scene *scene, const object *obj, struct mesh *m);

/* Triangles of all meshes. */
long long scene_mesh_triangles(const zt_scene *scene);

/* The default material of a thing that names none: black diffuse. */
material material_default(void);

/* The object of class cls at index (as counted in the file), or NULL. */
object *scene_find_object(zt_scene *scene, zt_object_class cls, int index);

#endif
