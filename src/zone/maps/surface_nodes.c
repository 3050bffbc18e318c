/* The layout of irradiance nodes and elements over the surfaces
 * (surface_nodes.h). */
#include "zone/maps/surface_nodes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/prim.h"
#include "util/vec3_convert.h"

#define PI 3.14159265358979323846
/* Outside the core a plane's cells grow by this factor each, out to this
 * many core extents: light that leaves an open room and comes back from
 * far away is kept, for a few dozen nodes more a side. */
#define OUTER_GROWTH 1.25
#define OUTER_REACH 64.0
#define MAX_TRI_STEPS 512
#define MAX_SPHERE_ROWS 256
/* Nodes on a triangle's edge or a wall's seam are lit this share of a
 * cell inside (the old texel centres were half a cell inside). */
#define EDGE_INSET 0.25

/* A model's triangles take nodes at half the spacing.  Their corners are
 * the model's vertices, often on its creases and seams, where the parts
 * around shade them; a triangle up to h long would otherwise be read, and
 * send its light, from its corners alone.  On the engine room at depth 3
 * this takes the error over 4 x 4 blocks from 1.36% to 1.06% for about 15%
 * more time (only the triangles with a corner on a crease: 1.14%).  A
 * smooth sphere of a few hundred triangles gains nothing and its Phase
 * One takes up to 2.3 times as long (the N-series at N = 840).  Triangles
 * written in the scene file keep h: their edge nodes sit a quarter cell
 * inside, and half the spacing made the shipped scenes no better
 * (triangletest 0.65% -> 0.83%) for up to 3.7 times the Phase One. */
#define MODEL_SPACING 0.5

static int tri_total(int n) { return (n + 1) * (n + 2) / 2; }
/* Row j of a triangle's grid starts here (row j holds n - j + 1 nodes). */
static int tri_row(int n, int j) { return j * (n + 1) - j * (j - 1) / 2; }

static int is_diffuse_thing(const rscene *rs, const rs_part *p)
{
    const rs_object *o = &rs->objects[p->object];
    return !o->is_light && o->weight[LOBE_DIFFUSE] > 0.0f;
}

/* Node coordinates along one plane axis: uniform over [a, b] (at least h
 * wide, at most max_side steps), then growing outward to `reach`. */
static double *plane_axis(double a, double b, double h, int max_side, double reach, int *count,
                          int *core, int *cells)
{
    if (b - a < h) {
        double c = 0.5 * (a + b);
        a = c - 0.5 * h;
        b = c + 0.5 * h;
    }
    int k = (int)ceil((b - a) / h - 1e-9);
    if (k < 1)
        k = 1;
    if (k > max_side)
        k = max_side;
    double w = (b - a) / k;
    int outer = 0;
    for (double s = 0, step = w; s < reach; step *= OUTER_GROWTH, outer++)
        s += step * OUTER_GROWTH;
    int n = k + 1 + 2 * outer;
    double *x = malloc((size_t)n * sizeof *x);
    if (!x)
        return NULL;
    for (int i = 0; i <= k; i++)
        x[outer + i] = i == k ? b : a + i * w;
    double lo = a, hi = b, step = w;
    for (int m = 1; m <= outer; m++) {
        step *= OUTER_GROWTH;
        lo -= step;
        hi += step;
        x[outer - m] = lo;
        x[outer + k + m] = hi;
    }
    *count = n;
    *core = outer;
    *cells = k;
    return x;
}

static void plane_frame(vec3 n, vec3 *u, vec3 *v)
{
    /* The world axis least aligned with n lies in the plane's frame, so an
     * axis-aligned room's walls fall on grid lines. */
    vec3 a = fabs(n.x) <= fabs(n.y) && fabs(n.x) <= fabs(n.z) ? v3(1, 0, 0)
             : fabs(n.y) <= fabs(n.z)                         ? v3(0, 1, 0)
                                                              : v3(0, 0, 1);
    *u = v3_normalize(v3_sub(a, v3_scale(n, v3_dot(a, n))));
    *v = v3_cross(n, *u);
}

