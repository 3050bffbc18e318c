/* The environment map (light/env_map.h): the latitude-longitude mapping in
 * both directions, the texel lookup, and the importance sampling of the
 * map by luminance x solid angle through a marginal cdf over rows and a
 * conditional cdf over each row's columns. */
#include "light/env_map.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/sincos_turn.h"

#define ENV_PI 3.14159265358979323846
/* The largest float below 1: where [0, 1) inputs and outputs are clamped. */
#define ENV_BELOW_ONE 0x1.fffffep-1f
/* How far (radians) a sampled direction stays inside its texel's edges. */
#define ENV_MARGIN 4e-6

/* Luminance (Rec. 709 weights, as f3_luminance) in double, so that a map of
 * values near FLT_MAX does not overflow; the weights and the pdf use this
 * one function, which keeps them consistent. */
static inline double texel_luminance(const float *rgb)
{
    return 0.2126 * (double)rgb[0] + 0.7152 * (double)rgb[1] + 0.0722 * (double)rgb[2];
}

/* Solid angle of any texel of row j: (2 pi / W) (cos theta0 - cos theta1). */
static double row_solid_angle(int j, int width, int height)
{
    return 2.0 * ENV_PI / width *
           (cos(ENV_PI * j / height) - cos(ENV_PI * (j + 1) / height));
}

/* x into [0, 1): NaN and negatives give 0. */
static inline float clamp_unit(float x)
{
    return x > 0.0f ? (x < ENV_BELOW_ONE ? x : ENV_BELOW_ONE) : 0.0f;
}

/* Index floor(x * n) in [0, n - 1], computed on the float before the cast
 * (a cast of NaN or of an out-of-range float is undefined). */
static inline int clamp_index(float x, int n)
{
    float f = x * (float)n;
    return f > 0.0f ? (f < (float)(n - 1) ? (int)f : n - 1) : 0;
}

/* Cumulative sums of w[0..n-1] into cdf[0..n] as floats, normalised by their
 * total (accumulated in double).  Entries after the last nonzero weight
 * divide the unchanged total by itself and so are exactly 1: no zero weight
 * at the end gets an interval from rounding.  An all-zero w gives a uniform
 * cdf, which is never searched. */
static void build_cdf(const double *w, int n, float *cdf)
{
    double total = 0.0;
    for (int i = 0; i < n; i++)
        total += w[i];
    double sum = 0.0;
    cdf[0] = 0.0f;
    for (int i = 0; i < n; i++) {
        sum += w[i];
        cdf[i + 1] = total > 0.0 ? (float)(sum / total) : (float)(i + 1) / (float)n;
    }
    cdf[n] = 1.0f;
}

/* The largest i in [0, n - 1] with cdf[i] <= u, for u in [0, 1): since
 * cdf[0] = 0 and cdf[n] = 1, cdf[i] <= u < cdf[i + 1], so intervals of zero
 * width are never returned.  The halves are chosen by conditional moves: u
 * is random, and a branch on it would be mispredicted half the time. */
static inline int cdf_search(const float *cdf, int n, float u)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        int at_or_below = cdf[mid] <= u;
        lo = at_or_below ? mid : lo;
        hi = at_or_below ? hi : mid - 1;
    }
    return lo;
}

env_map *env_map_create(const float *rgb, int width, int height)
{
    if (width <= 0 || height <= 0)
        return NULL;
    size_t texels = (size_t)width * (size_t)height;
    env_map *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->refs = 1;
    m->rgb = malloc(sizeof(float) * 3 * texels);
    m->marginal_cdf = malloc(sizeof(float) * ((size_t)height + 1));
    m->conditional_cdf = malloc(sizeof(float) * ((size_t)width + 1) * (size_t)height);
    m->row_cos = malloc(sizeof(double) * ((size_t)height + 1));
    /* Scratch: one row's texel weights, then every row's weight. */
    double *texel_weight = malloc(sizeof(double) * ((size_t)width + (size_t)height));
    if (!m->rgb || !m->marginal_cdf || !m->conditional_cdf || !m->row_cos || !texel_weight) {
        free(texel_weight);
        env_map_release(m);
        return NULL;
    }
    double *row_weight = texel_weight + width;
    m->width = width;
    m->height = height;
    memcpy(m->rgb, rgb, sizeof(float) * 3 * texels);
    for (int j = 0; j <= height; j++)
        m->row_cos[j] = cos(ENV_PI * j / height);

    /* Within a row every texel has the same solid angle, so the row's
     * conditional cdf is over luminance alone, and the row's weight is its
     * luminance sum times that solid angle. */
    double weight_sum = 0.0;
    for (int j = 0; j < height; j++) {
        const float *row = m->rgb + (size_t)j * (size_t)width * 3;
        double lum_sum = 0.0;
        for (int i = 0; i < width; i++) {
            texel_weight[i] = texel_luminance(row + 3 * (size_t)i);
            lum_sum += texel_weight[i];
        }
        build_cdf(texel_weight, width, m->conditional_cdf + (size_t)j * ((size_t)width + 1));
        row_weight[j] = lum_sum * row_solid_angle(j, width, height);
        weight_sum += row_weight[j];
    }
    build_cdf(row_weight, height, m->marginal_cdf);
    free(texel_weight);
    m->weight_sum = weight_sum;
    m->mean_luminance = weight_sum / (4.0 * ENV_PI);
    return m;
}

/* The maps are made, shared and released on one thread (scene loading and
 * renderer setup), so the count is a plain int, not an atomic. */
env_map *env_map_retain(env_map *m)
{
    m->refs++;
    return m;
}

void env_map_release(env_map *m)
{
    if (!m || --m->refs > 0)
        return;
    free(m->rgb);
    free(m->marginal_cdf);
    free(m->conditional_cdf);
    free(m->row_cos);
    free(m);
}

