/* The camera: a viewpoint, a screen given by four corners and a pixel grid.
 * The checks rule out screens that cannot give ray directions. */
#include "scene/scene_reader.h"

#include <math.h>

#include "scene/load_values.h"

#define MAX_SIDE 32768
#define MAX_PIXELS (1LL << 28)

/* Relative tolerances of the degeneracy tests (fractions of the screen's
 * edge lengths). */
#define SCREEN_FLATNESS 1e-10
#define VIEWPOINT_CLEARANCE 1e-9

static zt_status load_resolution(load_ctx *ctx, jref ref, zt_camera *out)
{
    if (!json_is_array(ref.value))
        return load_fail(ctx, ref, "wrong type: gridresolution must be "
                         "[width, height], not %s", load_type_name(ref.value));
    if (json_array_size(ref.value) != 2)
        return load_fail(ctx, ref, "wrong length: gridresolution needs 2 "
                         "integers, found %zu", json_array_size(ref.value));
    long long w, h;
    if (load_int(ctx, jref_element(ref.value, 0), 1, MAX_SIDE, &w) ||
        load_int(ctx, jref_element(ref.value, 1), 1, MAX_SIDE, &h))
        return ZT_ERR_PARSE;
    if (w * h > MAX_PIXELS)
        return load_fail(ctx, ref, "resolution out of range: %lldx%lld is "
                         "more than %lld pixels", w, h, MAX_PIXELS);
    out->width = (int)w;
    out->height = (int)h;
    return ZT_OK;
}

/* The screen is the parallelogram of TL, TR and BL; the viewpoint must lie
 * off its plane for the rays to have a direction. */
static zt_status check_screen(load_ctx *ctx, jref screen, jref viewpoint,
                              const vec3 *corner, vec3 eye)
{
    vec3 right = v3_sub(corner[1], corner[0]);
    vec3 down = v3_sub(corner[2], corner[0]);
    double lr = v3_length(right), ld = v3_length(down);
    vec3 n = v3_cross(right, down);
    double ln = v3_length(n);
    if (!(ln > SCREEN_FLATNESS * lr * ld) || lr == 0 || ld == 0)
        return load_fail(ctx, screen, "degenerate screen: top-left, top-right "
                         "and bottom-left corners are collinear");
    double distance = fabs(v3_dot(v3_scale(n, 1.0 / ln), v3_sub(eye, corner[0])));
    if (!(distance > VIEWPOINT_CLEARANCE * fmax(lr, ld)))
        return load_fail(ctx, viewpoint, "viewpoint lies on the screen plane");
    return ZT_OK;
}

/* {"position", "lookat", "up", "fov", "gridresolution"}: an aimed camera. */
static zt_status load_aimed(load_ctx *ctx, jref ref, zt_camera *out)
{
    static const char *const keys[] = {"position", "lookat", "up", "fov", "gridresolution",
                                       NULL};
    if (load_known_keys(ctx, ref, "camera", keys) ||
        load_require(ctx, ref, "position", "camera") ||
        load_require(ctx, ref, "lookat", "camera"))
        return ZT_ERR_PARSE;
    vec3 pos, at, up = v3(0, 1, 0);
    double fov = 40;
    zt_camera cam = {{0}, {{0}}, 512, 512};
    jref pos_ref = jref_member(ref.value, "position");
    jref up_ref = jref_member(ref.value, "up");
    jref fov_ref = jref_member(ref.value, "fov");
    jref grid = jref_member(ref.value, "gridresolution");
    if (load_triple(ctx, pos_ref, &pos) ||
        load_triple(ctx, jref_member(ref.value, "lookat"), &at) ||
        (up_ref.value && load_triple(ctx, up_ref, &up)) ||
        (fov_ref.value && load_number(ctx, fov_ref, &fov)) ||
        (grid.value && load_resolution(ctx, grid, &cam)))
        return ZT_ERR_PARSE;
    if (!(fov > 0 && fov < 180))
        return load_fail(ctx, fov_ref, "fov out of range: %g (the vertical field of view, "
                         "in degrees, between 0 and 180)", fov);
    double p[3], a[3], u[3];
    v3_store(pos, p);
    v3_store(at, a);
    v3_store(up, u);
    zt_error cerr;
    zt_error_clear(&cerr);
    if (zt_camera_look_at(&cam, p, a, u, fov, cam.width, cam.height, &cerr) != ZT_OK)
        return load_fail(ctx, pos_ref, "degenerate camera: %s", cerr.message);
    *out = cam;
    return ZT_OK;
}

zt_status load_camera(load_ctx *ctx, jref ref, zt_camera *out)
{
    static const char *const keys[] = {"viewpoint", "screen", "gridresolution", NULL};
    if (load_object(ctx, ref, "camera"))
        return ZT_ERR_PARSE;
    if (json_object_get(ref.value, "position") || json_object_get(ref.value, "lookat")) {
        if (json_object_get(ref.value, "viewpoint") || json_object_get(ref.value, "screen"))
            return load_fail(ctx, ref, "a camera is given either by viewpoint and screen or "
                             "by position and lookat, not both");
        return load_aimed(ctx, ref, out);
    }
    if (load_known_keys(ctx, ref, "camera", keys) ||
        load_require(ctx, ref, "viewpoint", "camera") ||
        load_require(ctx, ref, "screen", "camera") ||
        load_require(ctx, ref, "gridresolution", "camera"))
        return ZT_ERR_PARSE;
    jref viewpoint = jref_member(ref.value, "viewpoint");
    jref screen = jref_member(ref.value, "screen");
    vec3 eye, corner[4];
    if (load_triple(ctx, viewpoint, &eye) ||
        load_triples(ctx, screen, 4, corner) ||
        check_screen(ctx, screen, viewpoint, corner, eye) ||
        load_resolution(ctx, jref_member(ref.value, "gridresolution"), out))
        return ZT_ERR_PARSE;
    v3_store(eye, out->viewpoint);
    for (int i = 0; i < 4; i++)
        v3_store(corner[i], out->screen[i]);
    return ZT_OK;
}