static int build_plane(node_plane *pl, const rs_part *p, double h, int max_side, vec3 lo,
                       vec3 hi)
{
    vec3 n = v3_normalize(f3_to_v3(p->n));
    pl->n = n;
    plane_frame(n, &pl->u, &pl->v);
    pl->origin = v3_scale(n, p->offset);
    double s0 = 1e300, s1 = -1e300, t0 = 1e300, t1 = -1e300;
    for (int c = 0; c < 8; c++) {
        vec3 q = v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        vec3 d = v3_sub(q, pl->origin);
        double s = v3_dot(d, pl->u), t = v3_dot(d, pl->v);
        s0 = fmin(s0, s), s1 = fmax(s1, s), t0 = fmin(t0, t), t1 = fmax(t1, t);
    }
    double reach = OUTER_REACH * v3_length(v3_sub(hi, lo));
    pl->su = plane_axis(s0, s1, h, max_side, reach, &pl->nu, &pl->core_u, &pl->cells_u);
    pl->sv = plane_axis(t0, t1, h, max_side, reach, &pl->nv, &pl->core_v, &pl->cells_v);
    return pl->su && pl->sv;
}

static void build_sphere(node_sphere *s, const rs_part *p, double h)
{
    s->centre = f3_to_v3(p->p0);
    s->radius = p->radius;
    s->ax = v3(1, 0, 0);
    s->ay = v3(0, 0, -1);
    s->az = v3(0, 1, 0); /* the pole points up (+y), as the scenes stand */
    int nt = (int)ceil(PI * s->radius / h);
    s->nt = nt < 4 ? 4 : nt > MAX_SPHERE_ROWS ? MAX_SPHERE_ROWS : nt;
    s->np = 2 * s->nt;
}

static vec3 sphere_dir(const node_sphere *s, double theta, double phi)
{
    double st = sin(theta);
    return v3_add(v3_add(v3_scale(s->ax, st * cos(phi)), v3_scale(s->ay, st * sin(phi))),
                  v3_scale(s->az, cos(theta)));
}

static vec3 vertex_normal(const rs_mesh *mm, uint32_t v)
{
    const float *q = mm->m->normal + 3 * (size_t)v;
    return v3_normalize(v3(q[0], q[1], q[2]));
}

/* Triangle prim's own node (local index L of the full grid) position and
 * normal. */
static void tri_node_point(const rscene *rs, int prim, const rs_part *p, int n, int i, int j,
                           vec3 *x, vec3 *nrm)
{
    double b1 = (double)i / n, b2 = (double)j / n, b0 = 1.0 - b1 - b2;
    vec3 p0 = f3_to_v3(p->p0);
    *x = v3_add(p0, v3_add(v3_scale(f3_to_v3(p->e1), b1), v3_scale(f3_to_v3(p->e2), b2)));
    *nrm = v3_normalize(f3_to_v3(p->n));
    if (prim >= rs->part_count) {
        const rs_mesh *mm = rs_mesh_of(rs, prim);
        if (mm->smooth) {
            const uint32_t *v = rs_mesh_tri(mm, prim);
            vec3 s = v3_add(v3_add(v3_scale(vertex_normal(mm, v[0]), b0),
                                   v3_scale(vertex_normal(mm, v[1]), b1)),
                            v3_scale(vertex_normal(mm, v[2]), b2));
            if (v3_length(s) > 0)
                *nrm = v3_normalize(s);
        }
    }
}

static vec3 tri_centroid(const rs_part *p)
{
    vec3 p0 = f3_to_v3(p->p0);
    return v3_add(p0, v3_scale(v3_add(f3_to_v3(p->e1), f3_to_v3(p->e2)), 1.0 / 3.0));
}

static void set_node(surface_nodes *sn, int32_t k, vec3 x, vec3 n, int prim)
{
    sn->pos[3 * k] = (float)x.x;
    sn->pos[3 * k + 1] = (float)x.y;
    sn->pos[3 * k + 2] = (float)x.z;
    sn->nrm[3 * k] = (float)n.x;
    sn->nrm[3 * k + 1] = (float)n.y;
    sn->nrm[3 * k + 2] = (float)n.z;
    sn->prim_of[k] = prim;
    sn->live[k] = 1;
}

