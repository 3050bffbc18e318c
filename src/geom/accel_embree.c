/* The Embree 3 backend.  Each layer (foreground, background) is one Embree
 * scene with up to two geometries for the parts, the triangles and the
 * spheres, and one per mesh, which reads the mesh's own arrays (shared
 * buffers: nothing is copied).  Embree has no per-primitive back-face
 * culling, so culled triangles are rejected in a filter function, attached
 * only to geometries that have any.  Spheres are user geometry hit by the
 * project's own test (geom/shapes.h), which solves in double: Embree's
 * float sphere misses walls of radius 10^5 by a hundredth of a unit. */
#include "geom/accel_internal.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "geom/shapes.h"
#include "scene/mesh.h"
#include "util/error.h"

enum { GEOM_TRIANGLES, GEOM_SPHERES, GEOM_KINDS };

typedef struct geom_map {
    int *part_of_prim;   /* primitive index -> part index; NULL for a mesh */
    int prim_base;       /* a mesh: its first primitive number */
    const rscene *rs;
    int kind;            /* GEOM_TRIANGLES for meshes */
} geom_map;

typedef struct embree_accel {
    accel base;
    RTCDevice device;
    RTCScene scene[2];
    int empty[2];
    /* By layer and geometry id: the parts' kinds, then mesh k at
     * GEOM_KINDS + k (in the layer the mesh is in). */
    geom_map *map[2];
} embree_accel;

/* A query's context: Embree's (first, as Embree's callbacks are handed
 * it), and whether culled primitives show their backs too (node life's
 * probes: accel_nearest_all_sides). */
typedef struct query_context {
    struct RTCIntersectContext ctx;
    int all_sides;
} query_context;

static void query_context_init(query_context *q, int all_sides)
{
    rtcInitIntersectContext(&q->ctx);
    q->all_sides = all_sides;
}

static inline int all_sides(const struct RTCIntersectContext *ctx)
{
    return ((const query_context *)ctx)->all_sides;
}

static inline int prim_of(const geom_map *m, unsigned prim)
{
    return m->part_of_prim ? m->part_of_prim[prim] : m->prim_base + (int)prim;
}

/* Rejects hits on the back of culled primitives. */
static void cull_filter(const struct RTCFilterFunctionNArguments *args)
{
    if (all_sides(args->context))
        return;
    const geom_map *m = args->geometryUserPtr;
    unsigned n = args->N;
    const float *ray = (const float *)args->ray;
    const float *hitv = (const float *)args->hit;
    for (unsigned i = 0; i < n; i++) {
        if (args->valid[i] != -1)
            continue;
        unsigned prim = ((const unsigned *)hitv)[5 * n + i];
        vec3f d = f3(ray[4 * n + i], ray[5 * n + i], ray[6 * n + i]);
        vec3f facing;
        if (!m->part_of_prim) {
            /* A culled mesh: Embree's own geometric normal, Ng = e1 x e2 for
             * its vertex order (the front is counter-clockwise). */
            facing = f3(hitv[0 * n + i], hitv[1 * n + i], hitv[2 * n + i]);
            if (f3_dot(facing, d) >= 0.0f)
                args->valid[i] = 0;
            continue;
        }
        /* The parts' triangles (spheres cull in their own test). */
        const rs_part *p = &m->rs->parts[m->part_of_prim[prim]];
        if (!p->culled)
            continue;
        facing = p->n;
        if (f3_dot(facing, d) >= 0.0f)
            args->valid[i] = 0;
    }
}

/* Spheres as user geometry: bounds, nearest and any hit. */
static const rs_part *sphere_part(const void *user, unsigned prim)
{
    const geom_map *m = user;
    return &m->rs->parts[m->part_of_prim[prim]];
}

static void sphere_bounds(const struct RTCBoundsFunctionArguments *args)
{
    const rs_part *p = sphere_part(args->geometryUserPtr, args->primID);
    /* Widened by a float's rounding of the far coordinates. */
    float r = p->radius * (1.0f + 1e-6f);
    struct RTCBounds *b = args->bounds_o;
    b->lower_x = p->p0.x - r; b->lower_y = p->p0.y - r; b->lower_z = p->p0.z - r;
    b->upper_x = p->p0.x + r; b->upper_y = p->p0.y + r; b->upper_z = p->p0.z + r;
}

