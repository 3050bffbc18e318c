/* Light from far away: the "sky" item (a constant colour, an environment
 * map from a file, or the Preetham sky model) and the "sun" item, with the
 * sun placed by a direction or by a place and a local time. */
#include "scene/scene_reader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "light/env_map.h"
#include "light/sky_model.h"
#include "scene/load_values.h"
#include "zonetrace/image.h"

#define DEG (3.14159265358979323846 / 180.0)
/* The sun's default angular diameter, degrees (as seen from the Earth). */
#define SUN_ANGLE_DEFAULT 0.53
#define SUN_ANGLE_MAX 10.0
/* Texels of the map a sky model is drawn into: about 0.7 degrees each, far
 * finer than the model's gradients. */
#define SKY_MODEL_WIDTH 512
#define SKY_MODEL_HEIGHT 256

/* A number in [lo, hi] (lo excluded when lo_open). */
static zt_status load_number_in(load_ctx *ctx, jref ref, double lo, double hi, int lo_open,
                                const char *what, double *out)
{
    if (load_number(ctx, ref, out))
        return ZT_ERR_PARSE;
    if ((lo_open ? *out <= lo : *out < lo) || *out > hi)
        return load_fail(ctx, ref, "out of range: %s must be %s %g and at most %g, not %g",
                         what, lo_open ? "above" : "at least", lo, hi, *out);
    return ZT_OK;
}

/* A non-zero direction, made unit length. */
static zt_status load_direction(load_ctx *ctx, jref ref, const char *what, vec3 *out)
{
    if (load_triple(ctx, ref, out))
        return ZT_ERR_PARSE;
    double len = v3_length(*out);
    if (!(len > 1e-12))
        return load_fail(ctx, ref, "a zero direction: %s must point somewhere", what);
    *out = v3_scale(*out, 1.0 / len);
    return ZT_OK;
}

/* Whether s is exactly `pattern`, with 9 standing for any digit. */
static int fits(const char *s, const char *pattern)
{
    for (; *pattern; s++, pattern++)
        if (*pattern == '9' ? !(*s >= '0' && *s <= '9') : *s != *pattern)
            return 0;
    return *s == '\0';
}

