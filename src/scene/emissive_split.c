/* Emissive triangles cut where their texture varies (emissive_split.h).
 *
 * The zone tracer's lights are polygons of one radiance each, the mean of
 * the texture over the triangle (docs/zone-tracer.md): a lamp whose
 * texture is half bright and half black, made of two triangles that each
 * straddle the edge, would spread its light over the whole lamp.  Cut into
 * pieces about a texel wide, each piece's mean is close to what it shows.
 * The path tracer reads the texture at every point either way; the pieces
 * only make its next-event estimation choose the bright ones more often. */
#include "scene/emissive_split.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "material/texture.h"
#include "util/error.h"

/* The most pieces along one edge, and the most triangles the cutting may
 * add to a mesh: past that the pieces grow (coarser lights, not a failed
 * import). */
#define SPLIT_MAX 16
#define SPLIT_BUDGET (1 << 18)
/* A triangle whose emission's luminance varies by less than this share of
 * its largest value is left whole. */
#define SPLIT_FLAT 0.02

static double luminance(vec3f c)
{
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

/* The triangle's texture coordinates at barycentric (b1, b2). */
static void uv_at(const float *const uv[3], double b1, double b2, float out[2])
{
    double b0 = 1.0 - b1 - b2;
    for (int a = 0; a < 2; a++)
        out[a] = (float)(b0 * uv[0][a] + b1 * uv[1][a] + b2 * uv[2][a]);
}

/* Pieces along each edge for triangle t: 1 (left whole) unless its slot
 * emits through a texture that varies over it, else about one per texel
 * along its longest side in the texture. */
static int pieces(const mesh *m, int t)
{
    const mesh_slot *s = &m->slots[mesh_slot_of(m, t)];
    if (s->emissive_texture < 0 || v3_is_black(s->emission) || !m->uv)
        return 1;
    const mesh_texture *tex = &m->textures[s->emissive_texture];
    const uint32_t *v = m->index + 3 * (size_t)t;
    const float *uv[3] = {m->uv + 2 * (size_t)v[0], m->uv + 2 * (size_t)v[1],
                          m->uv + 2 * (size_t)v[2]};
    double span = 0.0;
    for (int k = 0; k < 3; k++) {
        const float *a = uv[k], *b = uv[(k + 1) % 3];
        span = fmax(span, fmax(fabs((double)b[0] - a[0]) * tex->width,
                               fabs((double)b[1] - a[1]) * tex->height));
    }
    if (!isfinite(span) || span < 1.5)
        return 1; /* within a texel or so the texture is near linear */
    /* Two points per texel along the longest side: a texel that differs
     * from its neighbours is seen. */
    int n = (int)fmin(2.0 * SPLIT_MAX, ceil(2.0 * span));
    double lo = INFINITY, hi = 0.0;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            float w[2];
            uv_at(uv, (double)i / n, (double)j / n, w);
            double l = luminance(texture_lookup(tex, w[0], w[1]));
            lo = fmin(lo, l);
            hi = fmax(hi, l);
        }
    if (!(hi - lo > SPLIT_FLAT * hi))
        return 1;
    return (int)fmin((double)SPLIT_MAX, ceil(span));
}

/* Grows *p to n elements of size `size` (plus `pad` zeroed ones).  0 when
 * out of memory (*p is then unchanged). */
static int grow(void *p, size_t n, size_t size, size_t pad)
{
    void **pp = p;
    if (!*pp)
        return 1;
    void *q = realloc(*pp, (n + pad) * size);
    if (!q)
        return 0;
    memset((char *)q + n * size, 0, pad * size);
    *pp = q;
    return 1;
}

/* The attributes of a new vertex at barycentric (b1, b2) of the triangle
 * with vertices v, written at vertex index w. */
static void make_vertex(mesh *m, const uint32_t v[3], double b1, double b2, uint32_t w)
{
    double b[3] = {1.0 - b1 - b2, b1, b2};
    for (int a = 0; a < 3; a++) {
        double sum = 0.0;
        for (int c = 0; c < 3; c++)
            sum += b[c] * m->position[3 * (size_t)v[c] + a];
        m->position[3 * (size_t)w + a] = (float)sum;
    }
    if (m->uv)
        for (int a = 0; a < 2; a++) {
            double sum = 0.0;
            for (int c = 0; c < 3; c++)
                sum += b[c] * m->uv[2 * (size_t)v[c] + a];
            m->uv[2 * (size_t)w + a] = (float)sum;
        }
    /* Normals and tangents: interpolated as the renderers interpolate
     * them, then made unit as the importer keeps them. */
    float *vec[2] = {m->normal, m->tangent};
    int stride[2] = {3, 4};
    for (int k = 0; k < 2; k++) {
        if (!vec[k])
            continue;
        double d[3] = {0, 0, 0};
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                d[a] += b[c] * vec[k][(size_t)stride[k] * v[c] + (size_t)a];
        double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; a++)
            vec[k][(size_t)stride[k] * w + (size_t)a] = l > 0 ? (float)(d[a] / l) : 0.0f;
    }
    if (m->tangent) {
        /* The side of the first corner; none when a corner has none. */
        float *t = m->tangent + 4 * (size_t)w;
        int none = 0;
        for (int c = 0; c < 3; c++)
            none |= m->tangent[4 * (size_t)v[c] + 3] == 0.0f;
        t[3] = none ? 0.0f : m->tangent[4 * (size_t)v[0] + 3];
    }
}

