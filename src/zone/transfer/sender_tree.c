/* The sender tree (sender_tree.h): built once over the elements, split at
 * the median of the longest axis of their centroids; filled per level
 * bottom-up. */
#include "zone/transfer/sender_tree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "material/bsdf.h"
#include "material/texture.h"
#include "render/prim.h"
#include "util/select_nth.h"
#include "util/vec3_convert.h"

#define LEAF_SIZE 2
#define PI 3.14159265358979323846

/* The albedo of an element: what its radiance is per unit irradiance. */
static void element_albedo(const rscene *rs, int prim, const vec3 q[4], int corners,
                           float out[3])
{
    rs_part tmp;
    const rs_part *p = rs_prim(rs, prim, &tmp);
    const rs_object *o = &rs->objects[p->object];
    vec3f col = o->color;
    float k = o->weight[LOBE_DIFFUSE] / (float)PI;
    /* Coverage (alpha): the element sends its mean covered share. */
    if (o->alpha_mode && !(o->texture && prim >= rs->part_count))
        k *= rs_coverage_mean(o, NULL, NULL, NULL, 1);
    if ((o->texture || (o->maps && o->maps->metal)) && prim >= rs->part_count) {
        const rs_mesh *mm = rs_mesh_of(rs, prim);
        if (mm->m->uv) {
            const uint32_t *v = rs_mesh_tri(mm, prim);
            float uv[4][2];
            for (int k = 0; k < corners; k++) {
                float b1, b2;
                rs_triangle_barycentric(p, v3_to_f3(q[k]), &b1, &b2);
                float b0 = 1.0f - b1 - b2;
                for (int a = 0; a < 2; a++)
                    uv[k][a] = b0 * mm->m->uv[2 * v[0] + a] + b1 * mm->m->uv[2 * v[1] + a] +
                               b2 * mm->m->uv[2 * v[2] + a];
            }
            if (o->texture)
                col = f3_mul(col, texture_triangle_mean(o->texture, uv[0], uv[1], uv[2], 4));
            /* A metal map: the element's own diffuse weight, not the
             * object's mean. */
            if (o->maps && o->maps->metal)
                k = rs_maps_diffuse_mean(o, uv[0], uv[1], uv[2], 4) / (float)PI;
            if (o->alpha_mode)
                k *= rs_coverage_mean(o, uv[0], uv[1], uv[2], 4);
        }
    }
    /* A coat (bsdf.h) sends what it reflects of light arriving evenly,
     * s E_avg, as the base does: spread as a diffuse surface's, in the
     * mean over directions; the base keeps the rest. */
    if (o->coat) {
        float a = o->specular * ggx_albedo_coat_average(bsdf_coat_alpha(o));
        col = f3_add(f3_scale(col, 1.0f - a), f3_splat(a));
    }
    out[0] = col.x * k;
    out[1] = col.y * k;
    out[2] = col.z * k;
}

static int make_elem(sender_elem *el, const surface_nodes *sn, const rscene *rs, int prim,
                     int side, int e)
{
    vec3 q[4];
    int32_t node[4];
    int corners = surface_element(sn, rs, prim, side, e, q, node);
    if (corners < 3)
        return 0;
    /* Area and normal of the polygon (a fan from q[0]). */
    vec3 s = v3(0, 0, 0), c = v3(0, 0, 0);
    double area = 0;
    for (int k = 1; k + 1 < corners; k++) {
        vec3 cr = v3_cross(v3_sub(q[k], q[0]), v3_sub(q[k + 1], q[0]));
        double a = 0.5 * v3_length(cr);
        s = v3_add(s, cr);
        c = v3_add(c, v3_scale(v3_add(v3_add(q[0], q[k]), q[k + 1]), a / 3.0));
        area += a;
    }
    if (!(area > 0))
        return 0;
    c = v3_scale(c, 1.0 / area);
    vec3 n = v3_normalize(s);
    rs_part tmp;
    const rs_part *sp = rs_prim(rs, prim, &tmp);
    if (sp->shape == SHAPE_SPHERE && side == 0) {
        /* A sphere's cell is a flat polygon between its nodes, inside the
         * sphere: rays from outside toward its centroid (the cut's
         * visibility, through the representatives) would meet the sphere
         * itself and find every cell hidden.  The centroid goes out onto
         * the surface, the normal along the radius.  (The inner side is
         * seen from inside, where the cell's own centroid is right.) */
        vec3 centre = f3_to_v3(sp->p0), d = v3_sub(c, centre);
        double len = v3_length(d);
        if (len > 0) {
            n = v3_scale(d, 1.0 / len);
            c = v3_add(centre, v3_scale(d, sp->radius / len));
        }
    }
    el->prim = prim;
    el->index = e;
    el->side = (uint8_t)side;
    el->any_way = 0;
    for (int a = 0; a < 3; a++) {
        el->lo[a] = INFINITY;
        el->hi[a] = -INFINITY;
    }
    for (int k = 0; k < corners; k++) {
        double v[3] = {q[k].x, q[k].y, q[k].z};
        for (int a = 0; a < 3; a++) {
            el->lo[a] = fminf(el->lo[a], (float)v[a]);
            el->hi[a] = fmaxf(el->hi[a], (float)v[a]);
        }
    }
    el->background = sp->background;
    el->c[0] = (float)c.x, el->c[1] = (float)c.y, el->c[2] = (float)c.z;
    el->n[0] = (float)n.x, el->n[1] = (float)n.y, el->n[2] = (float)n.z;
    el->area = (float)area;
    element_albedo(rs, prim, q, corners, el->albedo);
    return 1;
}

