/* Primitives by number: parts (0 .. part_count-1, stored as rs_part) and
 * mesh triangles (part_count .. prim_count-1, stored in the meshes' flat
 * arrays).  What a renderer needs of a hit on either: the rs_part view
 * (made on the fly for a mesh triangle, about 30 operations), the shading
 * normal and the albedo at the point. */
#ifndef ZT_RENDER_PRIM_H
#define ZT_RENDER_PRIM_H

#include "render/render_scene.h"
#include "scene/mesh.h"
#include "util/vec3f.h"

/* The mesh that primitive `prim` (a mesh triangle) belongs to. */
static inline const rs_mesh *rs_mesh_of(const rscene *rs, int prim)
{
    int lo = 0, hi = rs->mesh_count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (rs->meshes[mid].prim_base <= prim)
            lo = mid;
        else
            hi = mid - 1;
    }
    return &rs->meshes[lo];
}

/* The triangle's three vertex indices. */
static inline const uint32_t *rs_mesh_tri(const rs_mesh *mm, int prim)
{
    return mm->m->index + 3 * (size_t)(prim - mm->prim_base);
}

static inline vec3f rs_mesh_vertex(const rs_mesh *mm, uint32_t v)
{
    const float *p = mm->m->position + 3 * (size_t)v;
    return f3(p[0], p[1], p[2]);
}

/* The object (material or emission) of a mesh triangle. */
static inline int rs_mesh_object(const rs_mesh *mm, int prim)
{
    if (mm->is_light)
        return mm->object_base;
    return mm->object_base + mesh_slot_of(mm->m, prim - mm->prim_base);
}

/* Fills *out as rscene_build fills an rs_part for a triangle part. */
void rs_mesh_part(const rscene *rs, const rs_mesh *mm, int prim, rs_part *out);

/* The rs_part of any primitive: a pointer into rs->parts, or tmp filled. */
static inline const rs_part *rs_prim(const rscene *rs, int prim, rs_part *tmp)
{
    if (prim < rs->part_count)
        return &rs->parts[prim];
    rs_mesh_part(rs, rs_mesh_of(rs, prim), prim, tmp);
    return tmp;
}

/* The point's barycentric weights (of vertices 1 and 2) on triangle p. */
static inline void rs_triangle_barycentric(const rs_part *p, vec3f x, float *b1, float *b2)
{
    vec3f d = f3_sub(x, p->p0);
    float d00 = f3_dot(p->e1, p->e1), d01 = f3_dot(p->e1, p->e2);
    float d11 = f3_dot(p->e2, p->e2);
    float d20 = f3_dot(d, p->e1), d21 = f3_dot(d, p->e2);
    float den = d00 * d11 - d01 * d01;
    float inv = den != 0.0f ? 1.0f / den : 0.0f;
    *b1 = (d11 * d20 - d01 * d21) * inv;
    *b2 = (d00 * d21 - d01 * d20) * inv;
}

/* The radiance light primitive `prim` (object o) emits at barycentric
 * weights b1, b2 of its triangle: o's emission, times the emissive
 * texture's texel there for a mesh triangle with one.  Sides and culling
 * are the caller's (light_emitted). */
vec3f rs_emission_bary(const rscene *rs, int prim, const rs_object *o, float b1, float b2);

/* The same at point x of the primitive (view p). */
static inline vec3f rs_emission_at(const rscene *rs, int prim, const rs_part *p,
                                   const rs_object *o, vec3f x)
{
    if (!o->emissive)
        return o->emission;
    float b1, b2;
    rs_triangle_barycentric(p, x, &b1, &b2);
    return rs_emission_bary(rs, prim, o, b1, b2);
}

/* Its mean radiance over its surface: what its power (next-event
 * estimation's choice) and the zone tracer's lights, polygons of one
 * radiance, take. */
static inline vec3f rs_emission_mean(const rscene *rs, int prim, const rs_object *o)
{
    if (!o->emissive || prim < rs->part_count)
        return o->emission;
    const rs_mesh *mm = rs_mesh_of(rs, prim);
    return mm->emit_mean ? mm->emit_mean[prim - mm->prim_base] : o->emission;
}

/* The mean of o's emission over mesh triangle t of m (o has an emissive
 * texture and m texture coordinates): a midpoint rule over the triangle
 * cut into n^2 equal ones, n growing with the texels the triangle spans
 * (about 4 points per texel along its longest side, 2 <= n <= 64). */
vec3f rs_emission_triangle_mean(const rs_object *o, const struct mesh *m, int t);

/* What shading takes from a hit besides the rs_part: the shading normal
 * (unit, on the side of the geometric normal n_facing, which faces the
 * incoming ray), the albedo (the object's colour, times its texture) and,
 * for an object with maps (rs_object.maps), the material at the hit. */
typedef struct rs_shade {
    vec3f ns;
    vec3f albedo;
    const rs_object *m; /* &mat when the maps gave it, else NULL: the
                           object's own (rs_shade_material) */
    rs_object mat;      /* the object's with the maps' weights, alpha and
                           rough at the hit, and color = albedo */
} rs_shade;

/* For a hit at x on primitive prim (view p, object m) whose geometric
 * normal facing the ray is n_facing.  Parts and flat meshes have ns =
 * n_facing.  A shading normal bent beyond the geometric horizon is pulled
 * back to it (light must not leak through the surface). */
void rs_shade_at(const rscene *rs, int prim, const rs_part *p, const rs_object *m, vec3f x,
                 vec3f n_facing, rs_shade *out);

/* Whether the hit needs rs_shade_at at all (a textured object, one with
 * maps, or a smooth mesh); when not, ns = n_facing, albedo = m->color and
 * the material is m. */
static inline int rs_needs_shade(const rscene *rs, int prim, const rs_object *m)
{
    return m->texture != NULL || m->maps != NULL ||
           (prim >= rs->part_count && rs_mesh_of(rs, prim)->smooth);
}

/* The share of the surface present at hit x of primitive prim (view p,
 * object m, which has an alpha_mode): its coverage factor times the base
 * texture's alpha there; for ALPHA_MASK 1 at or above the cutoff, else 0.
 * A hit of coverage 0 is a hole that rays go through (accel.h); between 0
 * and 1 (BLEND) the surface is that share of its material and the rest
 * lets light pass untouched. */
float rs_coverage_at(const rscene *rs, int prim, const rs_part *p, const rs_object *m, vec3f x);

/* m's mean coverage over the triangle of texture coordinates uv0, uv1,
 * uv2 (NULL: none) on texture_triangle_mean's lattice of n (n + 1) / 2
 * points; 1 without an alpha_mode. */
float rs_coverage_mean(const rs_object *m, const float *uv0, const float *uv1, const float *uv2,
                       int n);

/* The coverage of a hit on any object: 1 unless m has an alpha_mode. */
static inline float rs_coverage(const rscene *rs, int prim, const rs_part *p,
                                const rs_object *m, vec3f x)
{
    return m->alpha_mode ? rs_coverage_at(rs, prim, p, m, x) : 1.0f;
}

/* The mean diffuse weight of m (which has a metal map) over the triangle
 * of texture coordinates uv0, uv1, uv2, on texture_triangle_mean's
 * lattice of n (n + 1) / 2 points. */
float rs_maps_diffuse_mean(const rs_object *m, const float *uv0, const float *uv1,
                           const float *uv2, int n);

/* The material at the hit that sh describes, m being the object's. */
static inline const rs_object *rs_shade_material(const rs_shade *sh, const rs_object *m)
{
    return sh->m ? sh->m : m;
}

#endif