/* "YYYY-MM-DD" */
static zt_status load_date(load_ctx *ctx, jref ref, solar_time *t)
{
    static const int days[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int y, m, d;
    const char *s = json_string_value(ref.value);
    if (!s || !fits(s, "9999-99-99") || sscanf(s, "%4d-%2d-%2d", &y, &m, &d) != 3 ||
        m < 1 || m > 12 || d < 1 || d > days[m - 1] ||
        (m == 2 && d == 29 && !((y % 4 == 0 && y % 100 != 0) || y % 400 == 0)) ||
        y < 1 || y > 9999)
        return load_fail(ctx, ref, "not a date: \"date\" must be a string "
                         "\"YYYY-MM-DD\" such as \"2026-06-21\"");
    t->year = y;
    t->month = m;
    t->day = d;
    return ZT_OK;
}

/* "HH:MM" or "HH:MM:SS", local clock time. */
static zt_status load_time(load_ctx *ctx, jref ref, solar_time *t)
{
    int h = 0, m = 0, sec = 0;
    const char *s = json_string_value(ref.value);
    int ok = s && ((fits(s, "99:99:99") && sscanf(s, "%2d:%2d:%2d", &h, &m, &sec) == 3) ||
                   (fits(s, "99:99") && sscanf(s, "%2d:%2d", &h, &m) == 2));
    if (!ok || h < 0 || h > 23 || m < 0 || m > 59 || sec < 0 || sec > 59)
        return load_fail(ctx, ref, "not a time: \"time\" must be a string \"HH:MM\" "
                         "or \"HH:MM:SS\" (local clock, 24 hours) such as \"15:00\"");
    t->hour = h + m / 60.0 + sec / 3600.0;
    return ZT_OK;
}

/* {"latitude", "longitude", "utc_offset", "date", "time", "north"}: the
 * direction toward the sun at that place and local time. */
static zt_status load_place(load_ctx *ctx, jref ref, vec3 *dir)
{
    static const char *const keys[] = {"latitude", "longitude", "utc_offset", "date", "time",
                                       "north", NULL};
    static const char *const required[] = {"latitude", "longitude", "utc_offset", "date",
                                           "time", NULL};
    if (load_object(ctx, ref, "a place") || load_known_keys(ctx, ref, "a place", keys))
        return ZT_ERR_PARSE;
    for (const char *const *k = required; *k; k++)
        if (load_require(ctx, ref, *k, "a place"))
            return ZT_ERR_PARSE;
    solar_time t;
    memset(&t, 0, sizeof t);
    vec3 north = v3(0, 0, -1);
    jref north_ref = jref_member(ref.value, "north");
    if (load_number_in(ctx, jref_member(ref.value, "latitude"), -90, 90, 0, "a latitude",
                       &t.latitude) ||
        load_number_in(ctx, jref_member(ref.value, "longitude"), -180, 180, 0, "a longitude",
                       &t.longitude) ||
        load_number_in(ctx, jref_member(ref.value, "utc_offset"), -14, 14, 0,
                       "a UTC offset (hours)", &t.utc_offset) ||
        load_date(ctx, jref_member(ref.value, "date"), &t) ||
        load_time(ctx, jref_member(ref.value, "time"), &t) ||
        (north_ref.value && load_direction(ctx, north_ref, "\"north\"", &north)))
        return ZT_ERR_PARSE;
    if (hypot(north.x, north.z) < 1e-6)
        return load_fail(ctx, north_ref, "\"north\" must not point straight up or down: "
                         "it is a direction on the ground");
    double elevation, azimuth;
    solar_position(&t, &elevation, &azimuth);
    if (elevation <= 0)
        return load_fail(ctx, ref, "the sun is below the horizon at that place and time "
                         "(elevation %.1f degrees): daylight needs a sun above it", elevation);
    *dir = solar_direction(elevation, azimuth, north);
    return ZT_OK;
}

/* The sun's direction from "direction" or "place" (exactly one of them) in
 * body; where names the object in messages. */
static zt_status load_sun_position(load_ctx *ctx, jref body, const char *dir_key,
                                   const char *where, vec3 *dir, int *given)
{
    jref direction = jref_member(body.value, dir_key);
    jref place = jref_member(body.value, "place");
    *given = direction.value || place.value;
    if (direction.value && place.value)
        return load_fail(ctx, place, "%s takes either \"%s\" or \"place\", not both",
                         where, dir_key);
    if (direction.value)
        return load_direction(ctx, direction, "the sun's direction", dir);
    if (place.value)
        return load_place(ctx, place, dir);
    return ZT_OK;
}

zt_status load_sun(load_ctx *ctx, jref item, jref body)
{
    static const char *const keys[] = {"direction", "place", "irradiance", "angle", NULL};
    if (ctx->scene->sun.present)
        return load_fail(ctx, item, "a second sun: only one is allowed");
    if (load_object(ctx, body, "sun") || load_known_keys(ctx, body, "sun", keys) ||
        load_require(ctx, body, "irradiance", "sun"))
        return ZT_ERR_PARSE;
    sun_light sun = {.present = 1, .angle = SUN_ANGLE_DEFAULT * DEG};
    int given;
    if (load_sun_position(ctx, body, "direction", "a sun", &sun.direction, &given))
        return ZT_ERR_PARSE;
    if (!given)
        return load_fail(ctx, body, "missing \"direction\" (or \"place\") in sun");
    if (load_radiance(ctx, jref_member(body.value, "irradiance"), &sun.irradiance))
        return ZT_ERR_PARSE;
    jref angle = jref_member(body.value, "angle");
    if (angle.value) {
        double deg;
        if (load_number_in(ctx, angle, 0, SUN_ANGLE_MAX, 1, "the sun's angle (degrees)", &deg))
            return ZT_ERR_PARSE;
        sun.angle = deg * DEG;
    }
    ctx->scene->sun = sun;
    return ZT_OK;
}

/* Non-zero when every texel is finite and >= 0; else names the first bad
 * one in *bx, *by. */
static int texels_ok(const zt_image *im, int *bx, int *by)
{
    for (int y = 0; y < im->height; y++)
        for (int x = 0; x < im->width; x++) {
            const float *p = zt_image_pixel(im, x, y);
            for (int c = 0; c < 3; c++)
                if (!isfinite(p[c]) || p[c] < 0.0f) {
                    *bx = x;
                    *by = y;
                    return 0;
                }
        }
    return 1;
}

static zt_status load_sky_file(load_ctx *ctx, jref file)
{
    if (!json_is_string(file.value) || json_string_length(file.value) == 0)
        return load_fail(ctx, file, "wrong type: a sky's file must be a non-empty string "
                         "(an image path relative to the scene file)");
    char path[4096];
    load_file_path(ctx, json_string_value(file.value), path, sizeof path);
    zt_image *im = NULL;
    zt_error ierr;
    zt_error_clear(&ierr);
    zt_status st = zt_image_read(path, &im, &ierr);
    if (st != ZT_OK)
        return load_fail_status(ctx, st == ZT_ERR_READ ? ZT_ERR_READ : ZT_ERR_PARSE, file,
                                "sky: %s", ierr.message);
    int bx = 0, by = 0;
    if (im->width < 1 || im->height < 1 || !texels_ok(im, &bx, &by)) {
        const float *p = im->width > 0 ? zt_image_pixel(im, bx, by) : NULL;
        zt_image_release(im);
        if (!p)
            return load_fail(ctx, file, "sky: %s has no texels", path);
        return load_fail(ctx, file, "sky: %s: texel (%d, %d) is not a radiance (NaN, "
                         "infinite or negative)", path, bx, by);
    }
    env_map *m = env_map_create(im->pixels, im->width, im->height);
    zt_image_release(im);
    if (!m)
        return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN, "out of memory");
    ctx->scene->sky_map = m;
    return ZT_OK;
}

