/* Phase One: the irradiance at every node, level by level, then the zones.
 *
 *   E_0  the lights' direct light, exact (direct.c), plus the sky's,
 *        gathered over fixed directions;
 *   E_k  (k >= 1) the light of level k arriving: from diffuse surfaces by
 *        the transfer (transfer.h) of E_{k-1} through the sender tree; by
 *        way of mirrors, metal and glass by gathering, and from the lights
 *        straight through them by caustic photons (caustic.c) and images
 *        in spheres (glint.c).
 *
 * Pixel level L reads E_{L-1} (level 1 is exact per pixel), so depth D
 * needs E_0 .. E_{D-1}. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/prim.h"
#include "render/share.h"
#include "util/error.h"
#include "util/vec3_convert.h"
#include "zone/light/sky_gather.h"
#include "zone/maps/mesh_rounds.h"
#include "zone/maps/node_groups.h"
#include "zone/maps/node_twins.h"
#include "zone/phase_one/caustic.h"
#include "zone/phase_one/glint.h"
#include "zone/phase_one/node_life.h"
#include "zone/phase_one/specular_gather.h"
#include "zone/transfer/bounce_gather.h"
#include "zone/transfer/sender_tree.h"
#include "zone/transfer/transfer.h"
#include "zone/zone.h"

/* Mesh vertex nodes share a cut (node_groups.h) within GROUP_RADIUS x h
 * of their group's leader, normals within acos(GROUP_NORMAL) of its; a
 * member's cut then opens at most 1/GROUP_MORE of its limit more.
 * The engine room at depth 3, 512 x 512 (whole job, error per pixel / over
 * 4 x 4 blocks; single runs one after the other): without groups 54.5 s,
 * 1.68% / 1.014%, and with the mesh's limit x 1.5 76.7 s, 1.64% / 0.96%;
 * with groups, the mesh's limit x 1 38.4 s, 1.72% / 1.041%; x 1.25 45.7 s,
 * 1.69% / 0.994%; x 1.5 54.1 s, 1.68% / 0.994%.  Groups by distance
 * alone (no sheet walk, x 1) within h/16 and h/4: 1.70% / 1.03% and
 * 1.98% / 1.24%. */
#define GROUP_RADIUS (1.0 / 8)
#define GROUP_NORMAL 0.9
/* A member's further opens cast rays of its own; on the engine room at
 * depth 3 (with the E_2 members below, single runs) 1/16 of the limit took
 * 38.9 s for 1.379% / 0.960%, 1/64 36.6 s for 1.385% / 0.963%, none 36.3 s
 * for 1.391% / 0.967%: fewer opens save more time than the path tracer
 * would need to make up the added error. */
#define GROUP_MORE 64
/* From this level on (E_2: light that has bounced twice) a group's members
 * take their leader's value instead of a cut of their own.  Light that
 * bounced twice varies little over h/8, and re-estimating a 640-cluster
 * cut at each member was a third of that level's cost.  The engine room at
 * depth 3, 512 x 512 (single runs): 45.0 s -> 41.6 s, 1.358% -> 1.379%
 * per pixel, 0.944% -> 0.960% over 4 x 4 blocks.  From E_1 on: 33.5 s,
 * 1.489% / 1.030%, where the first bounce bends within a group.  At E_2,
 * the mesh's plain limit instead gave 1.380% for 1.7 s more of Phase One,
 * and groups within h/4 or h/2 taking their leader's value 1.425% and
 * 1.498% for about 1 s less. */