/* surface_tri_node with the primitive's mesh given (NULL for a part). */
static int32_t tri_node_in(const surface_nodes *sn, const rscene *rs, const rs_mesh *mm, int prim,
                           int side, int i, int j)
{
    const node_prim *np = &sn->prim[prim];
    int n = np->n;
    int corner = (i == 0 && j == 0) ? 0 : (i == n && j == 0) ? 1 : (i == 0 && j == n) ? 2 : -1;
    if (np->shared && corner >= 0) {
        int k = (int)(mm - rs->meshes);
        return sn->vertex_first[k] + side * mm->m->vertex_count +
               (int32_t)rs_mesh_tri(mm, prim)[corner];
    }
    int local = tri_row(n, j) + i;
    if (np->shared)
        local -= 1 + (local > n);
    return np->first + side * np->count + local;
}

int32_t surface_tri_node(const surface_nodes *sn, const rscene *rs, int prim, int side, int i,
                         int j)
{
    const rs_mesh *mm = sn->prim[prim].shared ? rs_mesh_of(rs, prim) : NULL;
    return tri_node_in(sn, rs, mm, prim, side, i, j);
}

int surface_nodes_build(surface_nodes *sn, const rscene *rs, const zt_scene *scene, double h,
                        int max_side, vec3 lo, vec3 hi, long long max_nodes,
                        long long *wanted)
{
    (void)scene;
    memset(sn, 0, sizeof *sn);
    sn->h = h;
    sn->prim_count = rs->prim_count;
    sn->mesh_count = rs->mesh_count;
    sn->prim = calloc((size_t)rs->prim_count + 1, sizeof *sn->prim);
    sn->vertex_first = malloc(((size_t)rs->mesh_count + 1) * sizeof *sn->vertex_first);
    sn->planes = calloc((size_t)rs->part_count + 1, sizeof *sn->planes);
    sn->spheres = calloc((size_t)rs->part_count + 1, sizeof *sn->spheres);
    if (!sn->prim || !sn->vertex_first || !sn->planes || !sn->spheres)
        return 0;
    /* First pass: the layout and the node count. */
    long long count = 0;
    for (int k = 0; k < rs->mesh_count; k++) {
        const rs_mesh *mm = &rs->meshes[k];
        sn->vertex_first[k] = -1;
        if (mm->smooth && !mm->is_light) {
            sn->vertex_first[k] = (int32_t)count;
            count += (long long)mm->m->vertex_count * (mm->culled ? 1 : 2);
        }
    }
    for (int prim = 0; prim < rs->prim_count; prim++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, prim, &tmp);
        node_prim *np = &sn->prim[prim];
        np->first = -1;
        if (!is_diffuse_thing(rs, p))
            continue;
        np->sides = p->culled ? 1 : 2;
        switch (p->shape) {
        case SHAPE_TRIANGLE: {
            vec3f a = p->e1, b = p->e2, c = f3_sub(p->e2, p->e1);
            double edge = fmax(f3_length(a), fmax(f3_length(b), f3_length(c)));
            double spacing = prim >= rs->part_count ? MODEL_SPACING * h : h;
            int n = (int)ceil(edge / spacing - 1e-9);
            np->kind = NODE_TRIANGLE;
            np->n = (uint16_t)(n < 1 ? 1 : n > MAX_TRI_STEPS ? MAX_TRI_STEPS : n);
            np->shared = prim >= rs->part_count &&
                         sn->vertex_first[rs_mesh_of(rs, prim) - rs->meshes] >= 0;
            np->count = tri_total(np->n) - (np->shared ? 3 : 0);
            break;
        }
        case SHAPE_PLANE: {
            node_plane *pl = &sn->planes[sn->plane_count];
            if (!build_plane(pl, p, h, max_side, lo, hi))
                return 0;
            np->kind = NODE_PLANE;
            np->geom = sn->plane_count++;
            np->count = pl->nu * pl->nv;
            break;
        }
        case SHAPE_SPHERE: {
            node_sphere *s = &sn->spheres[sn->sphere_count];
            build_sphere(s, p, h);
            np->kind = NODE_SPHERE;
            np->geom = sn->sphere_count++;
            np->count = s->nt * s->np;
            break;
        }
        default:
            continue;
        }
        np->first = count < INT32_MAX ? (int32_t)count : -1;
        count += (long long)np->count * np->sides;
    }
    *wanted = count;
    if (count > INT32_MAX - 1 || count > max_nodes)
        return -1;
    sn->node_count = (int)count;
    size_t nc = (size_t)count + 1;
    sn->pos = malloc(nc * 3 * sizeof(float));
    sn->nrm = malloc(nc * 3 * sizeof(float));
    sn->prim_of = malloc(nc * sizeof(int32_t));
    sn->live = calloc(nc, 1);
    sn->growth = malloc(nc * sizeof(float));
    if (!sn->pos || !sn->nrm || !sn->prim_of || !sn->live || !sn->growth)
        return 0;
    for (size_t k = 0; k < nc; k++)
        sn->growth[k] = 1.0f;
    /* Second pass: positions and normals. */
    for (int k = 0; k < rs->mesh_count; k++) {
        if (sn->vertex_first[k] < 0)
            continue;
        const rs_mesh *mm = &rs->meshes[k];
        int sides = mm->culled ? 1 : 2, vc = mm->m->vertex_count;
        for (int s = 0; s < sides; s++)
            for (int v = 0; v < vc; v++) {
                const float *q = mm->m->position + 3 * (size_t)v;
                vec3 nrm = vertex_normal(mm, (uint32_t)v);
                set_node(sn, sn->vertex_first[k] + s * vc + v, v3(q[0], q[1], q[2]),
                         s ? v3_scale(nrm, -1) : nrm, mm->prim_base);
                /* A vertex no triangle uses stays dead. */
                sn->live[sn->vertex_first[k] + s * vc + v] = 0;
            }
    }
    for (int prim = 0; prim < rs->prim_count; prim++) {
        node_prim *np = &sn->prim[prim];
        if (np->first < 0)
            continue;
        rs_part tmp;
        const rs_part *p = rs_prim(rs, prim, &tmp);
        for (int side = 0; side < np->sides; side++) {
            double sg = side ? -1.0 : 1.0;
            if (np->kind == NODE_TRIANGLE) {
                int n = np->n;
                for (int j = 0; j <= n; j++)
                    for (int i = 0; i + j <= n; i++) {
                        vec3 x, nrm;
                        tri_node_point(rs, prim, p, n, i, j, &x, &nrm);
                        /* A node on the triangle's edge is lit a quarter
                         * cell inside: where the triangle meets another
                         * surface (a box on the floor), the light at the
                         * very edge is a limit that the cells beside it
                         * do not follow (a corner sees its neighbour
                         * edge-on). */
                        if (!np->shared && (i == 0 || j == 0 || i + j == n))
                            x = v3_add(x, v3_scale(v3_sub(tri_centroid(p), x),
                                                   EDGE_INSET / (n * (1.0 - 1.0 / 3.0))));
                        int32_t k = surface_tri_node(sn, rs, prim, side, i, j);
                        if (k >= np->first && k < np->first + np->sides * np->count)
                            set_node(sn, k, x, v3_scale(nrm, sg), prim);
                        else
                            sn->live[k] = 1; /* a used shared vertex */
                    }
            } else if (np->kind == NODE_PLANE) {
                const node_plane *pl = &sn->planes[np->geom];
                for (int j = 0; j < pl->nv; j++)
                    for (int i = 0; i < pl->nu; i++) {
                        vec3 x = v3_add(pl->origin, v3_add(v3_scale(pl->u, pl->su[i]),
                                                           v3_scale(pl->v, pl->sv[j])));
                        int32_t k = np->first + side * np->count + j * pl->nu + i;
                        set_node(sn, k, x, v3_scale(pl->n, sg), prim);
                        double wu = dmax(i > 0 ? pl->su[i] - pl->su[i - 1] : 0,
                                         i + 1 < pl->nu ? pl->su[i + 1] - pl->su[i] : 0);
                        double wv = dmax(j > 0 ? pl->sv[j] - pl->sv[j - 1] : 0,
                                         j + 1 < pl->nv ? pl->sv[j + 1] - pl->sv[j] : 0);
                        sn->growth[k] = (float)dmax(1.0, dmax(wu, wv) / (h * 1.0001));
                    }
            } else {
                const node_sphere *s = &sn->spheres[np->geom];
                for (int i = 0; i < s->nt; i++)
                    for (int j = 0; j < s->np; j++) {
                        vec3 d = sphere_dir(s, (i + 0.5) * PI / s->nt, 2 * PI * j / s->np);
                        set_node(sn, np->first + side * np->count + i * s->np + j,
                                 v3_add(s->centre, v3_scale(d, s->radius)), v3_scale(d, sg), prim);
                    }
            }
        }
    }
    return 1;
}

