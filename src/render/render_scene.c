/* Compiling the scene model into the renderers' flat arrays. */
#include "render/render_scene.h"

#include <stdlib.h>
#include <string.h>

#include "geom/accel.h"
#include "light/distant.h"
#include "material/microfacet.h"
#include "render/prim.h"
#include "scene/mesh.h"
#include "util/error.h"
#include "util/vec3_convert.h"


static int light_is_off(int index, const int *off, int n)
{
    for (int i = 0; i < n; i++)
        if (off[i] == index)
            return 1;
    return 0;
}

/* Emitted power up to the radiance's colour, used to share next-event
 * samples among lights.  Planes are unbounded and not sampled (0). */
static double part_power(const rs_part *p, vec3f emission)
{
    double lum = f3_luminance(emission);
    switch (p->shape) {
    case SHAPE_TRIANGLE: return lum * p->area * 3.14159265358979 * (p->culled ? 1 : 2);
    case SHAPE_SPHERE: return lum * p->area * 3.14159265358979;
    case SHAPE_POINT: return lum * 4 * 3.14159265358979;
    default: return 0;
    }
}

static void fill_object(rs_object *ro, const material *mat, vec3 emission, int is_light,
                        const object *o)
{
    int lobes = 0;
    for (int k = 0; k < LOBE_COUNT; k++) {
        ro->weight[k] = (float)mat->weight[k];
        lobes += ro->weight[k] > 0.0f;
    }
    ro->specular = (float)mat->specular;
    ro->coat = (uint8_t)(ro->specular > 0.0f && ro->weight[LOBE_DIFFUSE] > 0.0f);
    /* (A coat is a second choice under the diffuse lobe.) */
    ro->lobe_choice = lobes > 1 || ro->coat;
    ro->color = v3_to_f3(mat->color);
    ro->ior = (float)mat->ior;
    ro->thin = (uint8_t)(mat->thin && mat->weight[LOBE_REFRACTIVE] > 0);
    ro->tint = v3_to_f3(mat->tint);
    ro->alpha = mat->roughness > 0 ? (float)(mat->roughness * mat->roughness) : 0.0f;
    if (ro->alpha > 0.0f && ro->alpha < GGX_ALPHA_MIN)
        ro->alpha = GGX_ALPHA_MIN;
    ro->rough = (uint8_t)(ro->alpha > 0.0f &&
                          (ro->weight[LOBE_METALLIC] > 0.0f || ro->weight[LOBE_REFLECTING] > 0.0f ||
                           (ro->weight[LOBE_REFRACTIVE] > 0.0f && !ro->thin)));
    /* Lights have no coverage. */
    ro->alpha_mode = (uint8_t)(is_light ? ALPHA_OPAQUE : mat->alpha_mode);
    ro->alpha_cutoff = (float)mat->alpha_cutoff;
    ro->coverage = (float)mat->coverage;
    ro->is_light = (uint8_t)is_light;
    ro->culled = (uint8_t)o->backculled;
    ro->background = (uint8_t)o->background;
    ro->emission = v3_to_f3(emission);
}

/* The smallest alpha code of a texture's texels. */
static int texture_alpha_min(const mesh_texture *t)
{
    int lo = 255;
    size_t n = (size_t)t->width * (size_t)t->height;
    for (size_t i = 0; i < n && lo > 0; i++)
        lo = t->rgba[4 * i + 3] < lo ? t->rgba[4 * i + 3] : lo;
    return lo;
}

/* A coverage that is the same everywhere and whole makes the object
 * opaque, which costs nothing: files often say BLEND of opaque materials. */
static void simplify_alpha(rs_object *ro)
{
    if (ro->alpha_mode == ALPHA_OPAQUE)
        return;
    float tex = ro->texture ? texture_alpha_min(ro->texture) / 255.0f : 1.0f;
    float lowest = ro->coverage * tex;
    if (ro->alpha_mode == ALPHA_MASK ? lowest >= ro->alpha_cutoff : lowest >= 1.0f)
        ro->alpha_mode = ALPHA_OPAQUE;
}

