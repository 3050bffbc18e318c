/* Where the zone tracer keeps irradiance: at *nodes*, points spread over
 * every diffuse surface, read back by interpolation between them; and the
 * *elements* between the nodes, the small pieces of surface that send the
 * light of one level on to the next (transfer.c).
 *
 *   triangle (a part or a mesh triangle): an n x n barycentric grid, n the
 *     longest edge over the node spacing h (1 for a triangle smaller than
 *     h); nodes at the grid's points, elements its n^2 sub-triangles, read
 *     linearly inside each.  A smooth mesh's triangles share their corner
 *     nodes by vertex (with the vertex normal), so its light is continuous.
 *   plane: a grid of nodes, spacing h over the scene's core and growing by
 *     a factor 1.25 a step outside it, out to 64 core extents; elements its
 *     cells, read bilinearly.
 *   sphere: nodes on rows of latitude (cell centres) and columns of
 *     longitude; elements the cells between, read bilinearly.
 *
 * Two-sided surfaces (not back-culled) have a second set of nodes for the
 * back side.  A node may be *dead*: where no light can arrive (inside a
 * closed object, behind a wall of the room); dead nodes are left out of
 * every read and every element. */
#ifndef ZT_ZONE_MAPS_SURFACE_NODES_H
#define ZT_ZONE_MAPS_SURFACE_NODES_H

#include <stdint.h>

#include "render/render_scene.h"
#include "util/vec3.h"

/* A plane's grid: points origin + s u + t v for s in su[], t in sv[]. */
typedef struct node_plane {
    vec3 origin, u, v, n;
    int nu, nv;
    double *su, *sv;    /* ascending node coordinates */
    /* Where each axis's uniform core begins in su / sv, and its cells. */
    int core_u, cells_u, core_v, cells_v;
} node_plane;

/* A sphere's grid: row i at polar angle (i + 0.5) pi / nt from +z' (the
 * local frame's axis), column j at azimuth 2 pi j / np. */
typedef struct node_sphere {
    vec3 centre, ax, ay, az;
    double radius;
    int nt, np;
} node_sphere;

enum { NODE_NONE = 0, NODE_TRIANGLE, NODE_PLANE, NODE_SPHERE };

/* How one primitive's nodes are found. */
typedef struct node_prim {
    uint8_t kind;       /* NODE_* */
    uint8_t sides;      /* 1 or 2 */
    uint8_t shared;     /* triangle: corners are its mesh's vertex nodes */
    uint16_t n;         /* triangle: grid steps per side */
    int32_t first;      /* first own node of side 0; side 1's follow them */
    int32_t count;      /* own nodes per side */
    int32_t geom;       /* plane or sphere: index into planes[]/spheres[] */
} node_prim;

typedef struct surface_nodes {
    int prim_count;
    node_prim *prim;            /* by primitive number (prim.h) */
    node_plane *planes;
    int plane_count;
    node_sphere *spheres;
    int sphere_count;
    /* Per mesh (rs->meshes order): the first of its vertex nodes, or -1
     * when its triangles do not share corners; side s of vertex v is node
     * vertex_first[k] + s * vertex_count + v. */
    int32_t *vertex_first;
    int mesh_count;

    int node_count;
    float *pos;                 /* 3 per node */
    float *nrm;                 /* 3 per node: the side's (shading) normal */
    int32_t *prim_of;           /* a primitive the node lies on */
    uint8_t *live;              /* 0: dead (no light arrives there) */
    float *growth;              /* how many times wider the cells around
                                   the node are than h (>= 1; planes' outer
                                   rings grow) */
    double h;                   /* node spacing over the core */
} surface_nodes;

/* Lays out the nodes of every diffuse thing primitive of rs: spacing h,
 * planes' grids over the core [lo, hi] (at most max_side nodes a side over
 * it).  Positions and normals are set, every node live.  Returns 1, 0
 * when out of memory, or -1 when the nodes would be more than max_nodes (or
 * 2^31): *wanted then says how many, before anything large is allocated. */
int surface_nodes_build(surface_nodes *sn, const rscene *rs, const zt_scene *scene, double h,
                        int max_side, vec3 lo, vec3 hi, long long max_nodes,
                        long long *wanted);

void surface_nodes_free(surface_nodes *sn);

/* The nodes and weights that interpolate side `side` of primitive prim at
 * point x (on the primitive): up to 4 of them; dead nodes are left out and
 * the others' weights renormalised.  Returns the count (0: nothing live
 * there, or the primitive has no nodes). */
int surface_nodes_weights(const surface_nodes *sn, const rscene *rs, int prim, int side, vec3 x,
                          int32_t node[4], float w[4]);

/* Elements: side `side` of primitive prim has element_count(prim) of them,
 * each a polygon of 3 or 4 corners whose light is the mean of its corner
 * nodes' (the live ones).  Corners and nodes run counter-clockwise about
 * the side's normal. */
int surface_element_count(const surface_nodes *sn, int prim);
/* Element e of prim's side: its corners (q, in scene space) and their
 * nodes; returns the corner count (3 or 4). */
int surface_element(const surface_nodes *sn, const rscene *rs, int prim, int side, int e,
                    vec3 q[4], int32_t node[4]);

/* Coarse and fine nodes, for computing fewer of them where the light is
 * smooth.  On a plane's and a triangle's grid, nodes are taken in rounds: those with both indices
 * multiples of 4 (round 0), then the midpoints between them along grid
 * lines (rounds 1 and 2: first those with one index an odd multiple of 2,
 * then those with both), then between those (rounds 3 and 4, stride 1).  A
 * node of round r > 0 lies between line[1] and line[2] on a grid line,
 * with line[0] and line[3] beyond them, all of earlier rounds; pos[0..3]
 * are their positions along the line and pos[4] the node's.  Returns the
 * round (0 for every node that has no such line: it is computed). */
#define NODE_ROUNDS 5
int surface_node_line(const surface_nodes *sn, const rscene *rs, int32_t k, int32_t line[4],
                      double pos[5]);


/* The node of side `side`, grid point (i, j) of a triangle primitive
 * (i + j <= n). */
int32_t surface_tri_node(const surface_nodes *sn, const rscene *rs, int prim, int side, int i,
                         int j);

#endif
