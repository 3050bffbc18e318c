/* Phase Two's preview: an image for a camera that is moving, at a fraction
 * of the full image's cost.
 *
 * One sample per pixel at its centre, shaded from the forest alone: every
 * level of diffuse light is read from the nodes (level 1 from the nodes'
 * direct light E_0 instead of the exact direct light, levels 2 and up from
 * the nodes on meshes too instead of gathers), mirrors and glass followed as
 * in the full image, lights and the sky seen by the ray.  So a preview costs
 * about one ray and a few node reads a pixel, where the full image measures
 * edges by coverage, takes 8 x 8 samples over a mesh's detail and casts the
 * exact direct light's and the gathers' rays.  What it gives up: shadows
 * are as soft as the nodes' spacing, edges are aliased, and a mesh's bounce
 * light is the nodes' coarser one.  Deterministic, like the full image. */
#include <string.h>

#include "render/share.h"
#include "util/error.h"
#include "zone/phase_two/phase_two.h"

zt_status p2_render_preview(const p2_ctx *c, zt_image *sum, uint64_t *rays_out, zt_error *err)
{
    const zt_render_options *o = &c->r->options;
    int threads = render_thread_count(o->threads);
    progress prog;
    progress_init(&prog, o, "zone preview", (double)sum->height);
    uint64_t rays = 0;
    /* A forest of depth 1 keeps no maps: its direct light is the exact one.
     * A coat reflects its irradiance diffusely: its one direction a hit,
     * taken by a roulette of probability s E(cos_o) (a tenth) and weighed
     * by its inverse, speckled coated surfaces (the engine room's preview
     * 11.9% per pixel from the reference, 8.0% without the speckle). */
    int flags = (c->f->map_levels > 0 ? 0 : ZR_EXACT_DIRECT) | ZR_SMOOTH_COAT;
#pragma omp parallel num_threads(threads) reduction(+ : rays)
    {
        zone_trace t = {.f = c->f, .r = c->r};
#pragma omp for schedule(dynamic, 4)
        for (int y = 0; y < sum->height; y++) {
            if (prog.cancelled)
                continue;
            for (int x = 0; x < sum->width; x++) {
                vec3f org, dir;
                cam_ray(&c->c, (float)x + 0.5f, (float)y + 0.5f, &org, &dir);
                vec3 l = zone_radiance(&t, org, dir, c->lo, c->hi, flags, NULL, 0);
                float *px = zt_image_pixel(sum, x, y);
                px[0] += (float)l.x;
                px[1] += (float)l.y;
                px[2] += (float)l.z;
            }
            t.rays += direct_rays_take();
            progress_add(&prog, 1.0);
        }
        rays += t.rays;
    }
    *rays_out += rays;
    if (prog.cancelled)
        return zt_fail(err, ZT_ERR_CANCELLED, "render cancelled");
    return ZT_OK;
}