#define GROUP_COPY_LEVEL 2
/* ZONE_MESH_NODE_DIV (zone.h): the camera's samples gather their light on
 * meshes (gather.c), so a mesh's nodes are read only by the gathers' rays
 * and as senders, which average many of them.
 *
 * Its cut opens a quarter of the level's limit.  The engine room at depth
 * 3, 512 x 512 (whole job, single runs, before the gathers' per-pixel
 * directions): x 5/4 (as without gathers) about 37 s for 0.916% per pixel
 * and 0.558% over 4 x 4 blocks, x 1/2 20.3 s for 0.923% / 0.552%, x 1/4
 * 15.7 s for 0.927% / 0.567%, x 1/8 13.8 s for 1.093% / 0.786% (cuts at
 * their limit leave the floor 0.35% short).  Members of a group taking
 * their leader's value from E_1 on as well: 0.8 s less for 0.935% /
 * 0.574%.
 *
 * Its sky and its gather take a quarter of the directions (the gather
 * at least 64: bounce_gather_count), each node's set turned about its
 * normal (or, of an environment map's, one of 16 shifted sets) by a key of
 * its own, so that neighbouring nodes err apart and the reads' averages
 * take their errors out.  Whole jobs against every
 * direction at every node: Wuson alone A/B 0.664, 0.279% -> 0.273% per
 * pixel; the engine room at 256 x 256 A/B 0.806, 0.931% -> 0.932%;
 * house_day and house_inside at the default quality 0.71 and 0.70 (single
 * runs), 1.848% -> 1.850% and 16.0% -> 15.4%.  One quarter set at every
 * node instead: Wuson 0.2733% (0.2728% set apart), the engine room 0.9331%
 * (0.9323%), house_inside at quality 0 23.46% (23.33%); the nodes
 * themselves are tested in tests/test_sky_gather.c.
 *
 * Its gather is kept at the error a cut of that quarter limit allows: a
 * cut's error goes about as one over the square root of its clusters, so
 * the level's eps times the square root of the divisor, twice it (measured
 * with every direction: the engine room 256 x 256 A/B 0.967, 0.930% ->
 * 0.928% per pixel; Wuson alone A/B 0.875, 0.273% -> 0.279%). */
#define GATHERED_MESH_EPS_MUL sqrt((double)ZONE_MESH_NODE_DIV)

/* Where a triangle node's light is computed: moved this share of the way
 * toward its triangle's centroid.  A node on a triangle's edge or corner
 * lies where surfaces meet (a floor and a wall): on the other surface's
 * plane, so rays from it toward that surface's far side start on it and
 * pass, and the node sees what lies behind the wall: the sunlit ground
 * from inside a room of thin walls (a room of two triangles a wall was 44%
 * too bright at level 2, bright lines along every corner), the inside of
 * a thick wall (a house's rooms too dark).  Moved inside its triangle, the
 * node is off the other planes; the move is far below the node spacing. */
#define NODE_INSET 1e-4

static vec3 node_point(const surface_nodes *sn, const rscene *rs, int32_t k, vec3 *n)
{
    *n = v3(sn->nrm[3 * k], sn->nrm[3 * k + 1], sn->nrm[3 * k + 2]);
    vec3 x = v3(sn->pos[3 * k], sn->pos[3 * k + 1], sn->pos[3 * k + 2]);
    rs_part tmp;
    const rs_part *p = rs_prim(rs, sn->prim_of[k], &tmp);
    if (p->shape != SHAPE_TRIANGLE)
        return x;
    vec3 c = v3_add(f3_to_v3(p->p0), v3_scale(v3_add(f3_to_v3(p->e1), f3_to_v3(p->e2)), 1.0 / 3.0));
    return v3_add(x, v3_scale(v3_sub(c, x), NODE_INSET));
}

/* The luminance of node k's light at the levels below `level`. */
static double light_below(const zone_forest *f, int level, int32_t k)
{
    double y = 0;
    for (int j = 0; j < level; j++) {
        const float *v = zone_e(f, j, k);
        y += 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
    }
    return y;
}

/* Level `level`'s irradiance at live node k (without the caustics).  At
 * a level with a transfer the node gathers it where the gather is good
 * enough (bounce_gather.h; *gathered is then set), else takes a cut, kept
 * in rec (if any) or started from `from`, a nearby node's (if any). */