/* The meshes' table and their slots' objects (after the scene's own). */
static int build_meshes(rscene *rs, const zt_scene *scene, const int *lights_off,
                        int lights_off_count)
{
    int objects = scene->object_count, prims = scene->part_count;
    for (int i = 0; i < scene->object_count; i++) {
        const object *o = &scene->objects[i];
        if (o->mesh < 0)
            continue;
        const mesh *m = scene->meshes[o->mesh];
        rs_mesh *mm = &rs->meshes[rs->mesh_count++];
        mm->m = m;
        mm->prim_base = prims;
        mm->object_base = objects;
        mm->is_light = (uint8_t)o->is_light;
        mm->culled = (uint8_t)o->backculled;
        mm->background = (uint8_t)o->background;
        mm->smooth = m->normal != NULL;
        prims += m->triangle_count;
        if (o->is_light) {
            int off = light_is_off(o->index, lights_off, lights_off_count);
            fill_object(&rs->objects[objects++], &o->mat, off ? v3(0, 0, 0) : o->emission, 1, o);
            continue;
        }
        for (int k = 0; k < m->slot_count; k++) {
            const mesh_slot *sl = &m->slots[k];
            rs_object *ro = &rs->objects[objects++];
            fill_object(ro, &sl->mat, sl->emission, !v3_is_black(sl->emission), o);
            if (sl->texture >= 0 && !ro->is_light && m->uv)
                ro->texture = &m->textures[sl->texture];
            if (sl->emissive_texture >= 0 && ro->is_light && m->uv)
                ro->emissive = &m->textures[sl->emissive_texture];
            if (!ro->is_light && m->uv &&
                (sl->rough_map.texture >= 0 || sl->metal_map.texture >= 0 ||
                 sl->normal_texture >= 0)) {
                rs_maps *mp = &rs->maps[ro - rs->objects];
                if (sl->rough_map.texture >= 0) {
                    mp->rough = &m->textures[sl->rough_map.texture];
                    mp->rough_channel = sl->rough_map.channel;
                }
                if (sl->metal_map.texture >= 0) {
                    mp->metal = &m->textures[sl->metal_map.texture];
                    mp->metal_channel = sl->metal_map.channel;
                }
                if (sl->normal_texture >= 0)
                    mp->normal = &m->textures[sl->normal_texture];
                mp->roughness = (float)sl->roughness;
                mp->metallic = (float)sl->metallic;
                mp->transmission = (float)sl->transmission;
                mp->normal_scale = (float)sl->normal_scale;
                ro->maps = mp;
            }
        }
    }
    rs->prim_count = prims;
    return objects;
}

/* The mean emission of each triangle of the meshes whose slots have an
 * emissive texture (rs_mesh.emit_mean).  0 when out of memory. */
static int emission_means(rscene *rs)
{
    for (int k = 0; k < rs->mesh_count; k++) {
        rs_mesh *mm = &rs->meshes[k];
        int any = 0;
        for (int s = 0; s < mm->m->slot_count && !mm->is_light; s++)
            any |= rs->objects[mm->object_base + s].emissive != NULL;
        if (!any)
            continue;
        mm->emit_mean = calloc((size_t)mm->m->triangle_count, sizeof *mm->emit_mean);
        if (!mm->emit_mean)
            return 0;
        for (int t = 0; t < mm->m->triangle_count; t++) {
            const rs_object *o = &rs->objects[rs_mesh_object(mm, mm->prim_base + t)];
            mm->emit_mean[t] = o->emissive ? rs_emission_triangle_mean(o, mm->m, t) : o->emission;
        }
    }
    return 1;
}