/* Spheres' callbacks take a packet of N rays (N is 1 for single rays);
 * RTCRayN's fields lie one after another, N floats each. */
#define RAY_N(ray, n, field, i) (((float *)(ray))[(field) * (n) + (i)])
enum { RN_OX, RN_OY, RN_OZ, RN_TNEAR, RN_DX, RN_DY, RN_DZ, RN_TIME, RN_TFAR };

static void sphere_intersect(const struct RTCIntersectFunctionNArguments *args)
{
    const rs_part *p = sphere_part(args->geometryUserPtr, args->primID);
    rs_part open;
    if (p->culled && all_sides(args->context)) {
        open = *p;
        open.culled = 0;
        p = &open;
    }
    unsigned n = args->N;
    float *ray = (float *)args->rayhit;
    /* RTCRayHitN: the ray's 12 fields, then the hit's Ng (3), u, v,
     * primID, geomID, instID. */
    unsigned *hitv = (unsigned *)(ray + 12 * n);
    for (unsigned i = 0; i < n; i++) {
        if (args->valid[i] != -1)
            continue;
        vec3f o = f3(RAY_N(ray, n, RN_OX, i), RAY_N(ray, n, RN_OY, i), RAY_N(ray, n, RN_OZ, i));
        vec3f d = f3(RAY_N(ray, n, RN_DX, i), RAY_N(ray, n, RN_DY, i), RAY_N(ray, n, RN_DZ, i));
        float t = shape_sphere_hit(p, o, d, 0.0f, RAY_N(ray, n, RN_TFAR, i));
        if (t < 0.0f)
            continue;
        RAY_N(ray, n, RN_TFAR, i) = t;
        hitv[5 * n + i] = args->primID;
        hitv[6 * n + i] = args->geomID;
        hitv[7 * n + i] = args->context->instID[0];
    }
}

static void sphere_occluded(const struct RTCOccludedFunctionNArguments *args)
{
    const rs_part *p = sphere_part(args->geometryUserPtr, args->primID);
    rs_part open;
    if (p->culled && all_sides(args->context)) {
        open = *p;
        open.culled = 0;
        p = &open;
    }
    unsigned n = args->N;
    float *ray = (float *)args->ray;
    for (unsigned i = 0; i < n; i++) {
        if (args->valid[i] != -1)
            continue;
        vec3f o = f3(RAY_N(ray, n, RN_OX, i), RAY_N(ray, n, RN_OY, i), RAY_N(ray, n, RN_OZ, i));
        vec3f d = f3(RAY_N(ray, n, RN_DX, i), RAY_N(ray, n, RN_DY, i), RAY_N(ray, n, RN_DZ, i));
        /* tfar is inclusive here (the queries lowered it by one float). */
        float tmax = nextafterf(RAY_N(ray, n, RN_TFAR, i), INFINITY);
        if (shape_sphere_hit(p, o, d, 0.0f, tmax) >= 0.0f)
            RAY_N(ray, n, RN_TFAR, i) = -INFINITY;
    }
}

static void nearest_sides(const accel *a, int layer, vec3f o, vec3f d, hit *h, int sides)
{
    const embree_accel *e = (const embree_accel *)a;
    if (e->empty[layer])
        return;
    query_context q;
    query_context_init(&q, sides);
    struct RTCRayHit rh;
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = h->t;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(e->scene[layer], &q.ctx, &rh);
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
        h->t = rh.ray.tfar;
        h->part = prim_of(&e->map[layer][rh.hit.geomID], rh.hit.primID);
    }
}

static void embree_nearest(const accel *a, int layer, vec3f o, vec3f d, hit *h)
{
    nearest_sides(a, layer, o, d, h, 0);
}

static void embree_nearest_all_sides(const accel *a, int layer, vec3f o, vec3f d, hit *h)
{
    nearest_sides(a, layer, o, d, h, 1);
}

/* Embree includes tfar; the contract excludes it: one float below. */
static float below(float tmax)
{
    uint32_t bits;
    memcpy(&bits, &tmax, sizeof bits);
    if (tmax > 0.0f && bits < 0x7f800000u)
        bits--;
    memcpy(&tmax, &bits, sizeof bits);
    return tmax;
}