static vec3 node_value(zone_forest *f, const zt_renderer *r, int level, const transfer_ctx *tc,
                       int32_t k, cut_record *rec, const cut_record *from, uint64_t *rays,
                       uint64_t *links, uint64_t *capped, int *gathered)
{
    const surface_nodes *sn = &f->sn;
    zone_trace t = {.f = f, .r = r};
    vec3 n, x = node_point(sn, &r->rs, k, &n);
    int prim = sn->prim_of[k];
    vec3 e;
    *gathered = 0;
    /* A mesh node's sky and gather take a quarter of the directions, set
     * apart from its neighbours' (ZONE_MESH_NODE_DIV above). */
    int on_mesh = zone_gathers(&r->rs, prim);
    if (on_mesh)
        t.node_draw = zone_node_draw_key(k, level);
    if (level == 0) {
        e = zone_lights_at(&t, prim, x, n);
        if (f->sky)
            e = v3_add(e, zone_sky_irradiance(&t, x, n));
        *rays += t.rays + direct_rays_take();
        return e;
    }
    /* Far out on a plane a node stands for a wide cell that matters
     * little: a coarser limit (the square root of its growth, as the
     * texels had). */
    transfer_ctx tk = *tc;
    tk.eps = tc->eps * sqrt(sn->growth[k]);
    bounce_limit lim = {.eps = tk.eps, .lower = light_below(f, level, k), .floor = tc->floor};
    int least = f->q.gather;
    if (on_mesh) {
        lim.eps *= GATHERED_MESH_EPS_MUL;
        least = bounce_gather_count(least, ZONE_MESH_NODE_DIV);
    }
    *gathered = bounce_gather(&t, f->bounce_dirs, least, f->q.gather, x, n, level, &lim, &e);
    if (!*gathered) {
        if (on_mesh)
            tk.max_cut = tc->max_cut / ZONE_MESH_NODE_DIV;
        transfer_stats ts = {0};
        e = from ? transfer_irradiance_near(&tk, x, n, from, tk.max_cut / GROUP_MORE, &ts)
                 : transfer_irradiance(&tk, x, n, prim, &ts, rec);
        t.rays += ts.rays;
        *links += ts.clusters;
        *capped += ts.capped;
    }
    if (level == 1 && f->glint_count)
        e = v3_add(e, glint_irradiance(&t, f->glint_spheres, f->glint_count, x, n,
                                       f->q.glint_cuts));
    /* (A gather read the specular chains along its own rays.) */
    if (!*gathered && f->need_gather)
        e = v3_add(e, zone_specular_gather(&t, x, n, level));
    *rays += t.rays + direct_rays_take();
    return e;
}

/* Whether the light along a grid line (four nodes of earlier rounds,
 * live) is straight enough for the node between the inner two to be read
 * linearly from them: the parabola through either three differs there
 * from the line by at most SMOOTH of the values.  *w: the far one's
 * weight. */
#define SMOOTH 0.01
static int straight(const surface_nodes *sn, const float *v, const int32_t line[4],
                    const double pos[5], double *w)
{
    for (int s = 0; s < 4; s++)
        if (!sn->live[line[s]])
            return 0;
    const double *t = pos, x = pos[4];
    *w = (x - t[1]) / (t[2] - t[1]);
    for (int ch = 0; ch < 3; ch++) {
        double a = v[3 * (size_t)line[0] + ch], b = v[3 * (size_t)line[1] + ch];
        double c = v[3 * (size_t)line[2] + ch], d = v[3 * (size_t)line[3] + ch];
        double top = dmax(dmax(a, b), dmax(c, d));
        /* The parabola's excess over the chord b-c at x: its second
         * divided difference times (x - t1)(x - t2). */
        double k = (x - t[1]) * (x - t[2]);
        double dd1 = ((c - b) / (t[2] - t[1]) - (b - a) / (t[1] - t[0])) / (t[2] - t[0]);
        double dd2 = ((d - c) / (t[3] - t[2]) - (c - b) / (t[2] - t[1])) / (t[3] - t[1]);
        if (fabs(dd1 * k) > SMOOTH * top || fabs(dd2 * k) > SMOOTH * top)
            return 0;
    }
    return 1;
}

static void set_value(float *v, int32_t k, vec3 e)
{
    v[3 * (size_t)k] = (float)e.x;
    v[3 * (size_t)k + 1] = (float)e.y;
    v[3 * (size_t)k + 2] = (float)e.z;
}