void surface_nodes_free(surface_nodes *sn)
{
    for (int i = 0; i < sn->plane_count; i++) {
        free(sn->planes[i].su);
        free(sn->planes[i].sv);
    }
    free(sn->planes);
    free(sn->spheres);
    free(sn->prim);
    free(sn->vertex_first);
    free(sn->pos);
    free(sn->nrm);
    free(sn->prim_of);
    free(sn->live);
    free(sn->growth);
    memset(sn, 0, sizeof *sn);
}

/* Index of the cell [x[i], x[i+1]] holding s (clamped) and the fraction:
 * the last i with x[i] <= s.  Inside the uniform core (cells from `core`
 * on) the cell is guessed from its width and set right by a step or two
 * (the rounding of the guess); outside it, a binary search.  Camera
 * samples read the core nearly always, and the search's seven dependent
 * steps were most of a plane's read. */
static int axis_cell(const double *x, int n, int core, int cells, double s, double *f)
{
    if (s <= x[0]) {
        *f = 0;
        return 0;
    }
    if (s >= x[n - 1]) {
        *f = 1;
        return n - 2;
    }
    int lo;
    double a = x[core], b = x[core + cells];
    if (s >= a && s < b) {
        lo = core + (int)((s - a) / (b - a) * cells);
        if (lo > core + cells - 1)
            lo = core + cells - 1;
        while (x[lo] > s)
            lo--;
        while (x[lo + 1] <= s)
            lo++;
    } else {
        lo = 0;
        int hi = n - 1;
        while (hi - lo > 1) {
            int mid = (lo + hi) / 2;
            if (x[mid] <= s)
                lo = mid;
            else
                hi = mid;
        }
    }
    *f = (s - x[lo]) / (x[lo + 1] - x[lo]);
    return lo;
}

