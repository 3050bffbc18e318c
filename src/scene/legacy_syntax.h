/* The original programs' group syntax, rewritten into strict JSON.
 *
 * Retra and Silence write a multi-part object as key/value pairs and
 * primitives mixed inside an array, which is not JSON:
 *
 *     { "thing": [ "material": {...}, "backculled": true, {"sphere": {...}} ] }
 *
 * legacy_rewrite() turns every "thing": [ ... ] and "light": [ ... ] into the
 * canonical object form
 *
 *     { "thing": { "material": {...}, "backculled": true, "parts": [ {"sphere": {...}} ] } }
 *
 * by a scan that knows only strings and brackets.  It never removes or moves
 * text and never inserts a newline, so jansson's line numbers stay those of
 * the file; the inserts are recorded so that offsets can be mapped back.
 * A setting that follows a part in the legacy form cannot join the object
 * without moving text, so it is wrapped into a one-key object inside "parts"
 * ({"material": {...}}), which the loader applies in order like any other.
 * Text that is already strict JSON passes through unchanged. */
#ifndef ZT_SCENE_LEGACY_SYNTAX_H
#define ZT_SCENE_LEGACY_SYNTAX_H

#include <stddef.h>

/* One insertion: `length` bytes that start at `offset` in the output. */
typedef struct legacy_insert {
    size_t offset;
    size_t length;
} legacy_insert;

typedef struct legacy_text {
    char *text;              /* the rewritten text, NUL-terminated */
    size_t length;
    legacy_insert *inserts;  /* in increasing offset order */
    size_t insert_count;
    size_t insert_capacity;
} legacy_text;

typedef enum legacy_status {
    LEGACY_OK = 0,
    LEGACY_NO_MEMORY,
    LEGACY_TOO_DEEP          /* brackets nest deeper than LEGACY_MAX_DEPTH */
} legacy_status;

/* Scene files need about eight levels; anything this deep is not one. */
#define LEGACY_MAX_DEPTH 128

/* Rewrites in[0..n) into *out (which the caller frees with legacy_free, also
 * after a failure).  On LEGACY_TOO_DEEP, *error_offset is the input offset of
 * the bracket that went too deep.  A UTF-8 byte-order mark is blanked. */
legacy_status legacy_rewrite(const char *in, size_t n, legacy_text *out,
                             size_t *error_offset);

void legacy_free(legacy_text *t);

#endif
