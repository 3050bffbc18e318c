/* A render split over processes: the work units and the exchanges. */
#include "render/share.h"

#include <stdlib.h>
#include <string.h>

#include "util/error.h"

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
    return n == 1 || unit % n == share_rank(o);
}

long long share_owned(const zt_render_options *o, long long count)
{
    int n = share_ranks(o), r = share_rank(o);
    return count / n + (r < count % n);
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
