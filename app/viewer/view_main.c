/* zonetrace view: options, the window, keys and mouse, the HUD, replay
 * scripts and screenshots.  The rendering itself is in view_worker.c. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <SDL.h>

#include "../cli/cli.h"
#include "../cli/parse.h"
#include "viewer.h"

#define MAX_HELD 32
#define KEY_TICK 0.01            /* the originals polled held keys every 10 ms */
#define SCREENSHOT_TIMEOUT 60.0  /* a script's screenshot waits at most this */
#define MOUSE_TURN 0.004         /* radians per pixel of drag */

static void view_usage(FILE *f)
{
    fprintf(f,
"usage: zonetrace view SCENE [options]\n"
"\n"
"Shows SCENE in a window as it renders, progressively, and lets you move\n"
"through it (docs/viewer.md).\n"
"\n"
"      --method M        path (default) or zone\n"
"      --motions FILE    move lights and things, and the camera along a path,\n"
"                        as FILE says (the originals' motions file)\n"
"      --fps N           frames per second to aim for (default 10)\n"
"      --hud             show the HUD at start (u or Tab toggles it)\n"
"      --size WxH        pixel grid (default: the scene's gridresolution)\n"
"      --depth D         at most D scattering events (default 16; zone 3)\n"
"      --level L         only light that scattered exactly L times\n"
"      --lights-off LIST switch off lights by index, e.g. 0,2\n"
"      --exposure EV     fixed exposure (default: automatic)\n"
"      --threads T       render threads (default: all cores)\n"
"      --seed S          sampler and brownian motion seed (default 0)\n"
"      --move-step U     scene units per 10 ms a held move key travels (default 1)\n"
"      --turn-step R     radians per 10 ms a held turn key turns (default 0.1)\n"
"      --replay FILE     run the timed commands in FILE (see docs/viewer.md)\n"
"      --script TEXT     the same, commands separated by ';'\n"
"      --exit-after S    quit after S seconds\n"
"  -v, --verbose         print fps and samples per pixel every second\n"
"  -h, --help            this text\n"
"\n"
"Keys: w/s forward/back, a/d or h/l left/right, j/k down/up, arrows;\n"
"x/X y/Y z/Z turn; uppercase moves 10x; drag the mouse to look around;\n"
"m path/zone; 0-9 one level, - or ` all levels; F1-F8 (or Shift+1-8) switch\n"
"light 0-7 off/on; space pause motions; e lock exposure, [ ] darker/brighter;\n"
"r reset the camera; p screenshot; u or Tab HUD; q or Esc quit.\n");
}

typedef struct held_key {
    int id;            /* scancode, or 0x10000 + key for script keys */
    int kind;          /* 1 move, 2 turn */
    int axis;          /* move: 0 forward, 1 right, 2 up; turn: 0 right, 1 up, 2 back */
    double amount;     /* steps (signed, 10 for uppercase) */
    int script_clock;  /* timed by the script's clock, not the wall clock */
    double press;
    long steps_done;
} held_key;

typedef struct viewer {
    /* options */
    const char *scene_path;
    double fps;
    int depth, depth_given;
    int threads;
    unsigned long long seed;
    double move_step, turn_step;
    double exit_after;
    int verbose;
    int hud;
    /* state */
    zt_scene *scene0;
    zt_motions *motions;
    int path_failed;        /* the camera path degenerated: no longer followed */
    zt_camera cam, cam_home;
    int light_count;
    int width, height;
    view_shared sh;
    view_worker worker;
    int worker_running;
    SDL_Window *win;
    SDL_Surface *frame;
    float *linear;          /* the displayed frame's radiance */
    view_frame shown;       /* its metadata */
    uint8_t lut[4096];
    int exposure_fixed;
    double exposure;
    held_key held[MAX_HELD];
    int held_count;
    int dragging;
    int quit;
    int exit_code;
    double start;
    /* script */
    script sc;
    int sc_next;
    double sc_waited;       /* time the script clock stood still */
    int sc_waiting;         /* index of a screenshot that waits, or -1 */
    double sc_wait_start;
    /* HUD figures */
    double fps_t0;
    int fps_frames;
    double fps_value;
    uint64_t last_counted_seq;
    char message[VIEW_MESSAGE_MAX];
    double message_until;
    uint64_t message_seq_seen;
    uint64_t method_forced_seen;
    double report_t0;
    int report_spp;
    double report_restart;
    int screenshot_pending;  /* 'p' pressed */
    double last_present;
    int force_present;       /* redraw at the next tick */
} viewer;

static double script_clock(const viewer *v, double now)
{
    double wait = v->sc_waited;
    if (v->sc_waiting >= 0)
        wait += now - v->sc_wait_start;
    return now - v->start - wait;
}

static void show_message(viewer *v, const char *msg)
{
    v->force_present = 1;
    snprintf(v->message, sizeof v->message, "%s", msg);
    v->message_until = view_now() + 6.0;
    fprintf(stderr, "zonetrace view: %s\n", msg);
}

/* ---- requests to the worker ---- */

/* Sends v->cam, the camera path's at motion time t (or t < 0: moved by a
 * key or the mouse). */
static void push_camera_at(viewer *v, double t)
{
    pthread_mutex_lock(&v->sh.lock);
    v->sh.req.camera = v->cam;
    v->sh.req.camera_time = t;
    atomic_fetch_add(&v->sh.cam_epoch, 1);
    pthread_cond_signal(&v->sh.wake);
    pthread_mutex_unlock(&v->sh.lock);
}

static void push_camera(viewer *v)
{
    push_camera_at(v, -1);
}