/* The smallest cone holding cones (a, ta) and (b, tb) (angles in radians;
 * above pi/2 means "any direction"). */
static void cone_union(vec3 a, double ta, vec3 b, double tb, vec3 *axis, double *theta)
{
    if (tb > ta) {
        vec3 t = a;
        a = b;
        b = t;
        double u = ta;
        ta = tb;
        tb = u;
    }
    double d = acos(fmax(-1.0, fmin(1.0, v3_dot(a, b))));
    if (fmin(d + tb, PI) <= ta) {
        *axis = a;
        *theta = ta;
        return;
    }
    double to = 0.5 * (ta + d + tb);
    if (to >= PI) {
        *axis = a;
        *theta = PI;
        return;
    }
    /* Rotate a towards b by to - ta. */
    double r = to - ta;
    vec3 w = v3_sub(b, v3_scale(a, v3_dot(a, b)));
    double lw = v3_length(w);
    if (lw < 1e-12) {
        *axis = a;
        *theta = to;
        return;
    }
    w = v3_scale(w, 1.0 / lw);
    *axis = v3_normalize(v3_add(v3_scale(a, cos(r)), v3_scale(w, sin(r))));
    *theta = to;
}

static float box_radius(const sender_node *node)
{
    double dx = node->hi[0] - node->lo[0], dy = node->hi[1] - node->lo[1];
    double dz = node->hi[2] - node->lo[2];
    return (float)(0.5 * sqrt(dx * dx + dy * dy + dz * dz));
}

typedef struct builder {
    sender_tree *t;
} builder;

static int build_nodes(sender_tree *t);
static void fill_node(sender_tree *t, int32_t ni);