void env_map_uv(vec3f d, float *u, float *v)
{
    /* Azimuth 0 along -z, pi/2 along +x.  atan2f may return a float pi a
     * hair beyond the exact one and 0.5 + 0.5 rounds to 1, so the result
     * is wrapped and then clamped into [0, 1); both ends are the seam. */
    float uu = 0.5f + atan2f(d.x, -d.z) * (float)(0.5 / ENV_PI);
    if (uu >= 1.0f)
        uu -= 1.0f;
    *u = clamp_unit(uu);
    /* The polar angle as atan2 of the horizontal length and y rather than
     * acos(y): acos loses most digits near the poles, where y is close to
     * +-1, and the first and last rows of a large map are that close. */
    float theta = atan2f(sqrtf(d.x * d.x + d.z * d.z), d.y);
    *v = clamp_unit(theta * (float)(1.0 / ENV_PI));
}

vec3f env_map_direction(float u, float v)
{
    /* theta = pi v is half a turn of v; phi = 2 pi (u - 0.5) is a turn of u
     * less half a turn, which negates its sine and cosine. */
    float st, ct, s, c;
    sincos_turn(0.5f * v, &st, &ct);
    sincos_turn(u, &s, &c);
    return f3(-st * s, ct, st * c);
}

/* The texel holding direction d. */
static inline const float *texel_of(const env_map *m, vec3f d)
{
    float u, v;
    env_map_uv(d, &u, &v);
    int i = clamp_index(u, m->width), j = clamp_index(v, m->height);
    return m->rgb + 3 * ((size_t)j * (size_t)m->width + (size_t)i);
}

vec3f env_map_radiance(const env_map *m, vec3f d)
{
    const float *t = texel_of(m, d);
    return f3(t[0], t[1], t[2]);
}

float env_map_pdf(const env_map *m, vec3f d)
{
    if (!(m->weight_sum > 0.0))
        return 0.0f;
    /* weight / weight_sum / solid angle, where weight is luminance x
     * solid angle. */
    return (float)(texel_luminance(texel_of(m, d)) / m->weight_sum);
}

vec3f env_map_lookup(const env_map *m, vec3f d, float *pdf)
{
    const float *t = texel_of(m, d);
    *pdf = m->weight_sum > 0.0 ? (float)(texel_luminance(t) / m->weight_sum) : 0.0f;
    return f3(t[0], t[1], t[2]);
}

float env_map_sample(const env_map *m, const float u[2], vec3f *d)
{
    if (!(m->weight_sum > 0.0)) {
        *d = f3(0.0f, 1.0f, 0.0f);
        return 0.0f;
    }
    int w = m->width, h = m->height;
    float u0 = clamp_unit(u[0]), u1 = clamp_unit(u[1]);

    /* The row, then the column within it; each random number is remapped
     * to [0, 1) inside its interval, so a stratified pattern stays
     * stratified within the texel. */
    int j = cdf_search(m->marginal_cdf, h, u0);
    double r0 = m->marginal_cdf[j], r1 = m->marginal_cdf[j + 1];
    double fv = ((double)u0 - r0) / (r1 - r0);
    const float *row_cdf = m->conditional_cdf + (size_t)j * (size_t)(w + 1);
    int i = cdf_search(row_cdf, w, u1);
    double c0 = row_cdf[i], c1 = row_cdf[i + 1];
    double fu = ((double)u1 - c0) / (c1 - c0);

    /* Uniform in solid angle within the texel: u linear, cos theta linear
     * between the row's bounds.  In double, since near the poles cos theta
     * is within a float's rounding of 1 and the sine would be lost. */
    double cos0 = m->row_cos[j], cos1 = m->row_cos[j + 1];
    double ct = cos0 + fv * (cos1 - cos0);
    double uu = (i + fu) / w;
    /* The point is kept ENV_MARGIN radians inside the texel's edges and
     * off the poles, so that the float direction maps back to this texel
     * despite the rounding here and in env_map_uv (up to 6e-7 radians
     * measured, 1.3e-6 by adding up the bounds), and env_map_pdf(d) is the
     * density returned.  The move is far below a texel's size. */
    double sin0 = sqrt((1.0 - cos0) * (1.0 + cos0));
    double sin1 = sqrt((1.0 - cos1) * (1.0 + cos1));
    double pole = 0.5 * ENV_MARGIN * ENV_MARGIN; /* 1 - cos(margin), at a pole */
    double ct_hi = cos0 - ENV_MARGIN * sin0 - pole, ct_lo = cos1 + ENV_MARGIN * sin1 + pole;
    ct = ct_lo < ct_hi ? (ct < ct_hi ? (ct > ct_lo ? ct : ct_lo) : ct_hi) : 0.5 * (cos0 + cos1);
    double u_lo = (double)i / w + ENV_MARGIN / (2.0 * ENV_PI);
    double u_hi = (double)(i + 1) / w - ENV_MARGIN / (2.0 * ENV_PI);
    uu = u_lo < u_hi ? (uu < u_hi ? (uu > u_lo ? uu : u_lo) : u_hi) : (i + 0.5) / w;

    /* ct is in [-1, 1], so both factors are >= 0. */
    double st = sqrt((1.0 - ct) * (1.0 + ct));
    float s, c;
    sincos_turn((float)uu, &s, &c);
    *d = f3(-(float)st * s, (float)ct, (float)st * c);
    /* The density of the chosen texel, as env_map_pdf computes it. */
    const float *t = m->rgb + 3 * ((size_t)j * (size_t)w + (size_t)i);
    return (float)(texel_luminance(t) / m->weight_sum);
}