/* Changes the options under the lock; fn edits the request. */
static void push_options(viewer *v, void (*fn)(viewer *, view_request *, int), int arg)
{
    pthread_mutex_lock(&v->sh.lock);
    fn(v, &v->sh.req, arg);
    atomic_fetch_add(&v->sh.opt_epoch, 1);
    pthread_cond_signal(&v->sh.wake);
    pthread_mutex_unlock(&v->sh.lock);
}

static void opt_method(viewer *v, view_request *r, int unused)
{
    (void)unused;
    r->method = r->method == ZT_METHOD_PATH ? ZT_METHOD_ZONE : ZT_METHOD_PATH;
    if (!v->depth_given)
        r->depth = r->method == ZT_METHOD_ZONE ? 3 : 16;
}

static void opt_level(viewer *v, view_request *r, int level)
{
    (void)v;
    r->level = level;
}

static void opt_light(viewer *v, view_request *r, int light)
{
    (void)v;
    for (int i = 0; i < r->lights_off_count; i++)
        if (r->lights_off[i] == light) {
            r->lights_off[i] = r->lights_off[--r->lights_off_count];
            return;
        }
    if (r->lights_off_count < ZT_MAX_LIGHTS_OFF)
        r->lights_off[r->lights_off_count++] = light;
}

static void toggle_pause(viewer *v)
{
    double now = view_now();
    pthread_mutex_lock(&v->sh.lock);
    view_request *r = &v->sh.req;
    if (r->motions_paused) {
        r->motion_origin = now - r->motion_time_paused;
        r->motions_paused = 0;
    } else {
        r->motion_time_paused = view_motion_time(r, now);
        r->motions_paused = 1;
    }
    pthread_cond_signal(&v->sh.wake);
    pthread_mutex_unlock(&v->sh.lock);
}

/* ---- camera moves from held keys ---- */

static int key_motion(int key, int shift, held_key *h)
{
    int lower = key < 128 ? tolower(key) : key;
    int upper = key < 128 && isupper(key);
    double step = upper || shift ? 10.0 : 1.0;
    h->kind = 1;
    switch (lower) {
    case 'w': h->axis = 0; h->amount = step; return 1;
    case 's': h->axis = 0; h->amount = -step; return 1;
    case 'a': case 'h': h->axis = 1; h->amount = -step; return 1;
    case 'd': case 'l': h->axis = 1; h->amount = step; return 1;
    case 'j': h->axis = 2; h->amount = -step; return 1;
    case 'k': h->axis = 2; h->amount = step; return 1;
    case VKEY_UP: h->axis = 2; h->amount = step; return 1;
    case VKEY_DOWN: h->axis = 2; h->amount = -step; return 1;
    case VKEY_LEFT: h->axis = 1; h->amount = -step; return 1;
    case VKEY_RIGHT: h->axis = 1; h->amount = step; return 1;
    default: break;
    }
    /* turns: lowercase is +0.1 rad, uppercase -0.1 rad (as the originals) */
    h->kind = 2;
    double sign = upper ? -1.0 : 1.0;
    switch (lower) {
    case 'x': h->axis = 0; h->amount = sign; return 1;
    case 'y': h->axis = 1; h->amount = sign; return 1;
    case 'z': h->axis = 2; h->amount = sign; return 1;
    default: return 0;
    }
}

/* Applies n steps of a held key to the camera. */
static void apply_steps(viewer *v, const held_key *h, long n)
{
    for (long i = 0; i < n; i++) {
        double ax[4][3];
        vcam_axes(&v->cam, ax[1], ax[2], ax[3], ax[0]);
        if (h->kind == 1) {
            /* forward, right, up */
            const double *dir = h->axis == 0 ? ax[0] : h->axis == 1 ? ax[1] : ax[2];
            double d[3];
            for (int k = 0; k < 3; k++)
                d[k] = dir[k] * h->amount * v->move_step;
            vcam_translate(&v->cam, d);
        } else {
            /* right (pitch), up (yaw), back (roll) */
            const double *axis = ax[1 + h->axis];
            vcam_rotate(&v->cam, axis, h->amount * v->turn_step);
        }
    }
}

/* Brings a held key's steps up to time t: one at the press and one every
 * 10 ms after it. */
static int held_catch_up(viewer *v, held_key *h, double t)
{
    long due = 1 + (long)floor((t - h->press) / KEY_TICK + 1e-9);
    if (due <= h->steps_done)
        return 0;
    apply_steps(v, h, due - h->steps_done);
    h->steps_done = due;
    return 1;
}

static void take_screenshot(viewer *v, const char *path);

/* With a camera path, the camera follows it while the motions play: every
 * frame tick sets the path's camera at the motion time, over any key or
 * mouse move.  While they are paused the keys and the mouse move it from
 * where the path left it. */
static void follow_path(viewer *v, double now)
{
    if (v->path_failed || !zt_motions_camera_path(v->motions, NULL))
        return;
    pthread_mutex_lock(&v->sh.lock);
    int paused = v->sh.req.motions_paused;
    double t = view_motion_time(&v->sh.req, now);
    pthread_mutex_unlock(&v->sh.lock);
    if (paused)
        return;
    zt_camera cam;
    zt_error err;
    if (zt_motions_camera(v->motions, v->scene0, t, &cam, &err) != ZT_OK) {
        v->path_failed = 1; /* said once; the camera stays where it was */
        show_message(v, err.message);
        return;
    }
    if (memcmp(&cam, &v->cam, sizeof cam) == 0)
        return; /* holding still after the last key: the picture converges */
    v->cam = cam;
    push_camera_at(v, t);
}