/* Grid vertex (i, j) of a triangle cut n ways: its corners keep their
 * indices, the rest are numbered from `first` in row order. */
static uint32_t grid_vertex(const uint32_t v[3], int n, int i, int j, uint32_t first)
{
    if (i == 0 && j == 0)
        return v[0];
    if (i == n)
        return v[1];
    if (j == n)
        return v[2];
    /* Rows i = 0 .. n - 1 hold n + 1 - i points each, less the corners. */
    uint32_t before = 0;
    for (int r = 0; r < i; r++)
        before += (uint32_t)(n + 1 - r) - (r == 0 ? 2u : 0u);
    return first + before + (uint32_t)j - (i == 0 ? 1u : 0u);
}

zt_status mesh_split_emissive(mesh *m, const char *path, int *added, zt_error *err)
{
    *added = 0;
    int any = 0;
    for (int s = 0; s < m->slot_count; s++)
        any |= m->slots[s].emissive_texture >= 0 && !v3_is_black(m->slots[s].emission);
    if (!any || !m->uv)
        return ZT_OK;
    int *n = malloc((size_t)m->triangle_count * sizeof *n);
    if (!n)
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
    long long more_t = 0, more_v = 0;
    for (int t = 0; t < m->triangle_count; t++)
        n[t] = pieces(m, t);
    for (int cap = SPLIT_MAX;; cap = (cap + 1) / 2) {
        more_t = more_v = 0;
        for (int t = 0; t < m->triangle_count; t++) {
            long long k = n[t] < cap ? n[t] : cap;
            more_t += k * k - 1;
            more_v += (k + 1) * (k + 2) / 2 - 3;
        }
        if (more_t <= SPLIT_BUDGET || cap == 1) {
            for (int t = 0; t < m->triangle_count; t++)
                n[t] = n[t] < cap ? n[t] : cap;
            break;
        }
    }
    if (more_t == 0 || (long long)m->triangle_count + more_t > INT32_MAX / 3 ||
        (long long)m->vertex_count + more_v > INT32_MAX / 4) {
        free(n);
        return ZT_OK; /* nothing to cut, or no room: whole triangles */
    }
    size_t nv = (size_t)m->vertex_count + (size_t)more_v;
    size_t nt = (size_t)m->triangle_count + (size_t)more_t;
    if (!grow(&m->position, 3 * nv, sizeof(float), 1) ||
        !grow(&m->normal, 3 * nv, sizeof(float), 1) || !grow(&m->uv, 2 * nv, sizeof(float), 1) ||
        !grow(&m->tangent, 4 * nv, sizeof(float), 1) ||
        !grow(&m->index, 3 * nt, sizeof(uint32_t), 1) || !grow(&m->slot, nt, sizeof(uint16_t), 1)) {
        free(n);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory cutting emissive triangles",
                       path);
    }
    uint32_t next_v = (uint32_t)m->vertex_count;
    int old_count = m->triangle_count, next_t = old_count;
    for (int t = 0; t < old_count; t++) {
        int k = n[t];
        if (k <= 1)
            continue;
        uint32_t v[3];
        memcpy(v, m->index + 3 * (size_t)t, sizeof v);
        uint32_t first = next_v;
        for (int i = 0; i <= k; i++)
            for (int j = 0; i + j <= k; j++) {
                uint32_t w = grid_vertex(v, k, i, j, first);
                if (w >= first)
                    make_vertex(m, v, (double)i / k, (double)j / k, w);
            }
        next_v += (uint32_t)((k + 1) * (k + 2) / 2 - 3);
        uint16_t slot = m->slot ? m->slot[t] : 0;
        int piece = 0;
        for (int i = 0; i < k; i++)
            for (int j = 0; i + j < k; j++)
                for (int down = 0; down < 2 && (!down || i + j < k - 1); down++) {
                    /* The first piece takes the triangle's place. */
                    int out = piece++ == 0 ? t : next_t++;
                    uint32_t *f = m->index + 3 * (size_t)out;
                    /* Both kinds wind as the whole triangle does. */
                    if (!down) {
                        f[0] = grid_vertex(v, k, i, j, first);
                        f[1] = grid_vertex(v, k, i + 1, j, first);
                        f[2] = grid_vertex(v, k, i, j + 1, first);
                    } else {
                        f[0] = grid_vertex(v, k, i + 1, j, first);
                        f[1] = grid_vertex(v, k, i + 1, j + 1, first);
                        f[2] = grid_vertex(v, k, i, j + 1, first);
                    }
                    if (m->slot)
                        m->slot[out] = slot;
                }
    }
    free(n);
    m->vertex_count = (int)nv;
    m->triangle_count = (int)nt;
    *added = (int)more_t;
    return ZT_OK;
}
