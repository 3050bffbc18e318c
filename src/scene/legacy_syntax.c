/* The group-syntax rewrite (see legacy_syntax.h).  Malformed text is copied
 * through as well as can be: jansson reports what is wrong with it. */
#include "scene/legacy_syntax.h"

#include <stdlib.h>
#include <string.h>

#include "scene/text_scan.h"

/* Where a group (a legacy array being turned into an object) is in its
 * list of items. */
typedef enum group_state {
    G_ITEM,   /* expecting an item: a key, a part, or the closing ']' */
    G_KEY,    /* saw a key, expecting ':' */
    G_VALUE,  /* saw ':', expecting the key's value */
    G_AFTER   /* an item is complete, expecting ',' or ']' */
} group_state;

typedef struct frame {
    int is_group;
    int parts_open;  /* "parts": [ has been inserted */
    int wrapped;     /* the current keyed item was wrapped in '{' */
    group_state state;
} frame;

typedef struct rewriter {
    legacy_text *out;
    size_t capacity;
    int failed;
    frame stack[LEGACY_MAX_DEPTH];
    int depth;
} rewriter;

static void put(rewriter *w, const char *s, size_t len)
{
    legacy_text *t = w->out;
    if (w->failed)
        return;
    if (t->length + len + 1 > w->capacity) {
        size_t cap = w->capacity ? w->capacity : 256;
        while (cap < t->length + len + 1)
            cap *= 2;
        char *p = realloc(t->text, cap);
        if (!p) {
            w->failed = 1;
            return;
        }
        t->text = p;
        w->capacity = cap;
    }
    memcpy(t->text + t->length, s, len);
    t->length += len;
    t->text[t->length] = '\0';
}

static void insert(rewriter *w, const char *s)
{
    legacy_text *t = w->out;
    if (w->failed)
        return;
    if (t->insert_count == t->insert_capacity) {
        size_t cap = t->insert_capacity ? t->insert_capacity * 2 : 16;
        legacy_insert *p = realloc(t->inserts, cap * sizeof *p);
        if (!p) {
            w->failed = 1;
            return;
        }
        t->inserts = p;
        t->insert_capacity = cap;
    }
    t->inserts[t->insert_count].offset = t->length;
    t->inserts[t->insert_count].length = strlen(s);
    t->insert_count++;
    put(w, s, strlen(s));
}

static frame *top(rewriter *w)
{
    return w->depth ? &w->stack[w->depth - 1] : NULL;
}

/* A part (anything but a key) starts inside a group: the first one opens
 * the "parts" list. */
static void group_part(rewriter *w, frame *g)
{
    if (!g->parts_open) {
        insert(w, "\"parts\": [");
        g->parts_open = 1;
    }
    g->state = G_AFTER;
}

/* Something that is not a key starts at the current position: either the
 * value of the group's current key or a new part. */
static void group_value_or_part(rewriter *w)
{
    frame *g = top(w);
    if (!g || !g->is_group)
        return;
    if (g->state == G_VALUE)
        g->state = G_AFTER;
    else
        group_part(w, g);
}

/* A keyed item starts inside a group; after a part it must be wrapped. */
static void group_key(rewriter *w, frame *g)
{
    if (g->parts_open) {
        insert(w, "{");
        g->wrapped = 1;
    }
    g->state = G_KEY;
}

/* The current keyed item of a group ends (at ',' or ']'). */
static void group_item_end(rewriter *w, frame *g)
{
    if (g->wrapped) {
        insert(w, "}");
        g->wrapped = 0;
    }
}

/* Is s[i..end) the key "thing" or "light" whose value is an array?  Then
 * *bracket is the offset of that '['. */
static int starts_group(const char *s, size_t n, size_t i, size_t end,
                        size_t *bracket)
{
    size_t len = end - i;
    if (len != 7 || (memcmp(s + i, "\"thing\"", 7) && memcmp(s + i, "\"light\"", 7)))
        return 0;
    size_t j = scan_skip_space(s, n, end);
    if (j >= n || s[j] != ':')
        return 0;
    j = scan_skip_space(s, n, j + 1);
    if (j >= n || s[j] != '[')
        return 0;
    *bracket = j;
    return 1;
}

static int push(rewriter *w, int is_group)
{
    if (w->depth == LEGACY_MAX_DEPTH)
        return 0;
    frame *f = &w->stack[w->depth++];
    memset(f, 0, sizeof *f);
    f->is_group = is_group;
    f->state = G_ITEM;
    return 1;
}

static void close_bracket(rewriter *w, char c)
{
    frame *f = top(w);
    if (f && f->is_group && c == ']') {
        group_item_end(w, f);
        if (f->parts_open) {
            put(w, "]", 1);
            insert(w, "}");
        } else {
            put(w, "}", 1); /* the same length as the ']' it replaces */
        }
    } else {
        put(w, &c, 1);
    }
    if (w->depth)
        w->depth--;
}

legacy_status legacy_rewrite(const char *in, size_t n, legacy_text *out,
                             size_t *error_offset)
{
    rewriter w;
    memset(&w, 0, sizeof w);
    memset(out, 0, sizeof *out);
    w.out = out;
    put(&w, "", 0);

    size_t i = 0, group_bracket = (size_t)-1;
    if (n >= 3 && memcmp(in, "\xEF\xBB\xBF", 3) == 0) {
        put(&w, "   ", 3);
        i = 3;
    }
    while (i < n && !w.failed) {
        char c = in[i];
        frame *f = top(&w);
        if (scan_is_space(c)) {
            size_t end = scan_skip_space(in, n, i);
            put(&w, in + i, end - i);
            i = end;
        } else if (c == '"') {
            size_t end = scan_string_end(in, n, i);
            size_t after = scan_skip_space(in, n, end);
            int is_key = after < n && in[after] == ':';
            if (is_key)
                starts_group(in, n, i, end, &group_bracket);
            if (f && f->is_group) {
                if (is_key && (f->state == G_ITEM || f->state == G_AFTER))
                    group_key(&w, f);
                else
                    group_value_or_part(&w);
            }
            put(&w, in + i, end - i);
            i = end;
        } else if (c == ':') {
            if (f && f->is_group && f->state == G_KEY)
                f->state = G_VALUE;
            put(&w, &c, 1);
            i++;
        } else if (c == ',') {
            if (f && f->is_group) {
                group_item_end(&w, f);
                f->state = G_ITEM;
            }
            put(&w, &c, 1);
            i++;
        } else if (c == '{' || c == '[') {
            group_value_or_part(&w);
            int is_group = i == group_bracket;
            if (!push(&w, is_group)) {
                *error_offset = i;
                return LEGACY_TOO_DEEP;
            }
            put(&w, is_group ? "{" : &c, 1);
            i++;
        } else if (c == '}' || c == ']') {
            close_bracket(&w, c);
            i++;
        } else {
            size_t end = scan_word_end(in, n, i);
            group_value_or_part(&w);
            put(&w, in + i, end - i);
            i = end;
        }
    }
    return w.failed ? LEGACY_NO_MEMORY : LEGACY_OK;
}

void legacy_free(legacy_text *t)
{
    free(t->text);
    free(t->inserts);
    memset(t, 0, sizeof *t);
}