static void reset_camera(viewer *v)
{
    v->cam = v->cam_home;
    push_camera(v);
}

/* A key went down (repeat events are dropped before this). */
static void key_down(viewer *v, int id, int key, int shift, int script_clock_used, double t)
{
    held_key h;
    memset(&h, 0, sizeof h);
    v->force_present = 1;
    if (key_motion(key, shift, &h)) {
        for (int i = 0; i < v->held_count; i++)
            if (v->held[i].id == id)
                return;
        if (v->held_count == MAX_HELD)
            return;
        h.id = id;
        h.script_clock = script_clock_used;
        h.press = t;
        v->held[v->held_count++] = h;
        if (held_catch_up(v, &v->held[v->held_count - 1], t))
            push_camera(v);
        return;
    }
    if (key >= VKEY_F1 && key < VKEY_F1 + 12) {
        int light = key - VKEY_F1;
        if (light >= 8)
            return;
        if (light >= v->light_count) {
            char msg[96];
            snprintf(msg, sizeof msg, "no light %d: the scene has %d", light, v->light_count);
            show_message(v, msg);
            return;
        }
        push_options(v, opt_light, light);
        return;
    }
    switch (key) {
    case 'q': case 'Q': case VKEY_ESCAPE:
        v->quit = 1;
        break;
    case 'm': case 'M':
        push_options(v, opt_method, 0);
        break;
    case '-': case '`': case '~': case '_':
        push_options(v, opt_level, -1);
        break;
    case ' ':
        if (v->motions)
            toggle_pause(v);
        else
            show_message(v, "no motions to pause (--motions FILE)");
        break;
    case 'e': case 'E':
        if (v->exposure_fixed) {
            v->exposure_fixed = 0;
        } else {
            v->exposure_fixed = 1;
            v->exposure = v->shown.auto_exposure;
        }
        break;
    case '[': case ']':
        if (!v->exposure_fixed) {
            v->exposure_fixed = 1;
            v->exposure = v->shown.auto_exposure;
        }
        v->exposure += key == '[' ? -0.5 : 0.5;
        break;
    case 'r': case 'R':
        reset_camera(v);
        break;
    case 'p': case 'P':
        v->screenshot_pending = 1;
        break;
    case 'u': case 'U': case VKEY_TAB:
        v->hud = !v->hud;
        break;
    default:
        if (key >= '0' && key <= '9')
            push_options(v, opt_level, key - '0');
        break;
    }
}

static void key_up(viewer *v, int id, double t)
{
    for (int i = 0; i < v->held_count; i++)
        if (v->held[i].id == id) {
            if (held_catch_up(v, &v->held[i], t))
                push_camera(v);
            v->held[i] = v->held[--v->held_count];
            return;
        }
}

static void update_held(viewer *v, double now)
{
    int changed = 0;
    double st = script_clock(v, now);
    for (int i = 0; i < v->held_count; i++)
        changed |= held_catch_up(v, &v->held[i], v->held[i].script_clock ? st : now);
    if (changed)
        push_camera(v);
}

static void drag(viewer *v, double dx, double dy)
{
    double right[3], up[3], back[3], fwd[3];
    vcam_axes(&v->cam, right, up, back, fwd);
    if (dx != 0)
        vcam_rotate(&v->cam, up, -dx * MOUSE_TURN);
    vcam_axes(&v->cam, right, up, back, fwd);
    if (dy != 0)
        vcam_rotate(&v->cam, right, -dy * MOUSE_TURN);
    push_camera(v);
}

/* ---- SDL events ---- */

static int sdl_key(const SDL_Keysym *ks, int *shift)
{
    SDL_Keycode k = ks->sym;
    *shift = (ks->mod & KMOD_SHIFT) != 0;
    if (k >= 'a' && k <= 'z') {
        int up = *shift ^ ((ks->mod & KMOD_CAPS) != 0);
        return up ? toupper((int)k) : (int)k;
    }
    if (k >= '1' && k <= '8' && *shift)
        return VKEY_F1 + (int)(k - '1');
    if (k >= SDLK_F1 && k <= SDLK_F12)
        return VKEY_F1 + (int)(k - SDLK_F1);
    switch (k) {
    case SDLK_UP: return VKEY_UP;
    case SDLK_DOWN: return VKEY_DOWN;
    case SDLK_LEFT: return VKEY_LEFT;
    case SDLK_RIGHT: return VKEY_RIGHT;
    case SDLK_ESCAPE: return VKEY_ESCAPE;
    case SDLK_TAB: return VKEY_TAB;
    default: break;
    }
    if (k >= 32 && k < 127)
        return (int)k;
    return VKEY_NONE;
}

static void handle_event(viewer *v, const SDL_Event *e)
{
    double now = view_now();
    switch (e->type) {
    case SDL_QUIT:
        v->quit = 1;
        break;
    case SDL_KEYDOWN: {
        if (e->key.repeat)
            break;
        int shift;
        int key = sdl_key(&e->key.keysym, &shift);
        if (key != VKEY_NONE)
            key_down(v, e->key.keysym.scancode, key, shift, 0, now);
        break;
    }
    case SDL_KEYUP:
        key_up(v, e->key.keysym.scancode, now);
        break;
    case SDL_MOUSEBUTTONDOWN:
        if (e->button.button == SDL_BUTTON_LEFT)
            v->dragging = 1;
        break;
    case SDL_MOUSEBUTTONUP:
        if (e->button.button == SDL_BUTTON_LEFT)
            v->dragging = 0;
        break;
    case SDL_MOUSEMOTION:
        if (v->dragging && (e->motion.state & SDL_BUTTON_LMASK))
            drag(v, e->motion.xrel, e->motion.yrel);
        break;
    default:
        break;
    }
}