/* A fixed number in [0, 1) for node ni (splitmix64). */
static double rep_number(int32_t ni)
{
    uint64_t z = (uint64_t)ni * 0x9e3779b97f4a7c15ull + 0x632be59bd9b4e019ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* Sort keys: the centroid's axes 0-2, the normal's 3-5. */
static float elem_c(const sender_elem *e, int a) { return a < 3 ? e->c[a] : e->n[a - 3]; }

/* The cone of the normals of elements [first, first + n). */
static double elems_cone(const sender_elem *el, int n)
{
    vec3 ax = v3(0, 0, 1);
    double th = -1;
    for (int i = 0; i < n; i++) {
        vec3 en = v3(el[i].n[0], el[i].n[1], el[i].n[2]);
        double et = el[i].any_way ? PI : 0;
        if (th < 0) {
            ax = en;
            th = et;
        } else {
            cone_union(ax, th, en, et, &ax, &th);
        }
    }
    return th;
}

/* Axes 0-2 are the centre's, 3-5 the normal's. */
DEFINE_SELECT_NTH(select_nth, sender_elem, elem_c)

/* Fills node ni with elements [first, first + n). */
static void build(builder *b, int32_t ni, int first, int n, int depth)
{
    sender_tree *t = b->t;
    sender_node *node = &t->nodes[ni];
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = first; i < first + n; i++)
        for (int a = 0; a < 3; a++) {
            clo[a] = fminf(clo[a], t->elems[i].c[a]);
            chi[a] = fmaxf(chi[a], t->elems[i].c[a]);
        }
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[axis] - clo[axis])
            axis = a;
    /* Elements facing apart (the two sides of a surface, a closed mesh)
     * cannot be estimated together from afar: where the normals spread
     * widely, splitting them by direction may give children with narrow
     * cones, which the cut can take whole. */
    float nlo[3] = {INFINITY, INFINITY, INFINITY}, nhi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = first; i < first + n; i++)
        for (int a = 0; a < 3; a++) {
            nlo[a] = fminf(nlo[a], t->elems[i].n[a]);
            nhi[a] = fmaxf(nhi[a], t->elems[i].n[a]);
        }
    int naxis = 0;
    for (int a = 1; a < 3; a++)
        if (nhi[a] - nlo[a] > nhi[naxis] - nlo[naxis])
            naxis = a;
    int by_normal = 0;
    if (n > LEAF_SIZE && depth <= 60 && nhi[naxis] - nlo[naxis] > 1.0f) {
        int h = n / 2;
        sender_elem *el = t->elems + first;
        select_nth(el, n, h, 3 + naxis);
        double nl = elems_cone(el, h), nr = elems_cone(el + h, n - h);
        double sl = PI, sr = PI;
        if (chi[axis] > clo[axis]) {
            select_nth(el, n, h, axis);
            sl = elems_cone(el, h);
            sr = elems_cone(el + h, n - h);
        }
        if (fmax(nl, nr) < 0.7 * fmax(sl, sr)) {
            by_normal = 1;
            select_nth(el, n, h, 3 + naxis);
        }
    }
    if (!by_normal && (n <= LEAF_SIZE || depth > 60 || !(chi[axis] > clo[axis]))) {
        node->left = -1 - first;
        node->count = n;
        for (int a = 0; a < 3; a++) {
            node->lo[a] = INFINITY;
            node->hi[a] = -INFINITY;
        }
        vec3 ax = v3(0, 0, 1);
        double th = -1;
        node->background = 1;
        node->any_way = 0;
        for (int i = first; i < first + n; i++) {
            const sender_elem *e = &t->elems[i];
            node->background &= e->background;
            node->any_way |= e->any_way;
            for (int a = 0; a < 3; a++) {
                node->lo[a] = fminf(node->lo[a], e->lo[a]);
                node->hi[a] = fmaxf(node->hi[a], e->hi[a]);
            }
            vec3 en = v3(e->n[0], e->n[1], e->n[2]);
            double et = e->any_way ? PI : 0;
            if (th < 0) {
                ax = en;
                th = et;
            } else {
                cone_union(ax, th, en, et, &ax, &th);
            }
        }
        node->axis[0] = (float)ax.x, node->axis[1] = (float)ax.y, node->axis[2] = (float)ax.z;
        node->cone = (float)th;
        node->cos_cone = (float)cos(th);
        node->sin_cone = (float)sin(th);
        node->radius = box_radius(node);
        return;
    }
    int half = n / 2;
    if (!by_normal)
        select_nth(t->elems + first, n, half, axis);
    int32_t l = t->node_count;
    t->node_count += 2;
    node->left = l;
    node->count = 0;
    build(b, l, first, half, depth + 1);
    build(b, l + 1, first + half, n - half, depth + 1);
    node = &t->nodes[ni];
    const sender_node *L = &t->nodes[l], *R = &t->nodes[l + 1];
    node->background = L->background & R->background;
    node->any_way = L->any_way | R->any_way;
    for (int a = 0; a < 3; a++) {
        node->lo[a] = fminf(L->lo[a], R->lo[a]);
        node->hi[a] = fmaxf(L->hi[a], R->hi[a]);
    }
    vec3 ax;
    double th;
    cone_union(v3(L->axis[0], L->axis[1], L->axis[2]), L->cone,
               v3(R->axis[0], R->axis[1], R->axis[2]), R->cone, &ax, &th);
    node->axis[0] = (float)ax.x, node->axis[1] = (float)ax.y, node->axis[2] = (float)ax.z;
    node->cone = (float)th;
    node->cos_cone = (float)cos(th);
    node->sin_cone = (float)sin(th);
    node->radius = box_radius(node);
}

int sender_tree_build(sender_tree *t, const surface_nodes *sn, const rscene *rs)
{
    memset(t, 0, sizeof *t);
    long long count = 0;
    for (int prim = 0; prim < sn->prim_count; prim++)
        count += (long long)surface_element_count(sn, prim) * sn->prim[prim].sides;
    if (count > INT32_MAX / 2)
        return 0;
    t->elems = malloc(((size_t)count + 1) * sizeof *t->elems);
    if (!t->elems)
        return 0;
    int k = 0;
    for (int prim = 0; prim < sn->prim_count; prim++) {
        int ne = surface_element_count(sn, prim);
        for (int side = 0; side < sn->prim[prim].sides; side++)
            for (int e = 0; e < ne; e++)
                k += make_elem(&t->elems[k], sn, rs, prim, side, e);
    }
    t->elem_count = k;
    return build_nodes(t);
}

