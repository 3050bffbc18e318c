/* Phase One, the bookkeeping: a tree of zones per light part, a child for
 * every surface a zone can reach and every lobe of that surface's material,
 * down to the requested depth, pruned by --cutoff on a bound of the power
 * a zone carries; each zone records the parts that can shadow it. */
#include <stdlib.h>
#include <string.h>

#include "util/error.h"
#include "zone/zone_internal.h"

#define MAX_ZONES (1 << 22)

typedef struct box { vec3 lo, hi; int infinite; } box;

static box part_box(const part *p)
{
    box b;
    b.infinite = 0;
    switch (p->shape) {
    case SHAPE_TRIANGLE:
        b.lo = b.hi = p->p[0];
        for (int i = 1; i < 3; i++) {
            b.lo = v3(fmin(b.lo.x, p->p[i].x), fmin(b.lo.y, p->p[i].y), fmin(b.lo.z, p->p[i].z));
            b.hi = v3(fmax(b.hi.x, p->p[i].x), fmax(b.hi.y, p->p[i].y), fmax(b.hi.z, p->p[i].z));
        }
        break;
    case SHAPE_SPHERE:
        b.lo = v3_sub(p->p[0], v3(p->radius, p->radius, p->radius));
        b.hi = v3_add(p->p[0], v3(p->radius, p->radius, p->radius));
        break;
    case SHAPE_POINT:
        b.lo = b.hi = p->p[0];
        break;
    default:
        b.lo = v3(-1e300, -1e300, -1e300);
        b.hi = v3(1e300, 1e300, 1e300);
        b.infinite = 1;
    }
    return b;
}

/* Whether some point of part q lies strictly on the side of plane (n, o)
 * that n points to (conservative for spheres and planes). */
static int part_in_front(const part *q, vec3 n, double o)
{
    switch (q->shape) {
    case SHAPE_TRIANGLE:
        for (int i = 0; i < 3; i++)
            if (v3_dot(n, q->p[i]) > o + 1e-9 * (1 + fabs(o)))
                return 1;
        return 0;
    case SHAPE_SPHERE:
        return v3_dot(n, q->p[0]) + q->radius > o;
    case SHAPE_POINT:
        return v3_dot(n, q->p[0]) > o;
    default: {
        /* An infinite plane is in front unless parallel and behind. */
        double c = v3_dot(v3_normalize(n), q->normal);
        if (fabs(fabs(c) - 1.0) > 1e-12)
            return 1;
        return c * q->offset > o / v3_length(n) + 1e-12;
    }
    }
}

/* The plane of a flat part, with its front normal. */
static int part_plane(const part *p, vec3 *n, double *o)
{
    if (p->shape == SHAPE_TRIANGLE) {
        *n = v3_normalize(v3_cross(v3_sub(p->p[1], p->p[0]), v3_sub(p->p[2], p->p[0])));
        *o = v3_dot(*n, p->p[0]);
        return 1;
    }
    if (p->shape == SHAPE_PLANE) {
        *n = p->normal;
        *o = p->offset;
        return 1;
    }
    return 0;
}

/* Whether light leaving part s (from its lit side(s)) can reach part q:
 * q must have a point in front of s, and s a point in front of q when q
 * is culled.  Conservative: a "yes" may carry no light. */
static int can_reach(const zt_scene *sc, int s, int q, int kind)
{
    const part *ps = &sc->parts[s], *pq = &sc->parts[q];
    const object *os = &sc->objects[ps->object], *oq = &sc->objects[pq->object];
    if (s == q) /* only light inside a sphere reaches the sphere again */
        return kind == ZONE_REFRACT && ps->shape == SHAPE_SPHERE;
    vec3 n;
    double o;
    if (part_plane(ps, &n, &o) && kind != ZONE_REFRACT) {
        int front = part_in_front(pq, n, o);
        int back = part_in_front(pq, v3_scale(n, -1), -o);
        if (os->backculled ? !front : !(front || back))
            return 0;
    }
    if (oq->backculled && part_plane(pq, &n, &o) && !part_in_front(ps, n, o))
        return 0;
    return 1;
}

static int box_overlap(box a, box b)
{
    if (a.infinite || b.infinite)
        return 1;
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
           a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}

static box box_union(box a, box b)
{
    box r;
    r.infinite = a.infinite || b.infinite;
    r.lo = v3(fmin(a.lo.x, b.lo.x), fmin(a.lo.y, b.lo.y), fmin(a.lo.z, b.lo.z));
    r.hi = v3(fmax(a.hi.x, b.hi.x), fmax(a.hi.y, b.hi.y), fmax(a.hi.z, b.hi.z));
    return r;
}

