/* A render split over processes: the work units and the exchanges. */
#include "render/share.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "render/checkpoint.h"
#include "util/error.h"
#include "util/fnv1a.h"

int share_ranks(const zt_render_options *o)
{
    return o->share && o->share->ranks > 1 ? o->share->ranks : 1;
}

int share_rank(const zt_render_options *o)
{
    return share_ranks(o) > 1 ? o->share->rank : 0;
}

int share_owns(const zt_render_options *o, long long unit)
{
    int n = share_ranks(o);
    if (n == 1)
        return 1;
    /* Scrambled, not unit mod n: with mod n, a cost that repeats every
     * n units would land on one process. */
    uint64_t h = (uint64_t)unit * 0x9e3779b97f4a7c15ULL;
    return (int)((h >> 32) % (uint64_t)n) == share_rank(o);
}

long long share_owned(const zt_render_options *o, long long count)
{
    if (share_ranks(o) == 1)
        return count;
    long long mine = 0;
    for (long long u = 0; u < count; u++)
        mine += share_owns(o, u);
    return mine;
}

zt_status share_merge(const zt_render_options *o, void *buf, size_t bytes, zt_error *err)
{
    if (share_ranks(o) == 1 || bytes == 0)
        return ZT_OK;
    if (o->share->merge(o->share->user, buf, bytes) != 0)
        return zt_fail(err, ZT_ERR_EXCHANGE, "the exchange between the %d processes failed",
                       share_ranks(o));
    return ZT_OK;
}

zt_status share_all(const zt_render_options *o, const double *mine, int n, double *all,
                    zt_error *err)
{
    int ranks = share_ranks(o);
    memset(all, 0, (size_t)ranks * (size_t)n * sizeof *all);
    memcpy(all + (size_t)share_rank(o) * (size_t)n, mine, (size_t)n * sizeof *mine);
    return share_merge(o, all, (size_t)ranks * (size_t)n * sizeof *all, err);
}

static zt_status combine(const zt_render_options *o, double *x, int n, int sum, zt_error *err)
{
    int ranks = share_ranks(o);
    if (ranks == 1)
        return ZT_OK;
    double *all = malloc((size_t)ranks * (size_t)n * sizeof *all);
    if (!all)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    zt_status st = share_all(o, x, n, all, err);
    for (int i = 0; st == ZT_OK && i < n; i++) {
        x[i] = all[i];
        for (int k = 1; k < ranks; k++) {
            double v = all[(size_t)k * (size_t)n + (size_t)i];
            x[i] = sum ? x[i] + v : v > x[i] ? v : x[i];
        }
    }
    free(all);
    return st;
}

zt_status share_max(const zt_render_options *o, double *x, int n, zt_error *err)
{
    return combine(o, x, n, 0, err);
}

zt_status share_sum(const zt_render_options *o, double *x, int n, zt_error *err)
{
    return combine(o, x, n, 1, err);
}

zt_status share_check_same(const zt_scene *scene, const zt_render_options *o, zt_error *err)
{
    int ranks = share_ranks(o);
    if (ranks == 1)
        return ZT_OK;
    /* What the image depends on: the scene, camera, seed, levels and
     * lights-off (as a checkpoint's key) and the renderer's settings. */
    fnv1a h = {FNV1A_START};
    fnv_u64(&h, checkpoint_key(scene, o));
    fnv_i32(&h, (int)o->method);
    fnv_i32(&h, o->spp);
    fnv_i32(&h, o->quality);
    fnv_i32(&h, (int)o->strategy);
    fnv_f64(&h, o->cutoff);
    fnv_i32(&h, o->resume);
    double mine[2] = {(double)(h.h >> 32), (double)(h.h & 0xffffffffu)};
    double *all = malloc(2 * (size_t)ranks * sizeof *all);
    if (!all)
        return zt_fail(err, ZT_ERR_MEMORY, "out of memory");
    zt_status st = share_all(o, mine, 2, all, err);
    for (int k = 1; st == ZT_OK && k < ranks; k++)
        if (all[2 * k] != all[0] || all[2 * k + 1] != all[1])
            st = zt_fail(err, ZT_ERR_ARGUMENT, "process %d of %d has another scene or other "
                         "options than process 0: every process must read the same files "
                         "with the same options", k, ranks);
    free(all);
    return st;
}