static int embree_any(const accel *a, int layer, vec3f o, vec3f d, float tmax)
{
    const embree_accel *e = (const embree_accel *)a;
    if (e->empty[layer])
        return 0;
    query_context q;
    query_context_init(&q, 0);
    struct RTCRay r;
    r.org_x = o.x; r.org_y = o.y; r.org_z = o.z;
    r.dir_x = d.x; r.dir_y = d.y; r.dir_z = d.z;
    r.tnear = 0.0f;
    r.tfar = below(tmax);
    r.time = 0.0f;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(e->scene[layer], &q.ctx, &r);
    return r.tfar < 0.0f;
}

/* Lanes 0 .. w-1 of a packet laid out as RTCRay4/8/16 are (the ray's
 * fields, each w floats): lane j the ray from o[j * o_step] along d[j] up
 * to tfar[j], valid where on[j] (lanes m and past are not).  Returns
 * whether any lane is valid. */
/* A packet's storage: a ray and hit of 16 lanes (Embree's RTCRayHit16,
 * one instance level), read as floats or as integers. */
_Static_assert(RTC_MAX_INSTANCE_LEVEL_COUNT == 1, "a packet holds one instance id a lane");
typedef union packet {
    float f[20 * 16];
    unsigned u[20 * 16];
} packet;

static int packet_fill(packet *p, int *valid, int w, int m, const vec3f *o, int o_step,
                       const vec3f *d, const float *tfar, const unsigned char *on)
{
    float *ray = p->f;
    unsigned *bits = p->u;
    int any = 0;
    for (int j = 0; j < w; j++) {
        valid[j] = j < m && on[j] ? -1 : 0;
        any |= valid[j];
        vec3f oj = o[j < m ? j * o_step : 0], dj = j < m ? d[j] : f3(0.0f, 0.0f, 1.0f);
        RAY_N(ray, w, RN_OX, j) = oj.x;
        RAY_N(ray, w, RN_OY, j) = oj.y;
        RAY_N(ray, w, RN_OZ, j) = oj.z;
        RAY_N(ray, w, RN_TNEAR, j) = 0.0f;
        RAY_N(ray, w, RN_DX, j) = dj.x;
        RAY_N(ray, w, RN_DY, j) = dj.y;
        RAY_N(ray, w, RN_DZ, j) = dj.z;
        RAY_N(ray, w, RN_TIME, j) = 0.0f;
        RAY_N(ray, w, RN_TFAR, j) = j < m ? tfar[j] : 0.0f;
        bits[9 * w + j] = 0xffffffffu; /* mask */
        bits[10 * w + j] = (unsigned)j; /* id */
        bits[11 * w + j] = 0;          /* flags */
    }
    return any;
}

/* Packets of the machine's native width (a->packet: 4, 8 or 16); lanes
 * already hidden are left out. */
static void embree_any_n(const accel *a, int layer, vec3f o, const vec3f *d, const float *tmax,
                         int n, unsigned char *hidden)
{
    const embree_accel *e = (const embree_accel *)a;
    if (e->empty[layer])
        return;
    query_context q;
    query_context_init(&q, 0);
    int w = a->packet;
    _Alignas(64) packet ray;
    for (int base = 0; base < n; base += w) {
        _Alignas(64) int valid[16];
        int m = n - base < w ? n - base : w;
        float far[16];
        unsigned char on[16];
        for (int j = 0; j < m; j++) {
            on[j] = !hidden[base + j];
            far[j] = below(tmax[base + j]);
        }
        if (!packet_fill(&ray, valid, w, m, &o, 0, d + base, far, on))
            continue;
        if (w == 16)
            rtcOccluded16(valid, e->scene[layer], &q.ctx, (struct RTCRay16 *)&ray);
        else if (w == 8)
            rtcOccluded8(valid, e->scene[layer], &q.ctx, (struct RTCRay8 *)&ray);
        else
            rtcOccluded4(valid, e->scene[layer], &q.ctx, (struct RTCRay4 *)&ray);
        for (int j = 0; j < m; j++)
            if (valid[j] && RAY_N(ray.f, w, RN_TFAR, j) < 0.0f)
                hidden[base + j] = 1;
    }
}

/* Nearest hits in packets, as embree_any_n: RTCRayHitN is the ray's 12
 * fields, then the hit's Ng (3), u, v, primID, geomID, instID. */
