/* The environment map (light/env_map.h): its orientation and the
 * uv <-> direction round trip; that the sampling density integrates to 1
 * and env_map_pdf repeats what env_map_sample returned, also for samples
 * on texel edges; that black texels are never drawn; that samples are
 * distributed as luminance x solid angle, and uniformly in solid angle
 * within a texel; that the estimator of the irradiance under the map is
 * unbiased (against the exact integral over the texels); the black map;
 * the poles and the seam, where indices must stay in range (run under
 * ZT_SANITIZE for the reads); and the reference count.
 *
 * Needs nothing from ../shared. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>

#include "light/env_map.h"
#include "util/r2.h"

#define PI 3.14159265358979323846

/* A deterministic value in [0, 1) from an integer (an integer hash). */
static double hash01(unsigned x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return (double)(x >> 8) / 16777216.0;
}

static double luminance(const float *t)
{
    return 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
}

/* Solid angle of a texel of row j of a map w x h. */
static double texel_solid_angle(int j, int w, int h)
{
    return 2.0 * PI / w * (cos(PI * j / h) - cos(PI * (j + 1) / h));
}

/* The texel (column *i, row *j) that env_map_uv puts d in. */
static void texel_of(const env_map *m, vec3f d, int *i, int *j)
{
    float u, v;
    env_map_uv(d, &u, &v);
    assert_true(u >= 0.0f && u < 1.0f && v >= 0.0f && v < 1.0f);
    *i = (int)(u * (float)m->width);
    *j = (int)(v * (float)m->height);
    *i = *i < m->width ? *i : m->width - 1;
    *j = *j < m->height ? *j : m->height - 1;
}

static vec3f texel_centre(int i, int j, int w, int h)
{
    return env_map_direction(((float)i + 0.5f) / (float)w, ((float)j + 0.5f) / (float)h);
}

static env_map *make_map(const float *rgb, int w, int h)
{
    env_map *m = env_map_create(rgb, w, h);
    assert_non_null(m);
    return m;
}

/* Point k of the 2^16-point Hammersley set (k / 2^16 and k's bits
 * reversed, at the centres of their strips): a (0, 16, 2)-net in base 2,
 * so each cell of the regular 256 x 256 grid holds one point, as in a
 * stratified grid, while u[0] takes 2^16 values, not the grid's 256 that
 * would step over every row of small weight in the marginal cdf. */
#define SAMPLES 65536
static void stratified_point(unsigned k, float u[2])
{
    unsigned r = 0;
    for (int b = 0; b < 16; b++)
        r |= ((k >> b) & 1u) << (15 - b);
    u[0] = ((float)k + 0.5f) / (float)SAMPLES;
    u[1] = ((float)r + 0.5f) / (float)SAMPLES;
}

/* Texel (i, j) of a 4 x 2 map holds (i, j, 1): the direction between two
 * axes lands in the texel the header's convention names, the axes land
 * on the right u and v, and uv -> direction -> uv returns within 1e-5. */