/* The nodes over t->elems (elem_count of them). */
static int build_nodes(sender_tree *t)
{
    int k = t->elem_count;
    for (int i = 0; i < k; i++)
        t->total_area += t->elems[i].area;
    t->nodes = aligned_alloc(_Alignof(sender_node), (2 * (size_t)k + 1) * sizeof *t->nodes);
    t->light = aligned_alloc(_Alignof(sender_light), (2 * (size_t)k + 1) * sizeof *t->light);
    if (t->light)
        memset(t->light, 0, (2 * (size_t)k + 1) * sizeof *t->light);
    t->elem_radiance = calloc(3 * (size_t)k + 3, sizeof(float));
    if (!t->nodes || !t->light || !t->elem_radiance)
        return 0;
    if (k > 0) {
        builder b = {t};
        t->node_count = 1;
        build(&b, 0, 0, k, 0);
    }
    return 1;
}

/* One side of a light triangle as an element. */
static void light_side(sender_elem *el, const rs_part *p, int prim, int side)
{
    vec3f v[3] = {p->p0, f3_add(p->p0, p->e1), f3_add(p->p0, p->e2)};
    vec3f n = side ? f3_neg(p->n) : p->n;
    el->prim = prim;
    el->index = -1;
    el->side = (uint8_t)side;
    el->background = p->background;
    el->any_way = 0;
    vec3f c = f3_scale(f3_add(f3_add(v[0], v[1]), v[2]), 1.0f / 3.0f);
    el->c[0] = c.x, el->c[1] = c.y, el->c[2] = c.z;
    el->n[0] = n.x, el->n[1] = n.y, el->n[2] = n.z;
    for (int a = 0; a < 3; a++) {
        float x0 = a == 0 ? v[0].x : a == 1 ? v[0].y : v[0].z;
        el->lo[a] = el->hi[a] = x0;
        for (int k = 1; k < 3; k++) {
            float x = a == 0 ? v[k].x : a == 1 ? v[k].y : v[k].z;
            el->lo[a] = fminf(el->lo[a], x);
            el->hi[a] = fmaxf(el->hi[a], x);
        }
    }
    el->area = p->area;
    el->albedo[0] = el->albedo[1] = el->albedo[2] = 1.0f;
}

int sender_tree_build_lights(sender_tree *t, const rscene *rs)
{
    memset(t, 0, sizeof *t);
    t->elems = malloc(2 * ((size_t)rs->light_count + 1) * sizeof *t->elems);
    if (!t->elems)
        return 0;
    int k = 0;
    for (int j = 0; j < rs->light_count; j++) {
        int prim = rs->lights[j].part;
        rs_part tmp;
        const rs_part *p = rs_prim(rs, prim, &tmp);
        if (p->shape == SHAPE_TRIANGLE) {
            light_side(&t->elems[k++], p, prim, 0);
            if (!p->culled)
                light_side(&t->elems[k++], p, prim, 1);
            continue;
        }
        /* A sphere or a point: every way, from its centre. */
        sender_elem *el = &t->elems[k++];
        memset(el, 0, sizeof *el);
        el->prim = prim;
        el->index = -1;
        el->background = p->background;
        el->any_way = 1;
        el->c[0] = p->p0.x, el->c[1] = p->p0.y, el->c[2] = p->p0.z;
        el->n[2] = 1.0f;
        float r = p->shape == SHAPE_SPHERE ? p->radius : 0.0f;
        for (int a = 0; a < 3; a++) {
            el->lo[a] = el->c[a] - r;
            el->hi[a] = el->c[a] + r;
        }
        /* Flux per unit radiance: a sphere's pi r^2 seen from anywhere is
         * its area / 4 x pi...; the estimate is never taken from afar for
         * these (any_way), the area only weighs the choice. */
        el->area = p->shape == SHAPE_SPHERE ? p->area : 4.0f;
        el->albedo[0] = el->albedo[1] = el->albedo[2] = 1.0f;
    }
    t->elem_count = k;
    if (!build_nodes(t))
        return 0;
    /* The lights' radiance: their emission, switched off or not. */
    for (int i = 0; i < k; i++) {
        rs_part tmp;
        const rs_part *p = rs_prim(rs, t->elems[i].prim, &tmp);
        vec3f em = rs_emission_mean(rs, t->elems[i].prim, &rs->objects[p->object]);
        t->elem_radiance[3 * i] = em.x;
        t->elem_radiance[3 * i + 1] = em.y;
        t->elem_radiance[3 * i + 2] = em.z;
    }
    t->total_power = 0;
    if (t->node_count > 0) {
        fill_node(t, 0);
        t->total_power = t->light[0].power;
    }
    return 1;
}