static int push_zone(zone_forest *f, const zone *z)
{
    if (f->zone_count == f->zone_capacity) {
        int cap = f->zone_capacity ? 2 * f->zone_capacity : 256;
        zone *nz = realloc(f->zones, (size_t)cap * sizeof *nz);
        if (!nz)
            return -1;
        f->zones = nz;
        f->zone_capacity = cap;
    }
    f->zones[f->zone_count] = *z;
    return f->zone_count++;
}

static int push_occluder(zone_forest *f, int part)
{
    if (f->occluder_count == f->occluder_capacity) {
        int cap = f->occluder_capacity ? 2 * f->occluder_capacity : 1024;
        int *no = realloc(f->occluders, (size_t)cap * sizeof *no);
        if (!no)
            return 0;
        f->occluders = no;
        f->occluder_capacity = cap;
    }
    f->occluders[f->occluder_count++] = part;
    return 1;
}

static double light_power(const zt_scene *sc, const part *p)
{
    const object *o = &sc->objects[p->object];
    double lum = 0.2126 * o->emission.x + 0.7152 * o->emission.y + 0.0722 * o->emission.z;
    switch (p->shape) {
    case SHAPE_TRIANGLE:
        return lum * 3.14159265358979 * 0.5 *
               v3_length(v3_cross(v3_sub(p->p[1], p->p[0]), v3_sub(p->p[2], p->p[0])));
    case SHAPE_SPHERE: return lum * 3.14159265358979 * 4 * 3.14159265358979 * p->radius * p->radius;
    case SHAPE_POINT: return lum * 4 * 3.14159265358979;
    default: return 1e30; /* unbounded */
    }
}

zt_status forest_build_tree(zone_forest *f, const zt_renderer *r, zt_error *err)
{
    const zt_scene *sc = r->scene;
    const rscene *rs = &r->rs;
    int depth = r->options.level >= 0 ? r->options.level : r->options.depth;
    double cutoff = r->options.cutoff;
    static const int lobe_kind[LOBE_COUNT] = {ZONE_DIFFUSE, ZONE_METALLIC, ZONE_MIRROR, ZONE_REFRACT};

    for (int i = 0; i < sc->part_count; i++) {
        const part *p = &sc->parts[i];
        if (!sc->objects[p->object].is_light || f3_is_black(rs->objects[p->object].emission))
            continue;
        zone z = {-1, i, i, ZONE_EMIT, 0, (float)light_power(sc, p), 0, 0, 0, 0};
        if (push_zone(f, &z) < 0)
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zones");
    }
    /* Breadth first: zones of one level are contiguous. */
    int level_start = 0, level_end = f->zone_count;
    for (int level = 1; level <= depth; level++) {
        for (int zi = level_start; zi < level_end; zi++) {
            f->zones[zi].first_child = f->zone_count;
            zone parent = f->zones[zi];
            box src = part_box(&sc->parts[parent.source]);
            for (int q = 0; q < sc->part_count; q++) {
                const part *pq = &sc->parts[q];
                const object *oq = &sc->objects[pq->object];
                if (oq->is_light || !can_reach(sc, parent.source, q, parent.kind))
                    continue;
                box reach = box_union(src, part_box(pq));
                for (int k = 0; k < LOBE_COUNT; k++) {
                    double w = oq->mat.weight[k];
                    if (w <= 0)
                        continue;
                    double power = parent.power * w * v3_max(oq->mat.color);
                    if (power <= cutoff || f->zone_count >= MAX_ZONES) {
                        f->pruned++;
                        continue;
                    }
                    zone z = {zi, q, parent.root_light, (uint8_t)lobe_kind[k], (uint8_t)level,
                              (float)power, 0, 0, f->occluder_count, 0};
                    /* Occluders: parts that meet the box of source and receiver. */
                    for (int o = 0; o < sc->part_count; o++) {
                        if (o == q || o == parent.source || sc->parts[o].shape == SHAPE_POINT)
                            continue;
                        if (box_overlap(reach, part_box(&sc->parts[o]))) {
                            if (!push_occluder(f, o))
                                return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zones");
                            z.occluder_count++;
                        }
                    }
                    if (push_zone(f, &z) < 0)
                        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for zones");
                    f->zones[zi].child_count++;
                }
            }
        }
        level_start = level_end;
        level_end = f->zone_count;
        if (level_start == level_end)
            break;
    }
    return ZT_OK;
}