/* Receivers far darker than the scene's average need no fine cut: the
 * cut's limit is eps x at least FLOOR_SHARE of the irradiance that the
 * senders' mean radiance would give, since an image's error is measured
 * against its mean, not pixel by pixel.  The mean is over the area that
 * sends (planes' grids reach far behind the walls, where nothing does).
 * Engine room, level 2 at 128 x 128, with the mesh rounds: 0.3 halves the
 * rays (486 to 254 million) at the same error (4.40% per pixel against the
 * path reference); 0.02 changed no pixel. */
#define FLOOR_SHARE 0.3
static double cut_floor(const sender_tree *tree)
{
    double area = 0;
    for (int i = 0; i < tree->elem_count; i++) {
        const float *b = &tree->elem_radiance[3 * (size_t)i];
        if (b[0] > 0 || b[1] > 0 || b[2] > 0)
            area += tree->elems[i].area;
    }
    return area > 0 ? FLOOR_SHARE * 3.14159265358979 * tree->total_power / area : 0;
}

/* Clusters a receiver's cut opens at most at the first bounce (later
 * ones: level_max_cut); past them the cut's clusters stay as estimated (no
 * light is left out).  Lightcuts (Walter et al. 2005) caps its cuts at
 * 1000.  The engine room at depth 3, 512 x 512, with one limit for every
 * level (rays of the whole job, error per pixel / over 4 x 4 blocks): 512 takes
 * 66 M rays for 2.19% / 1.66%, 1024 149 M for 1.95% / 1.37%, 2048 344 M
 * and 4096 537 M for 1.89% / 1.30%.  How many cuts reach it is reported
 * (zt_render_stats). */
#define MAX_CUT 1024

/* The limit at `level` (1 = the first bounce): halved for each bounce
 * after the first, down to MIN_CUT.  A later bounce carries less of the
 * image's light, spread by the bounces after it.  The engine room at depth
 * 3, 512 x 512: 512 for E_2 instead of 1024 takes 27% off Phase One (149 M
 * to 106 M rays) for 1.95% -> 1.96% per pixel and 1.37% -> 1.38% over 4 x 4
 * blocks; the shipped scenes at 128 x 128 lose up to 3% of their accuracy
 * (triangletest) for up to 24% less Phase One.  With a model's triangles
 * at h/2, 256 for E_2 gives 1.85% / 1.26% against 512's 1.70% / 1.06%. */
#define MIN_CUT 128
static int level_max_cut(int level)
{
    int cut = MAX_CUT;
    for (int k = 2; k <= level && cut > MIN_CUT; k++)
        cut /= 2;
    return cut > MIN_CUT ? cut : MIN_CUT;
}

/* Threads take nodes in chunks this long, and check the clock once a
 * chunk. */
#define NODE_BLOCK 64
/* Processes take nodes in blocks this long (render/share.h): short, since
 * the costly nodes (shadow edges, corners) lie together. */
#define SHARE_BLOCK 8

/* E_level at every live node, added to what is there (caustics).  Coarse
 * nodes first; a finer node midway between coarser ones on a straight
 * stretch is their mean (surface_node_line), else it is computed too.  The
 * rounds depend on nothing but the nodes, so the values are the same on
 * any thread count; split over processes, each computes its blocks of a
 * round and the merge after it gives all of them the round.  When the clock
 * passes `until` or the render is asked to stop (on any process), the level
 * is abandoned: *abandoned is set and nothing changes. */