/* Drops dead nodes and renormalises; returns the count left. */
static int keep_live(const surface_nodes *sn, int32_t node[4], float w[4], int count)
{
    int m = 0;
    float sum = 0.0f;
    for (int k = 0; k < count; k++)
        if (w[k] > 0.0f && sn->live[node[k]]) {
            node[m] = node[k];
            w[m] = w[k];
            sum += w[k];
            m++;
        }
    if (m == 0 || !(sum > 0.0f)) {
        /* All weight on dead nodes: the nearest live one, if any. */
        for (int k = 0; k < count; k++)
            if (sn->live[node[k]]) {
                node[0] = node[k];
                w[0] = 1.0f;
                return 1;
            }
        return 0;
    }
    for (int k = 0; k < m; k++)
        w[k] /= sum;
    return m;
}

int surface_nodes_weights(const surface_nodes *sn, const rscene *rs, int prim, int side, vec3 x,
                          int32_t node[4], float w[4])
{
    if (prim < 0 || prim >= sn->prim_count)
        return 0;
    const node_prim *np = &sn->prim[prim];
    if (np->first < 0 || side >= np->sides)
        return 0;
    switch (np->kind) {
    case NODE_TRIANGLE: {
        /* Only the corner and the edges are needed: a mesh triangle's are
         * read from its vertices (as rs_mesh_part makes them), not through
         * the whole part view, whose frame and normal cost more than the
         * rest of this read. */
        const rs_mesh *mm = NULL;
        rs_part corner;
        const rs_part *p = &corner;
        if (prim < rs->part_count) {
            p = &rs->parts[prim];
        } else {
            mm = rs_mesh_of(rs, prim);
            const uint32_t *tv = rs_mesh_tri(mm, prim);
            corner.p0 = rs_mesh_vertex(mm, tv[0]);
            corner.e1 = f3_sub(rs_mesh_vertex(mm, tv[1]), corner.p0);
            corner.e2 = f3_sub(rs_mesh_vertex(mm, tv[2]), corner.p0);
        }
        float b1, b2;
        rs_triangle_barycentric(p, v3_to_f3(x), &b1, &b2);
        int n = np->n;
        double u = fmin(fmax((double)b1, 0.0), 1.0) * n, v = fmin(fmax((double)b2, 0.0), 1.0) * n;
        if (u + v > n) {
            double s = n / (u + v);
            u *= s;
            v *= s;
        }
        int i = (int)floor(u), j = (int)floor(v);
        if (i > n - 1)
            i = n - 1;
        if (j > n - 1)
            j = n - 1;
        if (i + j > n - 1)
            i = n - 1 - j;
        double fu = u - i, fv = v - j;
        if (fu + fv <= 1.0) {
            node[0] = tri_node_in(sn, rs, mm, prim, side, i, j);
            node[1] = tri_node_in(sn, rs, mm, prim, side, i + 1, j);
            node[2] = tri_node_in(sn, rs, mm, prim, side, i, j + 1);
            w[0] = (float)(1.0 - fu - fv), w[1] = (float)fu, w[2] = (float)fv;
        } else {
            node[0] = tri_node_in(sn, rs, mm, prim, side, i + 1, j + 1);
            node[1] = tri_node_in(sn, rs, mm, prim, side, i, j + 1);
            node[2] = tri_node_in(sn, rs, mm, prim, side, i + 1, j);
            w[0] = (float)(fu + fv - 1.0), w[1] = (float)(1.0 - fu), w[2] = (float)(1.0 - fv);
        }
        return keep_live(sn, node, w, 3);
    }
    case NODE_PLANE: {
        const node_plane *pl = &sn->planes[np->geom];
        vec3 d = v3_sub(x, pl->origin);
        double fu, fv;
        int i = axis_cell(pl->su, pl->nu, pl->core_u, pl->cells_u, v3_dot(d, pl->u), &fu);
        int j = axis_cell(pl->sv, pl->nv, pl->core_v, pl->cells_v, v3_dot(d, pl->v), &fv);
        int32_t base = np->first + side * np->count;
        node[0] = base + j * pl->nu + i;
        node[1] = node[0] + 1;
        node[2] = node[0] + pl->nu;
        node[3] = node[2] + 1;
        w[0] = (float)((1 - fu) * (1 - fv)), w[1] = (float)(fu * (1 - fv));
        w[2] = (float)((1 - fu) * fv), w[3] = (float)(fu * fv);
        return keep_live(sn, node, w, 4);
    }
    case NODE_SPHERE: {
        const node_sphere *s = &sn->spheres[np->geom];
        vec3 d = v3_normalize(v3_sub(x, s->centre));
        double theta = acos(fmax(-1.0, fmin(1.0, v3_dot(d, s->az))));
        double phi = atan2(v3_dot(d, s->ay), v3_dot(d, s->ax));
        if (phi < 0)
            phi += 2 * PI;
        double r = theta / (PI / s->nt) - 0.5, c = phi / (2 * PI / s->np);
        int i = (int)floor(r), j = (int)floor(c);
        double fr = r - i, fc = c - j;
        if (i < 0) {
            i = 0;
            fr = 0;
        } else if (i >= s->nt - 1) {
            i = s->nt - 2;
            fr = 1;
        }
        j = ((j % s->np) + s->np) % s->np;
        int j1 = (j + 1) % s->np;
        int32_t base = np->first + side * np->count;
        node[0] = base + i * s->np + j;
        node[1] = base + i * s->np + j1;
        node[2] = base + (i + 1) * s->np + j;
        node[3] = base + (i + 1) * s->np + j1;
        w[0] = (float)((1 - fr) * (1 - fc)), w[1] = (float)((1 - fr) * fc);
        w[2] = (float)(fr * (1 - fc)), w[3] = (float)(fr * fc);
        return keep_live(sn, node, w, 4);
    }
    default:
        return 0;
    }
}