static void test_orientation(void **state)
{
    (void)state;
    float rgb[4 * 2 * 3];
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 4; i++) {
            float *t = rgb + 3 * (j * 4 + i);
            t[0] = (float)i, t[1] = (float)j, t[2] = 1.0f;
        }
    env_map *m = make_map(rgb, 4, 2);
    /* Column centres at u = 1/8, 3/8, 5/8, 7/8: between +z and -x, -x and
     * -z, -z and +x, +x and +z; the top row is y > 0. */
    const struct { float x, z; int column; } cases[] = {
        {-1.0f, 1.0f, 0}, {-1.0f, -1.0f, 1}, {1.0f, -1.0f, 2}, {1.0f, 1.0f, 3},
    };
    for (int k = 0; k < 4; k++)
        for (int row = 0; row < 2; row++) {
            vec3f d = f3_normalize(f3(cases[k].x, row == 0 ? 0.5f : -0.5f, cases[k].z));
            vec3f l = env_map_radiance(m, d);
            assert_float_equal(l.x, (float)cases[k].column, 0.0f);
            assert_float_equal(l.y, (float)row, 0.0f);
        }
    /* Nearly straight up and down. */
    vec3f up = env_map_radiance(m, f3_normalize(f3(1e-3f, 1.0f, -1e-3f)));
    assert_float_equal(up.x, 2.0f, 0.0f);
    assert_float_equal(up.y, 0.0f, 0.0f);
    vec3f down = env_map_radiance(m, f3_normalize(f3(-1e-3f, -1.0f, 1e-3f)));
    assert_float_equal(down.x, 0.0f, 0.0f);
    assert_float_equal(down.y, 1.0f, 0.0f);

    /* The axes: -x at u = 1/4, -z at 1/2, +x at 3/4, all on the horizon. */
    const struct { vec3f d; float u; } axes[] = {
        {{-1.0f, 0.0f, 0.0f}, 0.25f}, {{0.0f, 0.0f, -1.0f}, 0.5f}, {{1.0f, 0.0f, 0.0f}, 0.75f},
    };
    for (int k = 0; k < 3; k++) {
        float u, v;
        env_map_uv(axes[k].d, &u, &v);
        assert_float_equal(u, axes[k].u, 1e-6f);
        assert_float_equal(v, 0.5f, 1e-6f);
        vec3f d = env_map_direction(axes[k].u, 0.5f);
        assert_true(fabsf(d.x - axes[k].d.x) < 1e-6f && fabsf(d.y) < 1e-6f &&
                    fabsf(d.z - axes[k].d.z) < 1e-6f);
    }
    vec3f plus_z = env_map_direction(0.0f, 0.5f), top = env_map_direction(0.3f, 0.0f);
    assert_true(fabsf(plus_z.z - 1.0f) < 1e-6f && fabsf(top.y - 1.0f) < 1e-6f);

    double worst = 0.0;
    for (int a = 1; a < 100; a++)
        for (int b = 1; b < 100; b++) {
            float u0 = (float)a / 100.0f, v0 = (float)b / 100.0f, u, v;
            vec3f d = env_map_direction(u0, v0);
            assert_true(fabsf(f3_length(d) - 1.0f) < 1e-6f);
            env_map_uv(d, &u, &v);
            worst = fmax(worst, fmax(fabs(u - u0), fabs(v - v0)));
        }
    print_message("orientation: uv round trip, largest error %.3g\n", worst);
    assert_true(worst < 1e-5);
    env_map_release(m);
}

/* A 24 x 13 map of hashed colours with a black row and scattered black
 * texels: the pdf at the texel centres times their solid angles sums to 1;
 * weight_sum and mean_luminance are the exact sums; and for 512 samples,
 * and samples on the edges of every texel's intervals, env_map_pdf gives
 * what env_map_sample returned, which is never on a black texel. */
static void test_pdf_normalised(void **state)
{
    (void)state;
    enum { W = 24, H = 13 };
    float rgb[W * H * 3];
    for (int k = 0; k < W * H * 3; k++)
        rgb[k] = (float)(4.0 * hash01((unsigned)k));
    for (int k = 0; k < W * H; k++)
        if (k / W == 5 || hash01(1000u + (unsigned)k) < 0.2)
            rgb[3 * k] = rgb[3 * k + 1] = rgb[3 * k + 2] = 0.0f;
    env_map *m = make_map(rgb, W, H);
    assert_int_equal(m->refs, 1);

    double integral = 0.0, weight = 0.0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double omega = texel_solid_angle(j, W, H);
            integral += env_map_pdf(m, texel_centre(i, j, W, H)) * omega;
            weight += luminance(rgb + 3 * (j * W + i)) * omega;
        }
    print_message("pdf: integral %.9f\n", integral);
    assert_true(fabs(integral - 1.0) < 1e-5);
    assert_true(fabs(m->weight_sum - weight) < 1e-9 * weight);
    assert_true(fabs(m->mean_luminance - weight / (4.0 * PI)) < 1e-9 * weight);
    /* Exactly (cmocka's assert_float_equal allows a relative FLT_EPSILON). */
    assert_true(m->marginal_cdf[H] == 1.0f && m->marginal_cdf[0] == 0.0f);
    for (int j = 0; j < H; j++)
        assert_true(m->conditional_cdf[j * (W + 1) + W] == 1.0f);

    double worst = 0.0;
    for (int k = 0; k < 512; k++) {
        double a, b;
        r2_point(k, &a, &b);
        float u[2] = {(float)a, (float)b};
        vec3f d;
        float pdf = env_map_sample(m, u, &d);
        assert_true(pdf > 0.0f);
        assert_true(fabsf(f3_length(d) - 1.0f) < 1e-5f);
        int i, j;
        texel_of(m, d, &i, &j);
        assert_true(luminance(rgb + 3 * (j * W + i)) > 0.0);
        worst = fmax(worst, fabs(env_map_pdf(m, d) - pdf) / pdf);
    }
    /* Samples on the edges of the texels' cdf intervals, where a direction
     * rounded across the texel's edge would get the neighbour's density. */
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            const float *row = m->conditional_cdf + j * (W + 1);
            float v0 = m->marginal_cdf[j], v1 = m->marginal_cdf[j + 1];
            if (row[i] == row[i + 1] || v0 == v1)
                continue;
            const float us[2][2] = {{v0, nextafterf(v1, 0.0f)},
                                    {row[i], nextafterf(row[i + 1], 0.0f)}};
            for (int e = 0; e < 4; e++) {
                float u[2] = {us[0][e & 1], us[1][e >> 1]};
                vec3f d;
                float pdf = env_map_sample(m, u, &d);
                int ti, tj;
                texel_of(m, d, &ti, &tj);
                assert_int_equal(ti, i);
                assert_int_equal(tj, j);
                worst = fmax(worst, fabs(env_map_pdf(m, d) - pdf) / pdf);
            }
        }
    assert_true(worst < 1e-6);
    env_map_release(m);
}