static void embree_nearest_n(const accel *a, int layer, const vec3f *o, int o_step,
                             const vec3f *d, int n, const unsigned char *want, hit *h)
{
    const embree_accel *e = (const embree_accel *)a;
    if (e->empty[layer])
        return;
    query_context q;
    query_context_init(&q, 0);
    int w = a->packet;
    _Alignas(64) packet rh;
    unsigned *bits = rh.u;
    for (int base = 0; base < n; base += w) {
        _Alignas(64) int valid[16];
        int m = n - base < w ? n - base : w;
        float far[16];
        for (int j = 0; j < m; j++)
            far[j] = h[base + j].t;
        int any = packet_fill(&rh, valid, w, m, o + base * o_step, o_step, d + base, far,
                              want + base);
        for (int j = 0; j < w; j++) {
            bits[18 * w + j] = RTC_INVALID_GEOMETRY_ID; /* geomID */
            bits[19 * w + j] = RTC_INVALID_GEOMETRY_ID; /* instID */
        }
        if (!any)
            continue;
        if (w == 16)
            rtcIntersect16(valid, e->scene[layer], &q.ctx, (struct RTCRayHit16 *)&rh);
        else if (w == 8)
            rtcIntersect8(valid, e->scene[layer], &q.ctx, (struct RTCRayHit8 *)&rh);
        else
            rtcIntersect4(valid, e->scene[layer], &q.ctx, (struct RTCRayHit4 *)&rh);
        for (int j = 0; j < m; j++) {
            unsigned geom = bits[18 * w + j];
            if (!valid[j] || geom == RTC_INVALID_GEOMETRY_ID)
                continue;
            h[base + j].t = RAY_N(rh.f, w, RN_TFAR, j);
            h[base + j].part = prim_of(&e->map[layer][geom], bits[17 * w + j]);
        }
    }
}

static void embree_destroy(accel *a)
{
    embree_accel *e = (embree_accel *)a;
    for (int l = 0; l < 2; l++) {
        if (e->scene[l])
            rtcReleaseScene(e->scene[l]);
        if (e->map[l])
            for (int k = 0; k < GEOM_KINDS; k++)
                free(e->map[l][k].part_of_prim);
        free(e->map[l]);
    }
    if (e->device)
        rtcReleaseDevice(e->device);
    free(e);
}

/* Adds the layer's primitives of one shape as one geometry. */
static int add_geometry(embree_accel *e, const rscene *rs, int layer, int kind)
{
    int shape = kind == GEOM_TRIANGLES ? SHAPE_TRIANGLE : SHAPE_SPHERE;
    int count = 0, any_culled = 0;
    for (int i = 0; i < rs->part_count; i++)
        if (rs->parts[i].shape == shape && rs->parts[i].background == layer) {
            count++;
            any_culled |= rs->parts[i].culled;
        }
    if (count == 0)
        return 1;
    int *map = malloc((size_t)count * sizeof(int));
    if (!map)
        return 0;
    RTCGeometry g = rtcNewGeometry(e->device, kind == GEOM_TRIANGLES
                                                  ? RTC_GEOMETRY_TYPE_TRIANGLE
                                                  : RTC_GEOMETRY_TYPE_USER);
    float *vb = NULL;
    unsigned *ib = NULL;
    if (kind == GEOM_TRIANGLES) {
        vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                     3 * sizeof(float), (size_t)count * 3);
        ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                     3 * sizeof(unsigned), (size_t)count);
    } else {
        rtcSetGeometryUserPrimitiveCount(g, (unsigned)count);
        rtcSetGeometryBoundsFunction(g, sphere_bounds, NULL);
        rtcSetGeometryIntersectFunction(g, sphere_intersect);
        rtcSetGeometryOccludedFunction(g, sphere_occluded);
    }
    if (kind == GEOM_TRIANGLES && (!vb || !ib)) {
        rtcReleaseGeometry(g);
        free(map);
        return 0;
    }
    int k = 0;
    for (int i = 0; i < rs->part_count; i++) {
        const rs_part *p = &rs->parts[i];
        if (p->shape != shape || p->background != layer)
            continue;
        map[k] = i;
        if (kind == GEOM_TRIANGLES) {
            vec3f v[3] = {p->p0, f3_add(p->p0, p->e1), f3_add(p->p0, p->e2)};
            for (int j = 0; j < 3; j++) {
                vb[(k * 3 + j) * 3 + 0] = v[j].x;
                vb[(k * 3 + j) * 3 + 1] = v[j].y;
                vb[(k * 3 + j) * 3 + 2] = v[j].z;
                ib[k * 3 + j] = (unsigned)(k * 3 + j);
            }
        }
        k++;
    }
    geom_map *gm = &e->map[layer][kind];
    gm->rs = rs;
    gm->kind = kind;
    /* The spheres' callbacks read the map (and cull themselves). */
    gm->part_of_prim = map;
    if (kind == GEOM_SPHERES)
        rtcSetGeometryUserData(g, gm);
    else if (any_culled) {
        rtcSetGeometryUserData(g, gm);
        rtcSetGeometryIntersectFilterFunction(g, cull_filter);
        rtcSetGeometryOccludedFilterFunction(g, cull_filter);
    }
    rtcCommitGeometry(g);
    /* The geometry id is the kind, so hits index map[layer] directly. */
    rtcAttachGeometryByID(e->scene[layer], g, (unsigned)kind);
    rtcReleaseGeometry(g);
    e->empty[layer] = 0;
    return 1;
}

