/* Replay scripts: timed key presses, drags, screenshots and quit, for
 * tests and demonstrations (docs/viewer.md). */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "../cli/cli.h"
#include "viewer.h"

int script_key_from_name(const char *name)
{
    static const struct { const char *name; int key; } named[] = {
        {"space", ' '}, {"tab", VKEY_TAB}, {"esc", VKEY_ESCAPE},
        {"escape", VKEY_ESCAPE}, {"up", VKEY_UP}, {"down", VKEY_DOWN},
        {"left", VKEY_LEFT}, {"right", VKEY_RIGHT}, {"minus", '-'},
        {"backquote", '`'}, {"hash", '#'}, {"semicolon", ';'},
    };
    if (strlen(name) == 1 && name[0] > ' ' && name[0] < 127)
        return (unsigned char)name[0];
    for (size_t i = 0; i < sizeof named / sizeof named[0]; i++)
        if (strcasecmp(name, named[i].name) == 0)
            return named[i].key;
    if ((name[0] == 'f' || name[0] == 'F') && isdigit((unsigned char)name[1])) {
        char *end;
        long n = strtol(name + 1, &end, 10);
        if (!*end && n >= 1 && n <= 12)
            return VKEY_F1 + (int)(n - 1);
    }
    return VKEY_NONE;
}

static int parse_num(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

static int add_event(script *s, const script_event *e)
{
    script_event *p = realloc(s->events, (size_t)(s->count + 1) * sizeof *p);
    if (!p)
        return 0;
    s->events = p;
    s->events[s->count++] = *e;
    return 1;
}

/* One command: words[0] is the time. */
static int parse_command(char **words, int n, const char *name, int line,
                         script *s)
{
    script_event e;
    memset(&e, 0, sizeof e);
    if (!parse_num(words[0], &e.time) || e.time < 0) {
        cli_error("%s:%d: expected a time in seconds first, not '%s'", name, line, words[0]);
        return 0;
    }
    if (n < 2) {
        cli_error("%s:%d: a command must follow the time", name, line);
        return 0;
    }
    const char *cmd = words[1];
    if (!strcmp(cmd, "key") && (n == 3 || n == 4)) {
        e.op = SCRIPT_KEY;
        e.key = script_key_from_name(words[2]);
        if (e.key == VKEY_NONE) {
            cli_error("%s:%d: unknown key '%s'", name, line, words[2]);
            return 0;
        }
        if (n == 4 && (!parse_num(words[3], &e.duration) || e.duration < 0)) {
            cli_error("%s:%d: expected a duration in seconds, not '%s'", name, line, words[3]);
            return 0;
        }
    } else if (!strcmp(cmd, "screenshot") && (n == 3 || n == 4)) {
        e.op = SCRIPT_SCREENSHOT;
        e.min_spp = 1;
        if (n == 4) {
            double v;
            if (!parse_num(words[3], &v) || v < 1 || v > 1e6 || v != floor(v)) {
                cli_error("%s:%d: expected a number of samples per pixel, not '%s'",
                          name, line, words[3]);
                return 0;
            }
            e.min_spp = (int)v;
        }
        if (zt_image_format_from_path(words[2]) == ZT_FORMAT_UNKNOWN) {
            cli_error("%s:%d: cannot tell the image format of '%s': use .png, .ppm, "
                      ".pfm or .exr", name, line, words[2]);
            return 0;
        }
        if (!(e.path = strdup(words[2])))
            return 0;
    } else if (!strcmp(cmd, "drag") && n == 4) {
        e.op = SCRIPT_DRAG;
        if (!parse_num(words[2], &e.dx) || !parse_num(words[3], &e.dy)) {
            cli_error("%s:%d: drag expects DX DY in pixels", name, line);
            return 0;
        }
    } else if (!strcmp(cmd, "quit") && n == 2) {
        e.op = SCRIPT_QUIT;
    } else {
        cli_error("%s:%d: unknown command '%s' (expected 'key NAME [SECONDS]', "
                  "'screenshot FILE [SPP]', 'drag DX DY' or 'quit')", name, line, cmd);
        return 0;
    }
    if (!add_event(s, &e)) {
        free(e.path);
        cli_error("out of memory");
        return 0;
    }
    if (e.op == SCRIPT_KEY) {
        script_event r = e;
        r.op = SCRIPT_RELEASE;
        r.time = e.time + e.duration;
        if (!add_event(s, &r)) {
            cli_error("out of memory");
            return 0;
        }
    }
    return 1;
}

int script_parse(const char *text, const char *name, script *out)
{
    memset(out, 0, sizeof *out);
    char *copy = strdup(text);
    if (!copy) {
        cli_error("out of memory");
        return 0;
    }
    int line = 1, ok = 1;
    char *p = copy;
    while (ok && *p) {
        size_t len = strcspn(p, "\n;");
        char sep = p[len];
        p[len] = '\0';
        char *hash = strchr(p, '#');
        if (hash)
            *hash = '\0';
        char *words[8];
        int n = 0;
        for (char *tok = strtok(p, " \t\r"); tok; tok = strtok(NULL, " \t\r")) {
            if (n == 8) {
                cli_error("%s:%d: too many words", name, line);
                ok = 0;
                break;
            }
            words[n++] = tok;
        }
        if (ok && n > 0)
            ok = parse_command(words, n, name, line, out);
        if (sep == '\n')
            line++;
        p += len + (sep ? 1 : 0);
    }
    free(copy);
    if (!ok) {
        script_free(out);
        return 0;
    }
    /* Stable sort by time: insertion sort keeps the order of equal times. */
    for (int i = 1; i < out->count; i++) {
        script_event e = out->events[i];
        int j = i;
        while (j > 0 && out->events[j - 1].time > e.time) {
            out->events[j] = out->events[j - 1];
            j--;
        }
        out->events[j] = e;
    }
    return 1;
}

void script_free(script *s)
{
    for (int i = 0; i < s->count; i++)
        free(s->events[i].path);
    free(s->events);
    s->events = NULL;
    s->count = 0;
}