static zt_status build_level(zone_forest *f, const zt_renderer *r, int level,
                             const sender_tree *tree, const mesh_rounds *mr,
                             const node_twins *tw, const node_groups *ng, double until,
                             int *abandoned, zt_error *err)
{
    const rscene *rs = &r->rs;
    const surface_nodes *sn = &f->sn;
    const zt_render_options *o = &r->options;
    transfer_ctx tc = {.tree = tree, .sn = sn, .rs = rs,
                       .e = level > 0 ? zone_e(f, level - 1, 0) : NULL, .eps = f->q.eps,
                       .theta = f->q.theta, .max_cut = level_max_cut(level)};
    if (level > 0)
        tc.floor = cut_floor(tree);
    float *v = calloc(3 * (size_t)sn->node_count + 3, sizeof(float));
    if (!v)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory for level %d's node values", level);
    uint64_t rays = 0, links = 0, capped = 0, cuts = 0, shared = 0, gathers = 0;
    int threads = render_thread_count(o->threads);
    const volatile sig_atomic_t *stop = o->stop;
    int quit = 0;
    /* A forest for one image leaves the last level out on meshes: their
     * camera samples gather it from the level below, and nothing else
     * reads it (zone.h, top_gathered). */
    int skip_meshes = f->top_gathered && level == f->map_levels - 1;
    /* Progress in nodes settled (computed or read: each in one pass). */
    double owned = 0;
    for (int k = 0; k < sn->node_count; k++) {
        /* (A member is settled by whoever settles its leader.) */
        int32_t lead = level > 0 ? node_group_lead(ng, k) : -1;
        owned += sn->live[k] && share_owns(o, (lead >= 0 ? lead : k) / SHARE_BLOCK) &&
                 !(skip_meshes && zone_gathers(rs, sn->prim_of[k]));
    }
    char stage[48];
    snprintf(stage, sizeof stage, "phase one %d/%d", level + 1, f->map_levels);
    progress prog;
    progress_init(&prog, o, stage, owned > 0 ? owned : 1);
    zt_status st = ZT_OK;
    int passes = mr->round && MESH_ROUNDS > NODE_ROUNDS ? MESH_ROUNDS : NODE_ROUNDS;
    for (int pass = 0; pass < passes && !quit && st == ZT_OK; pass++) {
#pragma omp parallel num_threads(threads)
        {
            cut_record rec = {0};
#pragma omp for schedule(dynamic, NODE_BLOCK) reduction(+ : rays, links, capped, cuts, shared, gathers)
            for (int k = 0; k < sn->node_count; k++) {
                int q;
#pragma omp atomic read
                q = quit;
                if (q)
                    continue;
                if (k % NODE_BLOCK == 0 &&
                    (render_clock() > until || (stop && *stop) || prog.cancelled)) {
#pragma omp atomic write
                    quit = 1;
                    continue;
                }
                if (!sn->live[k] || !share_owns(o, k / SHARE_BLOCK) ||
                    (skip_meshes && zone_gathers(rs, sn->prim_of[k])))
                    continue;
                /* A group's members are computed with its leader, in the
                 * first pass (direct light keeps a cut each). */
                int32_t lead = level > 0 ? node_group_lead(ng, k) : -1;
                if (lead >= 0 && lead != k)
                    continue;
                int32_t line[4];
                double pos[5], w = 0.5;
                int fine = surface_node_line(sn, rs, k, line, pos);
                /* (Direct light keeps every vertex: its shadows are sharp,
                 * and it costs little.) */
                int vertex = !fine && level > 0 && lead < 0 ? mesh_round(mr, k) : 0;
                /* A twin's node is computed in the first pass (a mesh
                 * triangle's grid node), and read in the next. */
                int32_t twin = node_twin(tw, k);
                if ((twin >= 0 ? 1 : lead >= 0 ? 0 : fine ? fine : vertex) != pass)
                    continue;
                vec3 e;
                float read[3];
                int gathered = 0;
                rec.n = 0;
                rec.failed = 1; /* until the leader's cut is kept */
                if (twin >= 0) {
                    const float *b = &v[3 * (size_t)twin];
                    e = v3(b[0], b[1], b[2]);
                } else if (fine && straight(sn, v, line, pos, &w)) {
                    const float *b = &v[3 * (size_t)line[1]], *c = &v[3 * (size_t)line[2]];
                    e = v3((1 - w) * b[0] + w * c[0], (1 - w) * b[1] + w * c[1],
                           (1 - w) * b[2] + w * c[2]);
                } else if (vertex && mesh_rounds_read(mr, sn, v, k, SMOOTH, read)) {
                    e = v3(read[0], read[1], read[2]);
                } else {
                    /* (Members take the leader's cut below, or its value.) */
                    int keep = lead >= 0 && level < GROUP_COPY_LEVEL;
                    e = node_value(f, r, level, &tc, k, keep ? &rec : NULL, NULL, &rays, &links,
                                   &capped, &gathered);
                    cuts += level > 0 && !gathered;
                    gathers += gathered;
                }
                set_value(v, k, e);
                progress_add(&prog, 1.0);
                if (lead < 0)
                    continue;
                for (int32_t i = ng->first[k]; i < ng->first[k + 1]; i++) {
                    int32_t m = ng->member[i];
                    /* A leader that gathered found its light smooth
                     * there: its members take its value. */
                    if (level < GROUP_COPY_LEVEL && !gathered) {
                        int g = 0;
                        e = node_value(f, r, level, &tc, m, NULL, rec.failed ? NULL : &rec,
                                       &rays, &links, &capped, &g);
                        cuts += !g;
                        gathers += g;
                        shared += !rec.failed && !g;
                    }
                    set_value(v, m, e);
                    progress_add(&prog, 1.0);
                }
            }
            free(rec.e);
        }
        if (share_ranks(o) > 1) {
            /* Earlier rounds' values are equal everywhere, this round's
             * each written by one process. */
            double q = quit;
            st = share_merge(o, v, 3 * (size_t)sn->node_count * sizeof *v, err);
            if (st == ZT_OK)
                st = share_max(o, &q, 1, err);
            quit = q != 0;
        }
    }
    f->rays += rays;
    if (prog.cancelled && st == ZT_OK)
        st = zt_fail(err, ZT_ERR_CANCELLED, "render cancelled in Phase One");
    *abandoned = quit;
    if (!quit && st == ZT_OK)
        for (int k = 0; k < sn->node_count; k++) {
            float *px = zone_e(f, level, k);
            for (int ch = 0; ch < 3; ch++)
                px[ch] += v[3 * (size_t)k + ch];
        }
    free(v);
    f->links += links;
    f->cuts += cuts;
    f->cuts_capped += capped;
    f->cuts_shared += shared;
    f->gathers += gathers;
    return st;
}