/* Adds mesh k as geometry GEOM_KINDS + k of its layer, on its own arrays. */
static int add_mesh(embree_accel *e, const rscene *rs, int k)
{
    const rs_mesh *mm = &rs->meshes[k];
    int layer = mm->background;
    RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               mm->m->position, 0, 3 * sizeof(float),
                               (size_t)mm->m->vertex_count);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mm->m->index, 0,
                               3 * sizeof(unsigned), (size_t)mm->m->triangle_count);
    geom_map *gm = &e->map[layer][GEOM_KINDS + k];
    gm->rs = rs;
    gm->kind = GEOM_TRIANGLES;
    gm->prim_base = mm->prim_base;
    if (mm->culled) {
        rtcSetGeometryUserData(g, gm);
        rtcSetGeometryIntersectFilterFunction(g, cull_filter);
        rtcSetGeometryOccludedFilterFunction(g, cull_filter);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(e->scene[layer], g, (unsigned)(GEOM_KINDS + k));
    rtcReleaseGeometry(g);
    e->empty[layer] = 0;
    return rtcGetDeviceError(e->device) == RTC_ERROR_NONE;
}

zt_status accel_build_embree(rscene *rs, zt_error *err)
{
    embree_accel *e = calloc(1, sizeof *e);
    if (!e)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    e->base.nearest = embree_nearest;
    e->base.nearest_all_sides = embree_nearest_all_sides;
    e->base.any = embree_any;
    e->base.destroy = embree_destroy;
    e->device = rtcNewDevice(NULL);
    if (!e->device) {
        free(e);
        return zt_fail(err, ZT_ERR_UNSUPPORTED, "Embree could not start (%d)",
                       (int)rtcGetDeviceError(NULL));
    }
    for (int l = 0; l < 2; l++) {
        e->empty[l] = 1;
        e->map[l] = calloc((size_t)(GEOM_KINDS + rs->mesh_count), sizeof(geom_map));
        e->scene[l] = rtcNewScene(e->device);
        if (!e->map[l]) {
            embree_destroy(&e->base);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory building Embree scene");
        }
        rtcSetSceneBuildQuality(e->scene[l], RTC_BUILD_QUALITY_HIGH);
        for (int k = 0; k < GEOM_KINDS; k++)
            if (!add_geometry(e, rs, l, k)) {
                embree_destroy(&e->base);
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory building Embree scene");
            }
    }
    for (int k = 0; k < rs->mesh_count; k++)
        if (!add_mesh(e, rs, k)) {
            embree_destroy(&e->base);
            return zt_fail(err, ZT_ERR_MEMORY, "Embree could not take mesh %d", k);
        }
    for (int l = 0; l < 2; l++)
        rtcCommitScene(e->scene[l]);
    if (rtcGetDeviceError(e->device) != RTC_ERROR_NONE) {
        embree_destroy(&e->base);
        return zt_fail(err, ZT_ERR_UNSUPPORTED, "Embree failed to build the scene");
    }
    e->base.packet =
        rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)  ? 16
        : rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) ? 8
        : rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED) ? 4
                                                                                     : 0;
    if (e->base.packet) {
        e->base.any_n = embree_any_n;
        e->base.nearest_n = embree_nearest_n;
    }
    rs->accel = &e->base;
    return ZT_OK;
}