/* Zero-weight rows and columns at the ends of the cdfs are not chosen even
 * by u = 0 and the largest float below 1. */
static void test_zero_weight_skipped(void **state)
{
    (void)state;
    enum { W = 8, H = 6 };
    float rgb[W * H * 3] = {0};
    /* Only rows 2 and 3, columns 3 and 5 are lit. */
    for (int j = 2; j <= 3; j++)
        for (int i = 3; i <= 5; i += 2)
            for (int c = 0; c < 3; c++)
                rgb[3 * (j * W + i) + c] = 1.0f + (float)i;
    env_map *m = make_map(rgb, W, H);
    const float edge[] = {0.0f, 1e-7f, 0.25f, 0.5f, 0.75f, 0.99999f, 0x1.fffffep-1f};
    int n = sizeof edge / sizeof edge[0];
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++) {
            float u[2] = {edge[a], edge[b]};
            vec3f d;
            float pdf = env_map_sample(m, u, &d);
            int i, j;
            texel_of(m, d, &i, &j);
            assert_true(pdf > 0.0f);
            assert_true(j >= 2 && j <= 3 && (i == 3 || i == 5));
        }
    env_map_release(m);
}

/* A 64 x 32 map of 1 with a 4 x 4 patch of 1e4 near the top: of 2^16
 * stratified samples, the patch takes its share of weight_sum within 1%.
 * The patch is placed where its share is 0.973, so that sampling it always
 * (or not preferring it) fails. */
static void test_distributed_as_luminance(void **state)
{
    (void)state;
    enum { W = 64, H = 32, I0 = 40, J0 = 1 };
    float *rgb = malloc(sizeof(float) * W * H * 3);
    assert_non_null(rgb);
    for (int k = 0; k < W * H; k++) {
        int i = k % W, j = k / W;
        int in = i >= I0 && i < I0 + 4 && j >= J0 && j < J0 + 4;
        rgb[3 * k] = rgb[3 * k + 1] = rgb[3 * k + 2] = in ? 1e4f : 1.0f;
    }
    env_map *m = make_map(rgb, W, H);
    double patch_weight = 0.0;
    for (int j = J0; j < J0 + 4; j++)
        patch_weight += 4.0 * 1e4 * texel_solid_angle(j, W, H);
    double share = patch_weight / m->weight_sum;
    assert_true(share > 0.5 && share < 0.98);

    int hits = 0;
    for (unsigned k = 0; k < SAMPLES; k++) {
        float u[2];
        stratified_point(k, u);
        vec3f d;
        assert_true(env_map_sample(m, u, &d) > 0.0f);
        int i, j;
        texel_of(m, d, &i, &j);
        hits += i >= I0 && i < I0 + 4 && j >= J0 && j < J0 + 4;
    }
    double fraction = (double)hits / SAMPLES;
    print_message("distribution: patch share %.5f, fraction of samples %.5f\n", share, fraction);
    assert_true(fabs(fraction - share) < 0.01 * share);
    env_map_release(m);
    free(rgb);
}

/* Integral of max(0, cos theta) over a texel of row j, in closed form:
 * (2 pi / W) (sin^2 min(theta1, pi/2) - sin^2 theta0) / 2 above the
 * horizon.  Checked against a midpoint sum over 64 steps of theta. */