/* The time limit: Phase Two must fit after the last level.  It costs about
 * what level 0 did (exact direct light at every node) per sample point,
 * times PHASE_TWO_FACTOR for its other terms (measured 3.9-6.7 on the Cornell
 * box at qualities 2 and 4). */
#define PHASE_TWO_FACTOR 6.0

static double phase_two_estimate(const zone_forest *f, const zt_renderer *r, double level0)
{
    if (f->sn.node_count <= 0)
        return 0;
    const zt_camera *c = &r->scene->camera;
    double points = (double)c->width * c->height * f->q.aa * f->q.aa;
    return PHASE_TWO_FACTOR * level0 * points / f->sn.node_count;
}

/* The images of lights in glint spheres at the mesh nodes (E_1 holds them
 * with the rest), into f->c for the gathers on meshes. */
static void glints_apart(zone_forest *f, const zt_renderer *r)
{
    const surface_nodes *sn = &f->sn;
    int threads = render_thread_count(r->options.threads);
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
    for (int32_t k = 0; k < sn->node_count; k++) {
        if (!sn->live[k] || sn->prim_of[k] < r->rs.part_count)
            continue;
        zone_trace t = {.f = f, .r = r};
        vec3 n, x = node_point(sn, &r->rs, k, &n);
        vec3 g = glint_irradiance(&t, f->glint_spheres, f->glint_count, x, n, f->q.glint_cuts);
        float *c = f->c + ((size_t)f->sn.node_count + (size_t)k) * 3;
        c[0] += (float)g.x;
        c[1] += (float)g.y;
        c[2] += (float)g.z;
    }
}