/* ---- the frame ---- */

static void build_lut(viewer *v)
{
    for (int i = 0; i < 4096; i++) {
        double x = (i + 0.5) / 4096.0;
        double s = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
        double b = floor(s * 255.0 + 0.5);
        v->lut[i] = (uint8_t)(b > 255 ? 255 : b < 0 ? 0 : b);
    }
}

static inline uint32_t to_byte(const viewer *v, float x)
{
    if (!(x > 0.0f))
        return 0;
    if (x >= 1.0f)
        return 255;
    return v->lut[(int)(x * 4096.0f)];
}

static double current_exposure(const viewer *v)
{
    return v->exposure_fixed ? v->exposure : v->shown.auto_exposure;
}

static void format_count(char *buf, size_t n, double x)
{
    if (x >= 1e9)
        snprintf(buf, n, "%.2fG", x / 1e9);
    else if (x >= 1e6)
        snprintf(buf, n, "%.2fM", x / 1e6);
    else if (x >= 1e3)
        snprintf(buf, n, "%.1fk", x / 1e3);
    else
        snprintf(buf, n, "%.0f", x);
}

static void draw_hud(viewer *v, uint32_t *px, int pitch, double now)
{
    view_request req;
    pthread_mutex_lock(&v->sh.lock);
    req = v->sh.req;
    pthread_mutex_unlock(&v->sh.lock);
    char lines[12][160];
    int n = 0;
    char rays[32];
    format_count(rays, sizeof rays, (double)v->shown.rays);
    snprintf(lines[n++], sizeof lines[0], "%.1f fps", v->fps_value);
    snprintf(lines[n++], sizeof lines[0], "%d spp  %s rays", v->shown.spp, rays);
    snprintf(lines[n++], sizeof lines[0], "%.1f s since change",
             v->shown.seq ? now - v->shown.restart_time : 0.0);
    char level[32];
    if (req.level < 0)
        snprintf(level, sizeof level, "all levels");
    else
        snprintf(level, sizeof level, "level %d", req.level);
    int depth = req.level > req.depth ? req.level : req.depth;
    char preview[48] = "";
    if (v->shown.method == ZT_METHOD_ZONE && v->shown.preview)
        snprintf(preview, sizeof preview, v->shown.preview > 1 ? "  preview 1/%d" : "  preview",
                 v->shown.preview);
    else if (v->shown.method == ZT_METHOD_ZONE)
        snprintf(preview, sizeof preview, "  full image");
    snprintf(lines[n++], sizeof lines[0], "%s  %s  depth %d%s",
             v->shown.method == ZT_METHOD_ZONE ? "zone" : "path", level, depth, preview);
    snprintf(lines[n++], sizeof lines[0], "EV %+.1f %s", current_exposure(v),
             v->exposure_fixed ? "fixed" : "auto");
    if (v->motions)
        snprintf(lines[n++], sizeof lines[0], "t %.2f s%s", v->shown.motion_time,
                 req.motions_paused ? " paused" : "");
    if (req.lights_off_count > 0) {
        int len = snprintf(lines[n], sizeof lines[0], "lights off:");
        for (int i = 0; i < req.lights_off_count && len < 140; i++)
            len += snprintf(lines[n] + len, sizeof lines[0] - (size_t)len, " %d",
                            req.lights_off[i]);
        n++;
    }
    int scale = v->width >= 400 ? 2 : 1;
    if (now < v->message_until) {
        /* the message, wrapped at spaces to the window's width */
        int cols = (v->width - 8 * scale) / (FONT_CELL_W * scale);
        if (cols < 8)
            cols = 8;
        if (cols > 150)
            cols = 150;
        const char *p = v->message;
        while (*p && n < 12) {
            int len = (int)strlen(p);
            int take = len;
            if (len > cols) {
                take = cols;
                while (take > cols / 2 && p[take] != ' ')
                    take--;
                if (p[take] != ' ')
                    take = cols;
            }
            snprintf(lines[n++], sizeof lines[0], "%.*s", take, p);
            p += take;
            while (*p == ' ')
                p++;
        }
    }
    uint32_t yellow = 0xFFFFFF66u, shadow = 0xFF000000u;
    for (int i = 0; i < n; i++)
        font_draw(px, v->width, v->height, pitch, 4 * scale,
                  3 * scale + i * FONT_CELL_H * scale + i * scale, scale, yellow,
                  shadow, lines[i]);
}

static void update_title(viewer *v)
{
    char title[ZT_ERROR_MESSAGE_MAX + 160];
    const char *base = strrchr(v->scene_path, '/');
    base = base ? base + 1 : v->scene_path;
    int n = snprintf(title, sizeof title, "zonetrace: %s [%s]", base,
                     v->shown.method == ZT_METHOD_ZONE ? "zone" : "path");
    if (view_now() < v->message_until && n > 0 && (size_t)n < sizeof title)
        snprintf(title + n, sizeof title - (size_t)n, " - %s", v->message);
    SDL_SetWindowTitle(v->win, title);
}