static void fill_part(rs_part *rp, const part *p, const object *o)
{
    memset(rp, 0, sizeof *rp);
    rp->shape = (uint8_t)p->shape;
    rp->is_light = (uint8_t)o->is_light;
    rp->culled = (uint8_t)o->backculled;
    rp->background = (uint8_t)o->background;
    rp->object = p->object;
    rp->light = -1;
    rp->p0 = v3_to_f3(p->p[0]);
    switch (p->shape) {
    case SHAPE_TRIANGLE: {
        vec3 e1 = v3_sub(p->p[1], p->p[0]), e2 = v3_sub(p->p[2], p->p[0]);
        vec3 c = v3_cross(e1, e2);
        rp->e1 = v3_to_f3(e1);
        rp->e2 = v3_to_f3(e2);
        rp->n = v3_to_f3(v3_normalize(c));
        rp->area = (float)(0.5 * v3_length(c));
        f3_basis(rp->n, &rp->tangent, &rp->bitangent);
        break;
    }
    case SHAPE_SPHERE:
        rp->radius = (float)p->radius;
        rp->c_lo = v3_to_f3(v3_sub(p->p[0], f3_to_v3(rp->p0)));
        rp->r_lo = (float)(p->radius - (double)rp->radius);
        rp->area = (float)(4 * 3.14159265358979 * p->radius * p->radius);
        break;
    case SHAPE_PLANE:
        rp->n = v3_to_f3(p->normal);
        rp->offset = (float)p->offset;
        f3_basis(rp->n, &rp->tangent, &rp->bitangent);
        break;
    default:
        break;
    }
}

/* Room for the layer's planes; the padding planes (normal 0, offset 1)
 * give t = inf and are never hit. */
static int planes_alloc(rs_planes *pl, const zt_scene *scene, int layer)
{
    int n = 0;
    for (int i = 0; i < scene->part_count; i++)
        n += scene->parts[i].shape == SHAPE_PLANE &&
             scene->objects[scene->parts[i].object].background == layer;
    pl->count = 0;
    pl->padded = (n + PLANE_LANES - 1) / PLANE_LANES * PLANE_LANES;
    size_t m = (size_t)pl->padded + 1;
    pl->nx = calloc(5 * m, sizeof(float));
    pl->part = calloc(m, sizeof(int));
    if (!pl->nx || !pl->part)
        return 0;
    pl->ny = pl->nx + m;
    pl->nz = pl->ny + m;
    pl->offset = pl->nz + m;
    pl->culled = pl->offset + m;
    for (int i = 0; i < pl->padded; i++)
        pl->offset[i] = 1.0f;
    return 1;
}

