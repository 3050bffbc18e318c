/* zonetrace view: the interactive SDL2 window (docs/viewer.md).
 *
 * Two threads: the main thread owns the window, the keys, the camera and
 * the HUD; a worker thread owns the renderer and renders progressively,
 * publishing a tonemapped frame about once per frame period.  They share a
 * view_shared under its mutex; the camera and options the main thread asks
 * for carry epochs, so the worker knows when to restart and can cancel a
 * render that has become stale. */
#ifndef ZT_VIEWER_H
#define ZT_VIEWER_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "zonetrace/zonetrace.h"

/* ---- camera moves (view_camera.c) ---- */

/* The camera's unit right, up and backward axes (backward = right x up) and
 * its unit view direction (from the viewpoint to the screen's centre). */
void vcam_axes(const zt_camera *c, double right[3], double up[3],
               double back[3], double forward[3]);

/* Moves viewpoint and screen by d. */
void vcam_translate(zt_camera *c, const double d[3]);

/* Turns the screen about the viewpoint by angle (radians, right-hand rule)
 * about the unit axis. */
void vcam_rotate(zt_camera *c, const double axis[3], double angle);

/* ---- bitmap font (view_font.c) ---- */

/* Draws text into a 32-bit pixel buffer (pitch in pixels) at (x, y), each
 * font pixel scale x scale, with a one-pixel dark shadow.  Returns the
 * width drawn.  Characters outside ASCII 32..126 draw as '?'. */
int font_draw(uint32_t *pixels, int width, int height, int pitch, int x, int y,
              int scale, uint32_t color, uint32_t shadow, const char *text);

/* Cell size of one character at scale 1 (5x7 glyphs in 6x9 cells). */
#define FONT_CELL_W 6
#define FONT_CELL_H 9

/* ---- replay scripts (view_script.c) ---- */

typedef enum script_op {
    SCRIPT_KEY,        /* press key at time (released at time + duration) */
    SCRIPT_RELEASE,    /* the release of a SCRIPT_KEY (added by the parser) */
    SCRIPT_SCREENSHOT, /* save the displayed frame (after it is up to date) */
    SCRIPT_DRAG,       /* a mouse drag by dx, dy pixels */
    SCRIPT_QUIT
} script_op;

typedef struct script_event {
    double time;
    script_op op;
    int key;           /* view key code (VKEY_* or a character) */
    double duration;
    int min_spp;       /* screenshot: wait for at least this many samples */
    double dx, dy;
    char *path;        /* screenshot file */
} script_event;

typedef struct script {
    script_event *events; /* sorted by time (stable) */
    int count;
} script;

/* Parses a script (lines or ';'-separated commands: "TIME key NAME
 * [DURATION]", "TIME screenshot FILE [SPP]", "TIME drag DX DY",
 * "TIME quit"; '#' starts a comment).  name is for messages.  Returns 0 and
 * prints a message on error. */
int script_parse(const char *text, const char *name, script *out);
void script_free(script *s);

/* View key codes beyond characters. */
enum {
    VKEY_NONE = 0,
    VKEY_UP = 0x1000, VKEY_DOWN, VKEY_LEFT, VKEY_RIGHT,
    VKEY_ESCAPE, VKEY_TAB,
    VKEY_F1 = 0x1100 /* .. VKEY_F1 + 11 */
};

/* The key code for a name ("w", "W", "space", "f1", "up", "esc" ...), or
 * VKEY_NONE. */
int script_key_from_name(const char *name);

/* ---- state shared by the main thread and the worker ---- */

#define VIEW_MESSAGE_MAX (ZT_ERROR_MESSAGE_MAX + 64)

typedef struct view_request {
    zt_camera camera;
    int method;              /* ZT_METHOD_* asked for */
    int level;               /* < 0: all */
    int depth;
    int lights_off[ZT_MAX_LIGHTS_OFF];
    int lights_off_count;
    int motions_paused;
    double motion_time_paused; /* the motion time while paused */
    double motion_origin;    /* wall time at which the motion time was 0 */
    double camera_time;      /* the motion time of a camera path's camera,
                                or < 0 (the camera is the keys' or mouse's) */
} view_request;

typedef struct view_frame {
    float *linear;           /* width*height*3, the averaged radiance */
    int width, height;
    uint64_t seq;            /* increases with every publish (0: none yet) */
    uint64_t cam_epoch, opt_epoch;
    int spp;
    uint64_t rays;           /* since the restart */
    double restart_time;     /* wall time the current state started */
    double motion_time;
    int method;              /* what rendered it */
    double auto_exposure;    /* EV the automatic exposure picked */
    double batch_seconds;    /* the last batch's time */
    int preview;             /* zone: a preview at 1/preview of the
                                resolution (moving); 0: the full image */
} view_frame;

typedef struct view_shared {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    view_request req;
    atomic_uint_least64_t cam_epoch, opt_epoch; /* bumped on changes */
    atomic_int quit;
    /* Raised with quit: a zone tracer Phase One under way gives up its
     * level (options.stop) instead of holding the window open. */
    volatile sig_atomic_t stop_build;
    view_frame front;        /* the last published frame */
    /* messages from the worker to the main thread (a method fallback...) */
    char message[VIEW_MESSAGE_MAX];
    uint64_t message_seq;
    int method_forced;       /* the worker had to fall back to this method */
    uint64_t method_forced_seq;
    uint32_t publish_event;  /* SDL user event type posted on publish */
} view_shared;

typedef struct view_worker_config {
    const zt_scene *scene0;       /* the scene at time 0 (the worker's) */
    const zt_motions *motions;    /* NULL: none */
    uint64_t seed;
    int threads;
    double frame_seconds;         /* 1 / fps */
    int verbose;
} view_worker_config;

/* Runs the worker loop until shared->quit (the thread's body). */
typedef struct view_worker {
    view_shared *shared;
    view_worker_config cfg;
    pthread_t thread;
} view_worker;

int view_worker_start(view_worker *w);
void view_worker_join(view_worker *w);

/* Wall-clock seconds (monotonic). */
double view_now(void);

/* The motion time for a request at wall time now. */
double view_motion_time(const view_request *r, double now);

#endif