/* Takes the newest published frame, if any; returns 1 if it is new. */
static int fetch_frame(viewer *v)
{
    int fresh = 0;
    pthread_mutex_lock(&v->sh.lock);
    if (v->sh.front.seq != v->shown.seq) {
        float *keep = v->shown.linear;
        v->shown = v->sh.front;
        v->shown.linear = keep;
        memcpy(v->linear, v->sh.front.linear,
               (size_t)v->width * (size_t)v->height * 3 * sizeof(float));
        fresh = 1;
    }
    if (v->sh.method_forced_seq != v->method_forced_seen) {
        /* the worker fell back to the path tracer: its default depth */
        v->method_forced_seen = v->sh.method_forced_seq;
        if (!v->depth_given && v->sh.req.depth != 16) {
            v->sh.req.depth = 16;
            atomic_fetch_add(&v->sh.opt_epoch, 1);
            pthread_cond_signal(&v->sh.wake);
        }
    }
    if (v->sh.message_seq != v->message_seq_seen) {
        v->message_seq_seen = v->sh.message_seq;
        char msg[VIEW_MESSAGE_MAX];
        snprintf(msg, sizeof msg, "%s", v->sh.message);
        pthread_mutex_unlock(&v->sh.lock);
        show_message(v, msg);
        pthread_mutex_lock(&v->sh.lock);
    }
    pthread_mutex_unlock(&v->sh.lock);
    return fresh;
}

static void present(viewer *v, double now, int fresh)
{
    v->last_present = now;
    v->force_present = 0;
    if (fresh && v->shown.seq != v->last_counted_seq) {
        v->fps_frames++;
        v->last_counted_seq = v->shown.seq;
    }
    if (now - v->fps_t0 >= 1.0) {
        v->fps_value = v->fps_frames / (now - v->fps_t0);
        v->fps_frames = 0;
        v->fps_t0 = now;
    }
    SDL_LockSurface(v->frame);
    uint32_t *px = v->frame->pixels;
    int pitch = v->frame->pitch / 4;
    float scale = (float)exp2(current_exposure(v));
    for (int y = 0; y < v->height; y++) {
        const float *src = v->linear + (size_t)y * (size_t)v->width * 3;
        uint32_t *dst = px + (size_t)y * (size_t)pitch;
        for (int x = 0; x < v->width; x++) {
            uint32_t r = to_byte(v, src[3 * x] * scale);
            uint32_t g = to_byte(v, src[3 * x + 1] * scale);
            uint32_t b = to_byte(v, src[3 * x + 2] * scale);
            dst[x] = 0xFF000000u | r << 16 | g << 8 | b;
        }
    }
    if (v->hud)
        draw_hud(v, px, pitch, now);
    SDL_UnlockSurface(v->frame);
    SDL_Surface *ws = SDL_GetWindowSurface(v->win);
    if (ws) {
        SDL_BlitSurface(v->frame, NULL, ws, NULL);
        SDL_UpdateWindowSurface(v->win);
    }
    update_title(v);
}

/* Writes the displayed frame, as read back from the window's surface. */
static void take_screenshot(viewer *v, const char *path)
{
    SDL_Surface *ws = SDL_GetWindowSurface(v->win);
    SDL_Surface *rgb = ws ? SDL_ConvertSurfaceFormat(ws, SDL_PIXELFORMAT_RGB24, 0) : NULL;
    if (!rgb) {
        char msg[300];
        snprintf(msg, sizeof msg, "cannot read the window for a screenshot: %s", SDL_GetError());
        show_message(v, msg);
        v->exit_code = EXIT_FAILURE_OTHER;
        return;
    }
    int w = rgb->w < v->width ? rgb->w : v->width;
    int h = rgb->h < v->height ? rgb->h : v->height;
    zt_image *img = zt_image_create(w, h);
    if (img) {
        SDL_LockSurface(rgb);
        for (int y = 0; y < h; y++) {
            const uint8_t *row = (const uint8_t *)rgb->pixels + (size_t)y * (size_t)rgb->pitch;
            float *dst = zt_image_pixel(img, 0, y);
            for (int i = 0; i < w * 3; i++)
                dst[i] = row[i] / 255.0f;
        }
        SDL_UnlockSurface(rgb);
        /* gamma 1 and exposure 0 write the bytes back exactly */
        zt_tonemap tm = {0, 0.0, 1.0};
        zt_error err;
        zt_error_clear(&err);
        char msg[VIEW_MESSAGE_MAX];
        if (zt_image_write(img, path, &tm, &err) != ZT_OK) {
            snprintf(msg, sizeof msg, "screenshot failed: %s", err.message);
            v->exit_code = EXIT_UNWRITABLE;
        } else {
            snprintf(msg, sizeof msg, "saved %s (%d spp)", path, v->shown.spp);
        }
        show_message(v, msg);
        zt_image_release(img);
    }
    SDL_FreeSurface(rgb);
}

static void screenshot_key(viewer *v)
{
    char name[64];
    struct stat st;
    for (int i = 1; i <= 9999; i++) {
        snprintf(name, sizeof name, "zonetrace-shot-%04d.png", i);
        if (stat(name, &st) != 0) {
            take_screenshot(v, name);
            return;
        }
    }
    show_message(v, "screenshot: zonetrace-shot-0001..9999.png all exist");
}

/* Whether the displayed frame shows what is asked for now. */
static int frame_is_current(viewer *v, int min_spp)
{
    uint64_t ce = atomic_load(&v->sh.cam_epoch), oe = atomic_load(&v->sh.opt_epoch);
    int spp_needed = v->shown.method == ZT_METHOD_ZONE ? 1 : min_spp;
    return v->shown.seq > 0 && v->shown.cam_epoch == ce && v->shown.opt_epoch == oe &&
           v->shown.spp >= spp_needed;
}

/* Runs the script's commands that are due; a screenshot waits for a
 * current frame (the script's clock stands still meanwhile). */