zt_status rscene_build(rscene *rs, const zt_scene *scene,
                       const int *lights_off, int lights_off_count,
                       int accel_choice, zt_error *err)
{
    memset(rs, 0, sizeof *rs);
    /* Light triangles of meshes and the meshes' slots, to size the tables. */
    long long mesh_lights = 0, slots = 0;
    for (int i = 0; i < scene->object_count; i++) {
        const object *o = &scene->objects[i];
        if (o->mesh < 0)
            continue;
        const mesh *m = scene->meshes[o->mesh];
        slots += o->is_light ? 1 : m->slot_count;
        for (int t = 0; t < m->triangle_count; t++)
            mesh_lights += o->is_light || !v3_is_black(m->slots[mesh_slot_of(m, t)].emission);
    }
    if ((long long)scene->part_count + scene_mesh_triangles(scene) > INT32_MAX - 1)
        return zt_fail(err, ZT_ERR_UNSUPPORTED, "the scene has more than 2^31 - 2 primitives");
    rs->part_count = scene->part_count;
    rs->parts = calloc((size_t)(scene->part_count + 1), sizeof(rs_part));
    rs->objects = calloc((size_t)(scene->object_count + slots + 1), sizeof(rs_object));
    rs->maps = calloc((size_t)(scene->object_count + slots + 1), sizeof(rs_maps));
    rs->lights = calloc((size_t)(scene->part_count + mesh_lights + 1), sizeof(rs_light));
    rs->point_lights = calloc((size_t)(scene->part_count + 1), sizeof(int));
    rs->meshes = calloc((size_t)(scene->mesh_count + 1), sizeof(rs_mesh));
    int planes_ok = 1;
    for (int l = 0; l < 2; l++)
        planes_ok &= planes_alloc(&rs->planes[l], scene, l);
    if (!rs->parts || !rs->objects || !rs->maps || !rs->lights || !rs->point_lights || !rs->meshes ||
        !planes_ok) {
        rscene_free(rs);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    }
    rs->sky = v3_to_f3(scene->sky);
    distant_build(&rs->distant, scene);

    for (int i = 0; i < scene->object_count; i++) {
        const object *o = &scene->objects[i];
        int on = o->is_light && !light_is_off(o->index, lights_off, lights_off_count);
        fill_object(&rs->objects[i], &o->mat, on ? o->emission : v3(0, 0, 0), o->is_light, o);
    }
    rs->object_count = build_meshes(rs, scene, lights_off, lights_off_count);
    if (!emission_means(rs)) {
        rscene_free(rs);
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    }
    int plain_objects = 1;
    for (int i = 0; i < rs->object_count; i++) {
        rs_object *ro = &rs->objects[i];
        simplify_alpha(ro);
        rs->pane_count += rs_passes(ro) != 0;
        rs->alpha_count += ro->alpha_mode != ALPHA_OPAQUE;
        plain_objects &= !ro->rough && !ro->coat && !ro->thin && !ro->texture && !ro->maps;
    }
    for (int k = 0; k < rs->mesh_count; k++)
        plain_objects &= !rs->meshes[k].smooth;
    rs->plain = plain_objects && !rs->distant.any && rs->pane_count == 0 && rs->alpha_count == 0;

    double total = 0;
    for (int i = 0; i < scene->part_count; i++) {
        const part *p = &scene->parts[i];
        rs_part *rp = &rs->parts[i];
        fill_part(rp, p, &scene->objects[p->object]);
        if (rp->shape == SHAPE_PLANE) {
            rs_planes *pl = &rs->planes[rp->background];
            int k = pl->count++;
            pl->nx[k] = rp->n.x;
            pl->ny[k] = rp->n.y;
            pl->nz[k] = rp->n.z;
            pl->offset[k] = rp->offset;
            pl->culled[k] = rp->culled ? 1.0f : 0.0f;
            pl->part[k] = i;
        }
        if (rp->is_light && rp->shape == SHAPE_POINT)
            rs->point_lights[rs->point_light_count++] = i;
        double power = rp->is_light ? part_power(rp, rs->objects[rp->object].emission) : 0;
        if (power > 0) {
            rp->light = rs->light_count;
            rs->lights[rs->light_count].part = i;
            rs->lights[rs->light_count].select_pdf = (float)power;
            rs->light_count++;
            total += power;
        }
    }
    /* Emitting mesh triangles, each a light of its own (power-proportional
     * choice lets thousands of them converge). */
    for (int k = 0; k < rs->mesh_count; k++) {
        const rs_mesh *mm = &rs->meshes[k];
        for (int t = 0; t < mm->m->triangle_count; t++) {
            int prim = mm->prim_base + t;
            const rs_object *o = &rs->objects[rs_mesh_object(mm, prim)];
            if (!o->is_light)
                continue;
            rs_part tri;
            rs_mesh_part(rs, mm, prim, &tri);
            /* A textured light weighs by its mean; one black all over is
             * no light to sample. */
            double power = part_power(&tri, rs_emission_mean(rs, prim, o));
            if (power > 0) {
                rs->lights[rs->light_count].part = prim;
                rs->lights[rs->light_count].select_pdf = (float)power;
                rs->light_count++;
                total += power;
            }
        }
    }
    double cdf = 0;
    for (int i = 0; i < rs->light_count; i++) {
        double pdf = rs->lights[i].select_pdf / total;
        cdf += pdf;
        rs->lights[i].select_pdf = (float)pdf;
        rs->lights[i].select_cdf = i == rs->light_count - 1 ? 1.0f : (float)cdf;
        if (rs->lights[i].part < rs->part_count)
            rs->parts[rs->lights[i].part].select_pdf = (float)pdf;
    }
    rs->light_power = (float)total;

    zt_status st = accel_build(rs, (accel_kind)accel_choice, err);
    if (st != ZT_OK) {
        rscene_free(rs);
        return st;
    }
    return ZT_OK;
}

void rscene_free(rscene *rs)
{
    accel_free(rs->accel);
    free(rs->parts);
    free(rs->objects);
    free(rs->maps);
    free(rs->lights);
    free(rs->point_lights);
    for (int k = 0; k < rs->mesh_count && rs->meshes; k++)
        free(rs->meshes[k].emit_mean);
    free(rs->meshes);
    for (int l = 0; l < 2; l++) {
        free(rs->planes[l].nx);
        free(rs->planes[l].part);
    }
    memset(rs, 0, sizeof *rs);
}