zt_status zone_phase_one(zone_forest *f, zt_renderer *r, zt_error *err)
{
    zt_status st = zone_forest_frame(f, r, err);
    if (st != ZT_OK)
        return st;
    int depth = r->options.level >= 0 ? r->options.level : r->options.depth;
    f->map_levels = depth >= 2 ? depth : 0;
    if (f->map_levels > 0) {
        f->rays += node_life_mark(&f->sn, &f->occ, r->scene, &r->rs,
                                  render_thread_count(r->options.threads));
        size_t n = (size_t)f->map_levels * (size_t)f->sn.node_count * 3;
        f->e = calloc(n + 3, sizeof(float));
        if (!f->e)
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for %zu node values", n);
        /* Light through mirrors and glass from the lights, into the levels
         * it arrives at; the rest is added level by level. */
        st = caustic_build(f, r, err);
        if (st != ZT_OK)
            return st;
        /* What the caustics put there, kept apart for the gathers on
         * meshes, which see everything else along their rays. */
        if (f->specular && r->rs.mesh_count > 0) {
            f->c = malloc((n + 3) * sizeof(float));
            if (!f->c)
                return zt_fail(err, ZT_ERR_MEMORY, "out of memory for %zu node values", n);
            memcpy(f->c, f->e, (n + 3) * sizeof(float));
        }
        mesh_rounds mr;
        if (!mesh_rounds_build(&mr, &f->sn, &r->rs, render_thread_count(r->options.threads)))
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the mesh's node rounds");
        node_twins tw;
        if (!node_twins_build(&tw, &f->sn, &r->rs)) {
            mesh_rounds_free(&mr);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the mesh's node twins");
        }
        node_groups ng;
        if (!node_groups_build(&ng, &f->sn, &r->rs, GROUP_RADIUS * f->sn.h, GROUP_NORMAL)) {
            mesh_rounds_free(&mr);
            node_twins_free(&tw);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the mesh's node groups");
        }
        sender_tree tree;
        if (!sender_tree_build(&tree, &f->sn, &r->rs)) {
            mesh_rounds_free(&mr);
            node_twins_free(&tw);
            node_groups_free(&ng);
            return zt_fail(err, ZT_ERR_MEMORY, "out of memory for the sender tree");
        }
        /* Levels are built while they fit before the deadline, less the
         * time Phase Two will need; one that does not is abandoned. */
        double phase_two = 0;
        int built = 0;
        f->top_gathered = r->one_image && r->rs.mesh_count > 0;
        for (int level = 0; level < f->map_levels; level++) {
            double t0 = render_clock();
            if (level > 0)
                sender_tree_fill(&tree, &f->sn, &r->rs, zone_e(f, level - 1, 0));
            int abandoned = 0;
            st = build_level(f, r, level, &tree, &mr, &tw, &ng, r->deadline - phase_two,
                             &abandoned, err);
            if (st != ZT_OK)
                break;
            if (abandoned) {
                f->stopped = r->options.stop && *r->options.stop ? ZT_STOP_INTERRUPT
                                                                 : ZT_STOP_TIME;
                break;
            }
            if (level == 0)
                phase_two = phase_two_estimate(f, r, render_clock() - t0);
            if (level == 1 && f->c && f->glint_count)
                glints_apart(f, r);
            built++;
        }
        sender_tree_free(&tree);
        mesh_rounds_free(&mr);
        node_twins_free(&tw);
        node_groups_free(&ng);
        if (st != ZT_OK)
            return st;
        if (built < f->map_levels) {
            /* E_0 .. E_{built-1} carry depth `built`; depth 1 needs none.
             * (Their last level was built whole.) */
            f->top_gathered = 0;
            r->options.depth = built > 1 ? built : 1;
            f->map_levels = built > 1 ? built : 0;
        }
    }
    if (share_ranks(&r->options) > 1) {
        /* The counts are the whole job's, as one process's would be. */
        double n[6] = {(double)f->rays, (double)f->links, (double)f->cuts,
                       (double)f->cuts_capped, (double)f->cuts_shared, (double)f->gathers};
        st = share_sum(&r->options, n, 6, err);
        if (st != ZT_OK)
            return st;
        f->rays = (uint64_t)n[0];
        f->links = (uint64_t)n[1];
        f->cuts = (uint64_t)n[2];
        f->cuts_capped = (uint64_t)n[3];
        f->cuts_shared = (uint64_t)n[4];
        f->gathers = (uint64_t)n[5];
    }
    return zone_forest_zones(f, r, err);
}
