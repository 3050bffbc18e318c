/* Specular targets: what light by way of mirrors, metal and glass can come
 * from, as bounding spheres that rays can be aimed at.  Caustic photons
 * are aimed at them from the lights (caustic.c), and nodes gather the
 * light they pass on by aiming at them (phase_one.c). */
#ifndef ZT_ZONE_SPECULAR_TARGETS_H
#define ZT_ZONE_SPECULAR_TARGETS_H

#include "render/render_scene.h"
#include "util/vec3.h"

/* A part (a triangle or sphere) with a specular lobe, or a whole mesh
 * with a specular material (aimed at by its bounding sphere). */
typedef struct specular_target {
    int part;   /* -1 for a mesh */
    int mesh;   /* rs->meshes index, -1 for a part */
    vec3 c;     /* bounding sphere */
    double r;
} specular_target;

/* The scene's targets into *out (caller frees); returns their count, or
 * -1 when out of memory.  *unaimable (if not NULL) is set when some other
 * primitive that is not a light has a specular lobe (a plane): light by
 * way of it can come from any direction. */
int specular_targets_make(const rscene *rs, specular_target **out, int *unaimable);

/* Whether primitive i is a target on its own: not a light, not a plane,
 * with a specular lobe (a mesh's triangles are aimed at as one).  A
 * gather ray that meets a triangle or sphere light right after such a
 * primitive (and after no diffuse event) counts nothing: the caustic
 * photons carry that light. */
int specular_target_part(const rscene *rs, int i);

/* Whether a ray's first hit, primitive prim, is on target tg. */
int specular_target_hit(const rscene *rs, const specular_target *tg, int prim);

/* A sphere around a triangle or sphere part. */
void part_bounding_sphere(const rs_part *p, vec3 *c, double *r);

/* 1 - cos of the half-angle of a sphere of radius r seen from distance
 * d > r, without cancellation for small cones. */
double specular_cone_omc(double r, double d);

#endif