int surface_element_count(const surface_nodes *sn, int prim)
{
    const node_prim *np = &sn->prim[prim];
    if (np->first < 0)
        return 0;
    switch (np->kind) {
    case NODE_TRIANGLE: return np->n * np->n;
    case NODE_PLANE: {
        const node_plane *pl = &sn->planes[np->geom];
        return (pl->nu - 1) * (pl->nv - 1);
    }
    case NODE_SPHERE: {
        const node_sphere *s = &sn->spheres[np->geom];
        return (s->nt + 1) * s->np; /* nt - 1 rows of quads, two caps */
    }
    default: return 0;
    }
}

/* Grid point (i, j) of a planar or triangular primitive, on the surface
 * (node positions may lie a little inside: EDGE_INSET). */
static vec3 tri_grid_point(const rs_part *p, int n, int i, int j)
{
    return v3_add(f3_to_v3(p->p0), v3_add(v3_scale(f3_to_v3(p->e1), (double)i / n),
                                         v3_scale(f3_to_v3(p->e2), (double)j / n)));
}

int surface_element(const surface_nodes *sn, const rscene *rs, int prim, int side, int e,
                    vec3 q[4], int32_t node[4])
{
    const node_prim *np = &sn->prim[prim];
    int corners = 0;
    switch (np->kind) {
    case NODE_TRIANGLE: {
        int n = np->n;
        /* Row j holds 2 (n - j) - 1 elements and starts at n^2 - (n - j)^2. */
        int j = (int)floor(n - sqrt((double)n * n - e));
        while (j > 0 && (long long)n * n - (long long)(n - j) * (n - j) > e)
            j--;
        while (j + 1 < n && (long long)n * n - (long long)(n - j - 1) * (n - j - 1) <= e)
            j++;
        int r = e - (n * n - (n - j) * (n - j));
        int gi[3], gj[3];
        if (r < n - j) {
            gi[0] = r, gj[0] = j, gi[1] = r + 1, gj[1] = j, gi[2] = r, gj[2] = j + 1;
        } else {
            int i = r - (n - j);
            gi[0] = i + 1, gj[0] = j, gi[1] = i + 1, gj[1] = j + 1, gi[2] = i, gj[2] = j + 1;
        }
        rs_part tmp;
        const rs_part *p = rs_prim(rs, prim, &tmp);
        for (int k = 0; k < 3; k++) {
            node[k] = surface_tri_node(sn, rs, prim, side, gi[k], gj[k]);
            q[k] = tri_grid_point(p, n, gi[k], gj[k]);
        }
        corners = 3;
        break;
    }
    case NODE_PLANE: {
        const node_plane *pl = &sn->planes[np->geom];
        int i = e % (pl->nu - 1), j = e / (pl->nu - 1);
        int32_t base = np->first + side * np->count + j * pl->nu + i;
        node[0] = base;
        node[1] = base + 1;
        node[2] = base + 1 + pl->nu;
        node[3] = base + pl->nu;
        const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
        for (int k = 0; k < 4; k++)
            q[k] = v3_add(pl->origin, v3_add(v3_scale(pl->u, pl->su[i + di[k]]),
                                             v3_scale(pl->v, pl->sv[j + dj[k]])));
        corners = 4;
        break;
    }
    case NODE_SPHERE: {
        const node_sphere *s = &sn->spheres[np->geom];
        int32_t base = np->first + side * np->count;
        int row = e / s->np, j = e % s->np, j1 = (j + 1) % s->np;
        if (row == 0 || row == s->nt) {
            /* A polar cap's sector: the pole and two nodes of the end row. */
            int i = row == 0 ? 0 : s->nt - 1;
            vec3 pole = v3_add(s->centre, v3_scale(s->az, row == 0 ? s->radius : -s->radius));
            node[0] = -1;
            node[1] = base + i * s->np + (row == 0 ? j : j1);
            node[2] = base + i * s->np + (row == 0 ? j1 : j);
            double th = (i + 0.5) * PI / s->nt;
            q[0] = pole;
            q[1] = v3_add(s->centre, v3_scale(sphere_dir(s, th, 2 * PI * (row == 0 ? j : j1) / s->np),
                                              s->radius));
            q[2] = v3_add(s->centre, v3_scale(sphere_dir(s, th, 2 * PI * (row == 0 ? j1 : j) / s->np),
                                              s->radius));
            corners = 3;
        } else {
            int i = row - 1;
            node[0] = base + i * s->np + j;
            node[1] = base + (i + 1) * s->np + j;
            node[2] = base + (i + 1) * s->np + j1;
            node[3] = base + i * s->np + j1;
            const int di[4] = {0, 1, 1, 0}, dj[4] = {j, j, j1, j1};
            for (int k = 0; k < 4; k++)
                q[k] = v3_add(s->centre,
                              v3_scale(sphere_dir(s, (i + di[k] + 0.5) * PI / s->nt,
                                                  2 * PI * dj[k] / s->np),
                                       s->radius));
            corners = 4;
        }
        if (corners == 3) {
            if (side) {
                vec3 t = q[1];
                q[1] = q[2];
                q[2] = t;
                int32_t u = node[1];
                node[1] = node[2];
                node[2] = u;
            }
            return corners;
        }
        break;
    }
    default:
        return 0;
    }
    if (side) {
        /* The back side runs the other way round. */
        int32_t t = node[1];
        node[1] = node[corners - 1];
        node[corners - 1] = t;
        vec3 u = q[1];
        q[1] = q[corners - 1];
        q[corners - 1] = u;
    }
    return corners;
}