static void run_script(viewer *v, double now)
{
    if (v->sc_waiting >= 0) {
        script_event *e = &v->sc.events[v->sc_waiting];
        int timed_out = now - v->sc_wait_start > SCREENSHOT_TIMEOUT;
        if (!frame_is_current(v, e->min_spp) && !timed_out)
            return;
        if (timed_out)
            fprintf(stderr, "zonetrace view: screenshot %s: the frame was not "
                            "ready after %.0f s; taking it as it is\n", e->path,
                    SCREENSHOT_TIMEOUT);
        take_screenshot(v, e->path);
        v->sc_waited += now - v->sc_wait_start;
        v->sc_waiting = -1;
        v->sc_next++;
    }
    while (v->sc_next < v->sc.count && v->sc_waiting < 0) {
        script_event *e = &v->sc.events[v->sc_next];
        double st = script_clock(v, now);
        if (e->time > st)
            break;
        switch (e->op) {
        case SCRIPT_KEY: {
            int shift = 0;
            int id = 0x10000 + e->key;
            key_down(v, id, e->key, shift, 1, e->time);
            break;
        }
        case SCRIPT_RELEASE:
            key_up(v, 0x10000 + e->key, e->time);
            break;
        case SCRIPT_DRAG:
            drag(v, e->dx, e->dy);
            break;
        case SCRIPT_QUIT:
            v->quit = 1;
            break;
        case SCRIPT_SCREENSHOT:
            v->sc_waiting = v->sc_next;
            v->sc_wait_start = now;
            return; /* taken once a current frame is shown */
        }
        v->sc_next++;
    }
}

static void report(viewer *v, double now)
{
    if (!v->verbose || now - v->report_t0 < 1.0)
        return;
    double rate = 0;
    if (v->report_restart == v->shown.restart_time && v->shown.spp >= v->report_spp)
        rate = (v->shown.spp - v->report_spp) / (now - v->report_t0);
    char rays[32];
    format_count(rays, sizeof rays, (double)v->shown.rays);
    fprintf(stderr, "view: %.1f fps, %d spp (%.1f spp/s), %s rays, %.1f s since "
                    "change, %s, batch %.3f s\n", v->fps_value, v->shown.spp, rate, rays,
            v->shown.seq ? now - v->shown.restart_time : 0.0,
            v->shown.method == ZT_METHOD_ZONE ? "zone" : "path", v->shown.batch_seconds);
    v->report_t0 = now;
    v->report_spp = v->shown.spp;
    v->report_restart = v->shown.restart_time;
}

/* ---- options ---- */

enum {
    OPT_METHOD = 256, OPT_MOTIONS, OPT_FPS, OPT_HUD, OPT_SIZE, OPT_DEPTH, OPT_LEVEL,
    OPT_LIGHTS_OFF, OPT_EXPOSURE, OPT_THREADS, OPT_SEED, OPT_MOVE_STEP, OPT_TURN_STEP,
    OPT_REPLAY, OPT_SCRIPT, OPT_EXIT_AFTER
};

static const struct option long_options[] = {
    {"method", required_argument, 0, OPT_METHOD},
    {"motions", required_argument, 0, OPT_MOTIONS},
    {"fps", required_argument, 0, OPT_FPS},
    {"hud", no_argument, 0, OPT_HUD},
    {"size", required_argument, 0, OPT_SIZE},
    {"depth", required_argument, 0, OPT_DEPTH},
    {"level", required_argument, 0, OPT_LEVEL},
    {"lights-off", required_argument, 0, OPT_LIGHTS_OFF},
    {"exposure", required_argument, 0, OPT_EXPOSURE},
    {"threads", required_argument, 0, OPT_THREADS},
    {"seed", required_argument, 0, OPT_SEED},
    {"move-step", required_argument, 0, OPT_MOVE_STEP},
    {"turn-step", required_argument, 0, OPT_TURN_STEP},
    {"replay", required_argument, 0, OPT_REPLAY},
    {"script", required_argument, 0, OPT_SCRIPT},
    {"exit-after", required_argument, 0, OPT_EXIT_AFTER},
    {"verbose", no_argument, 0, 'v'},
    {"help", no_argument, 0, 'h'},
    {0, 0, 0, 0}
};

typedef struct view_args {
    int method;
    const char *motions_path;
    int width, height;
    int level;
    int lights_off[ZT_MAX_LIGHTS_OFF];
    int lights_off_count;
    const char *replay_path;
    const char *script_text;
} view_args;

