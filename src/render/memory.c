/* Memory estimates and the limit they are checked against. */
#define _POSIX_C_SOURCE 200809L
#include "render/memory.h"

#include <stdio.h>
#include <unistd.h>

#include "util/error.h"

/* Measured peak resident memory per unit (BENCHMARKS.md, long renders): the
 * path tracer's float image, double sums and 8-bit output; the zone
 * tracer's image, pixel marks and output; a mesh triangle in the
 * renderer's copy of the scene and in Embree or our BVH; a part. */
#define PATH_PER_PIXEL 48
#define ZONE_PER_PIXEL 32
#define PER_TRIANGLE 400
#define PER_PART 256

static uint64_t cgroup_limit(void)
{
    FILE *f = fopen("/sys/fs/cgroup/memory.max", "r");
    if (!f)
        return 0;
    unsigned long long v = 0;
    int ok = fscanf(f, "%llu", &v) == 1; /* "max" when unlimited */
    fclose(f);
    return ok ? (uint64_t)v : 0;
}

uint64_t memory_limit(uint64_t requested, const char **source)
{
    if (requested) {
        *source = "as asked";
        return requested;
    }
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    uint64_t phys = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page : UINT64_MAX;
    uint64_t cg = cgroup_limit();
    if (cg && cg < phys) {
        *source = "the control group's limit";
        return cg;
    }
    *source = "the machine's physical memory";
    return phys;
}

uint64_t memory_estimate_render(const zt_scene *sc, const zt_render_options *o)
{
    uint64_t pixels = (uint64_t)sc->camera.width * (uint64_t)sc->camera.height;
    uint64_t per_pixel = o->method == ZT_METHOD_ZONE ? ZONE_PER_PIXEL : PATH_PER_PIXEL;
    /* The zone tracer's gathers at pixel centres on meshes
     * (phase_two/gather_cache.c): a point, a normal and a distance, and an
     * irradiance per level gathered. */
    if (o->method == ZT_METHOD_ZONE && scene_mesh_triangles(sc) > 0) {
        int gathered = o->level >= 0 ? 1 : o->depth - 1;
        per_pixel += 28 + 12 * (uint64_t)(gathered > 0 ? gathered : 0);
    }
    return pixels * per_pixel + (uint64_t)scene_mesh_triangles(sc) * PER_TRIANGLE +
           (uint64_t)sc->part_count * PER_PART;
}

uint64_t memory_zone_nodes(long long nodes, int map_levels)
{
    return (uint64_t)nodes * (600 + 12 * (uint64_t)map_levels);
}

const char *memory_format(uint64_t bytes, char *buf, int size)
{
    static const char *unit[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
    double v = (double)bytes;
    int u = 0;
    while (v >= 1024 && u < 5) {
        v /= 1024;
        u++;
    }
    if (u == 0)
        snprintf(buf, (size_t)size, "%llu bytes", (unsigned long long)bytes);
    else
        snprintf(buf, (size_t)size, "%.1f %s", v, unit[u]);
    return buf;
}

zt_status memory_check(uint64_t need, const char *what, const zt_render_options *o,
                       zt_error *err)
{
    const char *source;
    uint64_t limit = memory_limit(o->max_memory, &source);
    if (need <= limit)
        return ZT_OK;
    char a[32], b[32];
    return zt_fail(err, ZT_ERR_MEMORY, "%s needs about %s of memory, more than the limit of %s (%s)",
                   what, memory_format(need, a, sizeof a), memory_format(limit, b, sizeof b),
                   source);
}