static double texel_cosine(int j, int w, int h)
{
    double t0 = PI * j / h, t1 = PI * (j + 1) / h;
    if (t0 >= 0.5 * PI)
        return 0.0;
    double top = t1 < 0.5 * PI ? t1 : 0.5 * PI;
    double exact = PI / w * (sin(top) * sin(top) - sin(t0) * sin(t0));
    double sum = 0.0, step = (t1 - t0) / 64;
    for (int s = 0; s < 64; s++) {
        double t = t0 + (s + 0.5) * step;
        sum += fmax(0.0, cos(t)) * sin(t) * step;
    }
    sum *= 2.0 * PI / w;
    assert_true(fabs(sum - exact) < 1e-4 * exact + 1e-12);
    return exact;
}

/* Irradiance on a surface facing +y, the mean of L max(0, y) / pdf over
 * 2^16 stratified samples, against the exact sum over texels.  Returns the
 * largest relative error over the channels. */
static double irradiance_error(const float *rgb, int w, int h)
{
    env_map *m = make_map(rgb, w, h);
    double exact[3] = {0}, estimate[3] = {0};
    for (int j = 0; j < h; j++) {
        double c = texel_cosine(j, w, h);
        for (int i = 0; i < w; i++)
            for (int k = 0; k < 3; k++)
                exact[k] += rgb[3 * (j * w + i) + k] * c;
    }
    for (unsigned s = 0; s < SAMPLES; s++) {
        float u[2];
        stratified_point(s, u);
        vec3f d;
        float pdf = env_map_sample(m, u, &d);
        if (pdf <= 0.0f)
            continue;
        vec3f l = env_map_radiance(m, d);
        double f = fmax(0.0, d.y) / pdf;
        estimate[0] += l.x * f, estimate[1] += l.y * f, estimate[2] += l.z * f;
    }
    double worst = 0.0;
    for (int k = 0; k < 3; k++) {
        estimate[k] /= SAMPLES;
        worst = fmax(worst, fabs(estimate[k] - exact[k]) / exact[k]);
    }
    print_message("irradiance %dx%d: exact %.5f %.5f %.5f, estimate %.5f %.5f %.5f\n", w, h,
                  exact[0], exact[1], exact[2], estimate[0], estimate[1], estimate[2]);
    env_map_release(m);
    return worst;
}

/* The estimator is unbiased: a smooth coloured map with a bright patch
 * across the horizon (31 rows: the middle row straddles it) within 1%,
 * and a constant map, whose irradiance is pi, within 0.5%. */
static void test_irradiance_unbiased(void **state)
{
    (void)state;
    enum { W = 64, H = 31 };
    float *rgb = malloc(sizeof(float) * W * H * 3);
    assert_non_null(rgb);
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double u = (i + 0.5) / W, v = (j + 0.5) / H;
            float *t = rgb + 3 * (j * W + i);
            t[0] = (float)(1.0 + 0.8 * sin(2.0 * PI * u) * sin(PI * v));
            t[1] = (float)(0.5 + 0.4 * cos(3.0 * PI * v));
            t[2] = (float)(2.0 + cos(4.0 * PI * u));
            if (i >= 20 && i < 24 && j >= 13 && j < 17)
                t[0] = t[1] = t[2] = 1e4f;
        }
    double err = irradiance_error(rgb, W, H);
    assert_true(err < 0.01);

    for (int k = 0; k < W * H * 3; k++)
        rgb[k] = 1.0f;
    env_map *m = make_map(rgb, W, H);
    assert_true(fabs(m->mean_luminance - 1.0) < 1e-6);
    env_map_release(m);
    err = irradiance_error(rgb, W, H);
    assert_true(err < 0.005);
    /* The exact sum itself is pi for the constant map. */
    double sum = 0.0;
    for (int j = 0; j < H; j++)
        sum += W * texel_cosine(j, W, H);
    assert_true(fabs(sum - PI) < 1e-9);
    free(rgb);
}

/* Samples are uniform in solid angle within their texel: a 1 x 1 map (one
 * texel, the whole sphere) has the moments of the uniform sphere, and in
 * each texel of a 3 x 2 map the position across (u) and the position down
 * in cos theta are uniform on [0, 1) (mean 1/2, mean square 1/3). */