static int parse_args(int argc, char **argv, viewer *v, view_args *a)
{
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":vh", long_options, NULL)) != -1) {
        int ok = 1;
        switch (c) {
        case OPT_METHOD:
            if (!strcmp(optarg, "path")) a->method = ZT_METHOD_PATH;
            else if (!strcmp(optarg, "zone")) a->method = ZT_METHOD_ZONE;
            else { cli_error("--method expects 'path' or 'zone', not '%s'", optarg); ok = 0; }
            break;
        case OPT_MOTIONS: a->motions_path = optarg; break;
        case OPT_FPS: ok = parse_double("--fps", optarg, 0.1, 1000, &v->fps); break;
        case OPT_HUD: v->hud = 1; break;
        case OPT_SIZE: ok = parse_size("--size", optarg, &a->width, &a->height); break;
        case OPT_DEPTH:
            ok = parse_int("--depth", optarg, 0, 1024, &v->depth);
            v->depth_given = 1;
            break;
        case OPT_LEVEL: ok = parse_int("--level", optarg, 0, 1024, &a->level); break;
        case OPT_LIGHTS_OFF:
            ok = parse_int_list("--lights-off", optarg, a->lights_off, ZT_MAX_LIGHTS_OFF,
                                &a->lights_off_count);
            break;
        case OPT_EXPOSURE:
            ok = parse_double("--exposure", optarg, -100, 100, &v->exposure);
            v->exposure_fixed = 1;
            break;
        case OPT_THREADS: ok = parse_int("--threads", optarg, 1, 1024, &v->threads); break;
        case OPT_SEED: ok = parse_u64("--seed", optarg, &v->seed); break;
        case OPT_MOVE_STEP: ok = parse_double("--move-step", optarg, 0, 1e9, &v->move_step); break;
        case OPT_TURN_STEP: ok = parse_double("--turn-step", optarg, 0, 10, &v->turn_step); break;
        case OPT_REPLAY: a->replay_path = optarg; break;
        case OPT_SCRIPT: a->script_text = optarg; break;
        case OPT_EXIT_AFTER:
            ok = parse_double("--exit-after", optarg, 0, 1e9, &v->exit_after);
            break;
        case 'v': v->verbose = 1; break;
        case 'h': view_usage(stdout); return -1;
        case ':': cli_error("option '%s' needs a value", argv[optind - 1]); ok = 0; break;
        default: cli_error("unknown option '%s'", argv[optind - 1]); ok = 0; break;
        }
        if (!ok) {
            fprintf(stderr, "Try 'zonetrace view --help'.\n");
            return 0;
        }
    }
    if (optind >= argc) {
        cli_error("no scene file given");
        fprintf(stderr, "Try 'zonetrace view --help'.\n");
        return 0;
    }
    if (argc - optind > 1) {
        cli_error("one scene file at a time ('%s' and '%s' given)", argv[optind],
                  argv[optind + 1]);
        return 0;
    }
    if (a->replay_path && a->script_text) {
        cli_error("--replay and --script cannot be used together");
        return 0;
    }
    v->scene_path = argv[optind];
    return 1;
}

/* Loads the scene, the motions and the script; returns an exit code. */
static int load_inputs(viewer *v, view_args *a)
{
    zt_error err;
    zt_error_clear(&err);
    zt_status st = zt_scene_load_file(v->scene_path, &v->scene0, &err);
    if (st != ZT_OK) {
        fprintf(stderr, "zonetrace: %s\n", err.message);
        return cli_exit_code(st);
    }
    v->cam = zt_scene_get_camera(v->scene0);
    if (a->width) {
        if (zt_camera_set_resolution(&v->cam, a->width, a->height, &err) != ZT_OK) {
            cli_error("%s", err.message);
            return EXIT_USAGE;
        }
        zt_scene_set_camera(v->scene0, &v->cam);
    }
    v->cam_home = v->cam;
    v->width = v->cam.width;
    v->height = v->cam.height;
    v->light_count = zt_scene_object_count(v->scene0, ZT_OBJECT_LIGHT);
    for (int i = 0; i < a->lights_off_count; i++)
        if (a->lights_off[i] >= v->light_count) {
            cli_error("--lights-off: no light %d (the scene has %d)", a->lights_off[i],
                      v->light_count);
            return EXIT_USAGE;
        }
    if (a->motions_path) {
        st = zt_motions_load_file(a->motions_path, &v->motions, &err);
        if (st == ZT_OK)
            st = zt_motions_check(v->motions, v->scene0, &err);
        /* the path's camera at time 0 from the first picture on */
        if (st == ZT_OK && zt_motions_camera_path(v->motions, NULL))
            st = zt_motions_camera(v->motions, v->scene0, 0.0, &v->cam, &err);
        if (st != ZT_OK) {
            fprintf(stderr, "zonetrace: %s\n", err.message);
            return cli_exit_code(st);
        }
        v->cam_home = v->cam;
    }
    if (a->replay_path) {
        size_t len = 0;
        FILE *f = fopen(a->replay_path, "rb");
        char *text = NULL;
        if (f) {
            text = malloc(1 << 20);
            if (text) {
                len = fread(text, 1, (1 << 20) - 1, f);
                text[len] = '\0';
            }
            fclose(f);
        }
        if (!text) {
            cli_error("cannot read the replay file '%s'", a->replay_path);
            return EXIT_UNREADABLE;
        }
        int ok = script_parse(text, a->replay_path, &v->sc);
        free(text);
        if (!ok)
            return EXIT_UNPARSEABLE;
    } else if (a->script_text) {
        if (!script_parse(a->script_text, "--script", &v->sc))
            return EXIT_USAGE;
    }
    return EXIT_OK;
}

static int open_window(viewer *v)
{
    /* The window's pixels go to X directly: no OpenGL texture in between
     * (under Xvfb that would start Mesa's software renderer for nothing).
     * SDL_FRAMEBUFFER_ACCELERATION in the environment still wins. */
    SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        cli_error("cannot open a window: %s (is there a display? xvfb-run can "
                  "provide one)", SDL_GetError());
        return 0;
    }
    v->win = SDL_CreateWindow("zonetrace", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED,
                              v->width, v->height, 0);
    if (!v->win) {
        cli_error("cannot open a window: %s", SDL_GetError());
        return 0;
    }
    v->frame = SDL_CreateRGBSurfaceWithFormat(0, v->width, v->height, 32,
                                              SDL_PIXELFORMAT_ARGB8888);
    if (!v->frame) {
        cli_error("cannot create the frame: %s", SDL_GetError());
        return 0;
    }
    v->sh.publish_event = SDL_RegisterEvents(1);
    if (v->sh.publish_event == (uint32_t)-1) {
        cli_error("cannot register an SDL event");
        return 0;
    }
    return 1;
}