/* The round of grid point (i, j) and the direction of its line (di, dj)
 * and stride s; round 0: no line. */
static int node_round(int i, int j, int *di, int *dj, int *s)
{
    for (int stride = 2; stride >= 1; stride >>= 1) {
        if (i % stride || j % stride)
            continue;
        int oi = (i / stride) & 1, oj = (j / stride) & 1;
        if (!oi && !oj)
            return 0; /* on the coarser grid */
        *s = stride;
        if (oi != oj) {
            *di = oi, *dj = oj;
            return stride == 2 ? 1 : 3;
        }
        *di = 1, *dj = 0; /* between two edge midpoints of this stride */
        return stride == 2 ? 2 : 4;
    }
    return 0;
}

int surface_node_line(const surface_nodes *sn, const rscene *rs, int32_t k, int32_t line[4],
                      double pos[5])
{
    int prim = sn->prim_of[k];
    const node_prim *np = &sn->prim[prim];
    if (np->first < 0 || k < np->first || k >= np->first + np->sides * np->count)
        return 0; /* a mesh's vertex */
    int side = (k - np->first) / np->count, local = (k - np->first) % np->count;
    int i, j, di = 0, dj = 0, st = 1, round;
    if (np->kind == NODE_PLANE) {
        const node_plane *pl = &sn->planes[np->geom];
        i = local % pl->nu, j = local / pl->nu;
        /* The core's first node sets the phase, so rounds line up with it
         * (indices counted from a multiple of 4 there). */
        if (!(round = node_round(i, j, &di, &dj, &st)))
            return 0;
        int r3 = 3 * st;
        if (i - r3 * di < 0 || j - r3 * dj < 0 || i + r3 * di >= pl->nu || j + r3 * dj >= pl->nv)
            return 0;
        int32_t base = np->first + side * np->count;
        const double *axis = di ? pl->su : pl->sv;
        int at = di ? i : j;
        for (int s = 0; s < 4; s++) {
            int o = (2 * s - 3) * st; /* -3, -1, 1, 3 strides */
            line[s] = base + (j + o * dj) * pl->nu + i + o * di;
            pos[s] = axis[at + o];
        }
        pos[4] = axis[at];
        return round;
    }
    if (np->kind != NODE_TRIANGLE || np->shared)
        return 0;
    int n = np->n;
    j = 0;
    while (j < n && tri_row(n, j + 1) <= local)
        j++;
    i = local - tri_row(n, j);
    if (!(round = node_round(i, j, &di, &dj, &st)))
        return 0;
    int r3 = 3 * st;
    if (i - r3 * di < 0 || j - r3 * dj < 0 || i + r3 * di + j + r3 * dj > n)
        return 0;
    for (int s = 0; s < 4; s++) {
        int o = (2 * s - 3) * st;
        line[s] = surface_tri_node(sn, rs, prim, side, i + o * di, j + o * dj);
        pos[s] = o;
    }
    pos[4] = 0;
    return round;
}