static void test_uniform_within_texel(void **state)
{
    (void)state;
    float one[3] = {0.3f, 0.6f, 0.9f};
    env_map *m = make_map(one, 1, 1);
    double mean[3] = {0}, square[3] = {0}, upper_cap = 0.0;
    for (unsigned k = 0; k < SAMPLES; k++) {
        float u[2];
        stratified_point(k, u);
        vec3f d;
        float pdf = env_map_sample(m, u, &d);
        assert_float_equal(pdf, 1.0 / (4.0 * PI), 1e-7);
        const float c[3] = {d.x, d.y, d.z};
        for (int a = 0; a < 3; a++)
            mean[a] += c[a], square[a] += (double)c[a] * c[a];
        upper_cap += d.y > 0.5f;
    }
    for (int a = 0; a < 3; a++) {
        assert_true(fabs(mean[a] / SAMPLES) < 1e-3);
        assert_true(fabs(square[a] / SAMPLES - 1.0 / 3.0) < 1e-3);
    }
    assert_true(fabs(upper_cap / SAMPLES - 0.25) < 1e-3);
    env_map_release(m);

    enum { W = 3, H = 2 };
    float rgb[W * H * 3];
    for (int k = 0; k < W * H * 3; k++)
        rgb[k] = 1.0f + (float)(k / 3);
    m = make_map(rgb, W, H);
    double count[W * H] = {0}, across[W * H][2] = {{0}}, down[W * H][2] = {{0}};
    for (unsigned k = 0; k < SAMPLES; k++) {
        float u[2], tu, tv;
        stratified_point(k, u);
        vec3f d;
        env_map_sample(m, u, &d);
        int i, j;
        texel_of(m, d, &i, &j);
        env_map_uv(d, &tu, &tv);
        double x = tu * W - i;
        double c0 = cos(PI * j / H), c1 = cos(PI * (j + 1) / H), y = (c0 - d.y) / (c0 - c1);
        int t = j * W + i;
        count[t] += 1.0;
        across[t][0] += x, across[t][1] += x * x;
        down[t][0] += y, down[t][1] += y * y;
    }
    for (int t = 0; t < W * H; t++) {
        assert_true(count[t] > 1000.0);
        assert_true(fabs(across[t][0] / count[t] - 0.5) < 2e-3);
        assert_true(fabs(across[t][1] / count[t] - 1.0 / 3.0) < 2e-3);
        assert_true(fabs(down[t][0] / count[t] - 0.5) < 2e-3);
        assert_true(fabs(down[t][1] / count[t] - 1.0 / 3.0) < 2e-3);
    }
    env_map_release(m);
}

/* A black map: nothing to sample, density 0 everywhere, no NaN. */
static void test_black_map(void **state)
{
    (void)state;
    float rgb[8 * 4 * 3] = {0};
    env_map *m = make_map(rgb, 8, 4);
    assert_true(m->weight_sum == 0.0 && m->mean_luminance == 0.0);
    const float us[] = {0.0f, 0.3f, 0x1.fffffep-1f};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            float u[2] = {us[a], us[b]};
            vec3f d = f3(NAN, NAN, NAN);
            float pdf = env_map_sample(m, u, &d);
            assert_true(pdf == 0.0f);
            assert_false(isnan(d.x) || isnan(d.y) || isnan(d.z));
        }
    const vec3f dirs[] = {{0, 1, 0}, {0, -1, 0}, {0.6f, 0, 0.8f}, {-0.6f, 0.8f, 0}};
    for (int k = 0; k < 4; k++) {
        assert_true(env_map_pdf(m, dirs[k]) == 0.0f);
        assert_true(f3_is_black(env_map_radiance(m, dirs[k])));
    }
    env_map_release(m);
}

/* The poles, the seam and a direction whose u rounds to 1.0: u and v stay
 * in [0, 1), the texel is the expected one, the reads stay in the image
 * (ASan in a ZT_SANITIZE build), and nothing is NaN. */