static void main_loop(viewer *v)
{
    double period = 1.0 / v->fps;
    double next = view_now();
    v->fps_t0 = v->report_t0 = next;
    while (!v->quit) {
        double now = view_now();
        int wait_ms = (int)ceil((next - now) * 1000.0);
        SDL_Event e;
        int publish = 0;
        if (wait_ms > 0 && SDL_WaitEventTimeout(&e, wait_ms)) {
            if (e.type == v->sh.publish_event)
                publish = 1;
            else
                handle_event(v, &e);
        }
        while (SDL_PollEvent(&e)) {
            if (e.type == v->sh.publish_event)
                publish = 1;
            else
                handle_event(v, &e);
        }
        now = view_now();
        if (v->exit_after > 0 && now - v->start >= v->exit_after)
            v->quit = 1;
        if (now < next && !publish)
            continue;
        if (now >= next) {
            next += period;
            if (next < now)
                next = now + period;
        }
        update_held(v, now);
        follow_path(v, now);
        /* A new frame is shown at once; otherwise the window is redrawn
         * only for the HUD's figures and after keys, so a high --fps does
         * not spend the time on redrawing the same picture. */
        int fresh = fetch_frame(v);
        if (fresh || v->force_present || now - v->last_present >= 0.25)
            present(v, now, fresh);
        if (v->screenshot_pending) {
            v->screenshot_pending = 0;
            screenshot_key(v);
        }
        run_script(v, now);
        report(v, now);
    }
    /* A script may press 'p' and quit in one step (when a screenshot
     * before them waited for samples): the shot is still taken. */
    if (v->screenshot_pending) {
        v->screenshot_pending = 0;
        screenshot_key(v);
    }
}

int cli_view(int argc, char **argv)
{
    viewer *v = calloc(1, sizeof *v);
    if (!v) {
        cli_error("out of memory");
        return EXIT_MEMORY;
    }
    v->fps = 10;
    v->move_step = 1.0;
    v->turn_step = 0.1;
    v->sc_waiting = -1;
    v->depth = 16;
    view_args a;
    memset(&a, 0, sizeof a);
    a.method = ZT_METHOD_PATH;
    a.level = -1;
    int code = EXIT_OK;
    int pr = parse_args(argc, argv, v, &a);
    if (pr <= 0) {
        free(v);
        return pr < 0 ? EXIT_OK : EXIT_USAGE;
    }
    if (!v->depth_given && a.method == ZT_METHOD_ZONE)
        v->depth = 3;
    if (a.level > v->depth) {
        if (v->depth_given) {
            cli_error("--level %d is deeper than --depth %d (levels count from 0)",
                      a.level, v->depth);
            free(v);
            return EXIT_USAGE;
        }
        v->depth = a.level;
    }
    code = load_inputs(v, &a);
    int sdl_started = 0;
    if (code == EXIT_OK) {
        build_lut(v);
        size_t n = (size_t)v->width * (size_t)v->height * 3;
        v->linear = calloc(n, sizeof(float));
        v->sh.front.linear = calloc(n, sizeof(float));
        v->sh.front.width = v->width;
        v->sh.front.height = v->height;
        if (!v->linear || !v->sh.front.linear) {
            cli_error("out of memory");
            code = EXIT_FAILURE_OTHER;
        }
    }
    if (code == EXIT_OK) {
        sdl_started = 1;
        if (!open_window(v))
            code = EXIT_FAILURE_OTHER;
    }
    if (code == EXIT_OK) {
        pthread_mutex_init(&v->sh.lock, NULL);
        pthread_cond_init(&v->sh.wake, NULL);
        view_request *r = &v->sh.req;
        r->camera = v->cam;
        r->method = a.method;
        r->level = a.level;
        r->depth = v->depth;
        memcpy(r->lights_off, a.lights_off, sizeof r->lights_off);
        r->lights_off_count = a.lights_off_count;
        v->start = view_now();
        r->motion_origin = v->start;
        r->camera_time = zt_motions_camera_path(v->motions, NULL) ? 0.0 : -1.0;
        v->shown.method = a.method;
        v->worker.shared = &v->sh;
        v->worker.cfg.scene0 = v->scene0;
        v->worker.cfg.motions = v->motions;
        v->worker.cfg.seed = v->seed;
        v->worker.cfg.threads = v->threads;
        v->worker.cfg.frame_seconds = 1.0 / v->fps;
        v->worker.cfg.verbose = v->verbose;
        if (!view_worker_start(&v->worker)) {
            cli_error("cannot start the render thread");
            code = EXIT_FAILURE_OTHER;
        } else {
            v->worker_running = 1;
            main_loop(v);
            code = v->exit_code;
            pthread_mutex_lock(&v->sh.lock);
            atomic_store(&v->sh.quit, 1);
            v->sh.stop_build = 1;
            pthread_cond_broadcast(&v->sh.wake);
            pthread_mutex_unlock(&v->sh.lock);
            view_worker_join(&v->worker);
            if (v->sc_waiting >= 0)
                fprintf(stderr, "zonetrace view: quit before screenshot %s was taken\n",
                        v->sc.events[v->sc_waiting].path);
        }
        pthread_cond_destroy(&v->sh.wake);
        pthread_mutex_destroy(&v->sh.lock);
    }
    if (v->frame)
        SDL_FreeSurface(v->frame);
    if (v->win)
        SDL_DestroyWindow(v->win);
    if (sdl_started)
        SDL_Quit();
    script_free(&v->sc);
    free(v->linear);
    free(v->sh.front.linear);
    zt_motions_release(v->motions);
    zt_scene_release(v->scene0);
    free(v);
    return code;
}