zt_status load_sky(load_ctx *ctx, jref item, jref body)
{
    static const char *const keys[] = {"color", "file", "model", "strength", "rotate",
                                       "turbidity", "sun_direction", "place", NULL};
    zt_scene *sc = ctx->scene;
    if (sc->has_sky)
        return load_fail(ctx, item, "a second sky: only one is allowed");
    if (load_object(ctx, body, "sky") || load_known_keys(ctx, body, "sky", keys))
        return ZT_ERR_PARSE;
    jref color = jref_member(body.value, "color");
    jref file = jref_member(body.value, "file");
    jref model = jref_member(body.value, "model");
    int forms = !!color.value + !!file.value + !!model.value;
    if (forms == 0)
        return load_fail(ctx, body, "missing \"color\", \"file\" or \"model\" in sky");
    if (forms > 1)
        return load_fail(ctx, color.value && file.value ? file : model,
                         "a sky is one of a \"color\", a \"file\" or a \"model\": they "
                         "cannot be mixed");
    sc->has_sky = 1;
    if (color.value) {
        static const char *const map_keys[] = {"strength", "rotate", "turbidity",
                                               "sun_direction", "place", NULL};
        for (const char *const *k = map_keys; *k; k++)
            if (json_object_get(body.value, *k))
                return load_fail_key(ctx, body.value, *k, "\"%s\" belongs to a sky from a "
                                     "file or a model, not to a sky of one colour", *k);
        return load_radiance(ctx, color, &sc->sky);
    }
    sc->sky_strength = 1;
    jref strength = jref_member(body.value, "strength");
    jref rotate = jref_member(body.value, "rotate");
    double deg = 0;
    if ((strength.value && load_number_in(ctx, strength, 0, LOAD_NUMBER_LIMIT, 0,
                                          "a sky's strength", &sc->sky_strength)) ||
        (rotate.value && load_number(ctx, rotate, &deg)))
        return ZT_ERR_PARSE;
    sc->sky_rotate = fmod(deg, 360.0) * DEG;
    if (file.value) {
        static const char *const model_keys[] = {"turbidity", "sun_direction", "place", NULL};
        for (const char *const *k = model_keys; *k; k++)
            if (json_object_get(body.value, *k))
                return load_fail_key(ctx, body.value, *k, "\"%s\" belongs to a sky model, "
                                     "not to a sky from a file", *k);
        return load_sky_file(ctx, file);
    }
    if (!json_is_string(model.value) || strcmp(json_string_value(model.value), "preetham") != 0)
        return load_fail(ctx, model, "unknown sky model: the model must be \"preetham\"");
    if (rotate.value)
        return load_fail_key(ctx, body.value, "rotate", "a sky model follows its sun and "
                             "takes no \"rotate\"");
    sky_model_request *rq = &ctx->sky_model;
    rq->pending = 1;
    rq->where = model;
    rq->turbidity = 3;
    jref turbidity = jref_member(body.value, "turbidity");
    if (turbidity.value && load_number_in(ctx, turbidity, 1.7, 10, 0,
                                          "the turbidity (Preetham's range)", &rq->turbidity))
        return ZT_ERR_PARSE;
    return load_sun_position(ctx, body, "sun_direction", "a sky model", &rq->sun,
                             &rq->has_sun);
}

zt_status load_daylight_finish(load_ctx *ctx)
{
    sky_model_request *rq = &ctx->sky_model;
    if (!rq->pending)
        return ZT_OK;
    zt_scene *sc = ctx->scene;
    vec3 sun = rq->sun;
    if (!rq->has_sun) {
        if (!sc->sun.present)
            return load_fail(ctx, rq->where, "a sky model needs the sun's position: add "
                             "a sun item, or give the sky a \"sun_direction\" or a \"place\"");
        sun = sc->sun.direction;
    }
    preetham_sky model;
    preetham_init(&model, rq->turbidity, sun);
    float *rgb = malloc((size_t)SKY_MODEL_WIDTH * SKY_MODEL_HEIGHT * 3 * sizeof(float));
    if (!rgb)
        return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN, "out of memory");
    /* Each texel takes the model at its centre; the lower half (below the
     * horizon) is black: the ground is the scene's to model. */
    for (int j = 0; j < SKY_MODEL_HEIGHT; j++)
        for (int i = 0; i < SKY_MODEL_WIDTH; i++) {
            float *p = rgb + ((size_t)j * SKY_MODEL_WIDTH + i) * 3;
            vec3f d = env_map_direction((i + 0.5f) / SKY_MODEL_WIDTH,
                                        (j + 0.5f) / SKY_MODEL_HEIGHT);
            vec3 l = d.y > 0 ? preetham_radiance(&model, v3(d.x, d.y, d.z)) : v3(0, 0, 0);
            p[0] = (float)l.x;
            p[1] = (float)l.y;
            p[2] = (float)l.z;
        }
    sc->sky_map = env_map_create(rgb, SKY_MODEL_WIDTH, SKY_MODEL_HEIGHT);
    free(rgb);
    if (!sc->sky_map)
        return load_fail_offset(ctx, ZT_ERR_MEMORY, SOURCE_OFFSET_UNKNOWN, "out of memory");
    return ZT_OK;
}