void sender_tree_free(sender_tree *t)
{
    free(t->elems);
    free(t->nodes);
    free(t->light);
    free(t->elem_radiance);
    memset(t, 0, sizeof *t);
}

/* Sums a node's light from its elements or children (children first). */
static void fill_node(sender_tree *t, int32_t ni)
{
    sender_node *node = &t->nodes[ni];
    sender_light *l = &t->light[ni];
    double v[3][3] = {{0}}, af[3][3] = {{0}}, c[3] = {0, 0, 0}, p = 0;
    if (node->count > 0) {
        int first = -1 - node->left;
        for (int i = first; i < first + node->count; i++) {
            const sender_elem *e = &t->elems[i];
            const float *b = &t->elem_radiance[3 * (size_t)i];
            for (int ch = 0; ch < 3; ch++) {
                double f = (double)b[ch] * e->area;
                for (int a = 0; a < 3; a++) {
                    v[ch][a] += f * e->n[a];
                    af[ch][a] += f * fabs(e->n[a]);
                }
            }
            double w = sender_elem_power(t, i);
            p += w;
            for (int a = 0; a < 3; a++)
                c[a] += w * e->c[a];
        }
    } else {
        fill_node(t, node->left);
        fill_node(t, node->left + 1);
        for (int k = 0; k < 2; k++) {
            const sender_light *cl = &t->light[node->left + k];
            for (int ch = 0; ch < 3; ch++)
                for (int a = 0; a < 3; a++) {
                    v[ch][a] += cl->vflux[ch][a];
                    af[ch][a] += cl->aflux[ch][a];
                }
            p += cl->power;
            for (int a = 0; a < 3; a++)
                c[a] += (double)cl->power * cl->c[a];
        }
    }
    for (int ch = 0; ch < 3; ch++)
        for (int a = 0; a < 3; a++) {
            l->vflux[ch][a] = (float)v[ch][a];
            l->aflux[ch][a] = (float)af[ch][a];
        }
    l->power = (float)p;
    for (int a = 0; a < 3; a++)
        l->c[a] = p > 0 ? (float)(c[a] / p) : 0.5f * (node->lo[a] + node->hi[a]);
    /* The representative is drawn in proportion to power, by a fixed
     * number per node: the brightest element of a cluster is also its
     * most exposed one, so always taking it overstates the cluster's
     * visibility where its elements shade each other. */
    double u = rep_number(ni);
    if (node->count > 0) {
        int first = -1 - node->left, best = -1, last = first;
        double total = 0;
        for (int i = first; i < first + node->count; i++)
            total += sender_elem_power(t, i);
        double acc = 0, aim = u * total;
        for (int i = first; i < first + node->count && best < 0; i++) {
            double w = sender_elem_power(t, i);
            acc += w;
            if (w > 0) {
                last = i;
                if (acc > aim)
                    best = i;
            }
        }
        if (best < 0)
            best = last; /* rounding, or no element with light */
        for (int a = 0; a < 3; a++) {
            l->rep[a] = t->elems[best].c[a];
            l->rep_n[a] = t->elems[best].n[a];
        }
    } else {
        const sender_light *L = &t->light[node->left], *R = &t->light[node->left + 1];
        const sender_light *pick = u * ((double)L->power + R->power) < L->power ? L : R;
        for (int a = 0; a < 3; a++) {
            l->rep[a] = pick->rep[a];
            l->rep_n[a] = pick->rep_n[a];
        }
    }
}

void sender_tree_fill(sender_tree *t, const surface_nodes *sn, const rscene *rs, const float *e)
{
#pragma omp parallel for schedule(static)
    for (int i = 0; i < t->elem_count; i++) {
        const sender_elem *el = &t->elems[i];
        vec3 q[4];
        int32_t node[4];
        int corners = surface_element(sn, rs, el->prim, el->side, el->index, q, node);
        double sum[3] = {0, 0, 0};
        int live = 0;
        for (int k = 0; k < corners; k++) {
            if (node[k] < 0 || !sn->live[node[k]])
                continue;
            for (int ch = 0; ch < 3; ch++)
                sum[ch] += e[3 * (size_t)node[k] + ch];
            live++;
        }
        float *b = &t->elem_radiance[3 * (size_t)i];
        for (int ch = 0; ch < 3; ch++)
            b[ch] = live ? (float)(sum[ch] / live) * el->albedo[ch] : 0.0f;
    }
    /* Sums in tree order, on one thread: the same at any thread count. */
    t->total_power = 0;
    if (t->node_count > 0) {
        fill_node(t, 0);
        t->total_power = t->light[0].power;
    }
}