static void test_poles_and_seam(void **state)
{
    (void)state;
    enum { W = 7, H = 5 };
    float rgb[W * H * 3];
    for (int k = 0; k < W * H; k++)
        rgb[3 * k] = (float)(k % W), rgb[3 * k + 1] = (float)(k / W), rgb[3 * k + 2] = 1.0f;
    env_map *m = make_map(rgb, W, H);

    /* The premise: before wrapping, this direction's u is 1.0 in float. */
    vec3f seam = f3_normalize(f3(1e-9f, 0.0f, 1.0f));
    assert_true(0.5f + atan2f(seam.x, -seam.z) * (float)(0.5 / PI) == 1.0f);

    const struct { vec3f d; int row; int column; } cases[] = {
        {{0.0f, 1.0f, 0.0f}, 0, -1},         {{0.0f, -1.0f, 0.0f}, H - 1, -1},
        {{-0.0f, 1.0f, -0.0f}, 0, -1},       {{-0.0f, -1.0f, -0.0f}, H - 1, -1},
        {{0.0f, 0.0f, 1.0f}, H / 2, -2},     {{0.0f, 0.0f, -1.0f}, H / 2, W / 2},
        {{-0.0f, 0.0f, 1.0f}, H / 2, -2},    {{1.0f, 0.0f, 0.0f}, H / 2, 5},
        {{-1.0f, 0.0f, 0.0f}, H / 2, 1},     {{0.0f, 1.0000001f, 0.0f}, 0, -1},
        {{-1e-9f, 0.0f, 1.0f}, H / 2, -2},   {{0.0f, 0.0f, 0.0f}, -1, -1},
    };
    int n = sizeof cases / sizeof cases[0];
    for (int k = -1; k < n; k++) {
        vec3f d = k < 0 ? seam : cases[k].d;
        int row = k < 0 ? H / 2 : cases[k].row, column = k < 0 ? -2 : cases[k].column;
        float u, v;
        env_map_uv(d, &u, &v);
        assert_false(isnan(u) || isnan(v));
        assert_true(u >= 0.0f && u < 1.0f && v >= 0.0f && v < 1.0f);
        vec3f l = env_map_radiance(m, d);
        assert_true(l.z == 1.0f);
        if (row >= 0)
            assert_float_equal(l.y, (float)row, 0.0f);
        /* -1: any column (a pole), -2: either side of the seam. */
        if (column >= 0)
            assert_float_equal(l.x, (float)column, 0.0f);
        if (column == -2)
            assert_true(l.x == 0.0f || l.x == (float)(W - 1));
        float pdf = env_map_pdf(m, d);
        assert_true(pdf > 0.0f && isfinite(pdf));
    }
    /* Directions at the grid's extremes come back unit and finite. */
    const float ends[] = {0.0f, 0x1.fffffep-1f, 1.0f};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            vec3f d = env_map_direction(ends[a], ends[b]);
            assert_true(fabsf(f3_length(d) - 1.0f) < 1e-6f);
            (void)env_map_radiance(m, d);
        }
    /* And a dense sweep of the sphere near the poles and the seam. */
    for (int k = 0; k < 20000; k++) {
        double a, b;
        r2_point(k, &a, &b);
        float y = (float)(k & 1 ? 1.0 - 1e-6 * a : -1.0 + 1e-6 * a);
        float r = sqrtf(fmaxf(0.0f, 1.0f - y * y));
        vec3f d = k % 3 ? f3(r * cosf((float)(2 * PI * b)), y, r * sinf((float)(2 * PI * b)))
                        : f3_normalize(f3((float)(1e-7 * (b - 0.5)), (float)(a - 0.5), 1.0f));
        float u, v;
        env_map_uv(d, &u, &v);
        assert_true(u >= 0.0f && u < 1.0f && v >= 0.0f && v < 1.0f);
        assert_true(env_map_radiance(m, d).z == 1.0f);
    }
    env_map_release(m);
}

/* retain and release count references; release(NULL) is a no-op (the
 * frees are checked by ASan's leak check in a ZT_SANITIZE build). */
static void test_references(void **state)
{
    (void)state;
    float rgb[2 * 1 * 3] = {1, 2, 3, 4, 5, 6};
    env_map *m = make_map(rgb, 2, 1);
    rgb[0] = 9.0f;  /* copied: the map does not see this */
    assert_true(m->rgb[0] == 1.0f);
    assert_ptr_equal(env_map_retain(m), m);
    assert_int_equal(m->refs, 2);
    env_map_release(m);
    assert_int_equal(m->refs, 1);
    env_map_release(m);
    env_map_release(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_orientation),
        cmocka_unit_test(test_pdf_normalised),
        cmocka_unit_test(test_zero_weight_skipped),
        cmocka_unit_test(test_distributed_as_luminance),
        cmocka_unit_test(test_irradiance_unbiased),
        cmocka_unit_test(test_uniform_within_texel),
        cmocka_unit_test(test_black_map),
        cmocka_unit_test(test_poles_and_seam),
        cmocka_unit_test(test_references),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
