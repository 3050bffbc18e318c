/* From an offset in the text jansson parsed (the legacy rewrite of the
 * file) back to a line and column of the file itself. */
#ifndef ZT_SCENE_SOURCE_MAP_H
#define ZT_SCENE_SOURCE_MAP_H

#include <stddef.h>

#include "scene/legacy_syntax.h"

typedef struct source_map {
    const char *text;            /* the original file, not owned */
    size_t length;
    size_t *line_starts;         /* offset of the first byte of each line */
    size_t line_count;
    const legacy_insert *inserts; /* not owned */
    size_t *shift_before;        /* total insert length before each insert */
    size_t insert_count;
} source_map;

/* Offsets that no scanner could place. */
#define SOURCE_OFFSET_UNKNOWN ((size_t)-1)

/* Indexes the lines of text.  Returns 0 when out of memory.  rewrite may be
 * NULL when the parsed text is the file itself. */
int source_map_init(source_map *map, const char *text, size_t length,
                    const legacy_text *rewrite);

void source_map_free(source_map *map);

/* The offset in the original text of offset `parsed` in the rewritten text;
 * a position inside inserted text maps to the original byte after it. */
size_t source_map_original(const source_map *map, size_t parsed);

/* Line and column (both from 1; columns count UTF-8 characters) of an
 * offset in the original text.  Returns 0 for SOURCE_OFFSET_UNKNOWN. */
int source_map_locate(const source_map *map, size_t original, int *line,
                      int *column);

struct json_error_t;

/* Where in text a jansson syntax error is: the start of the token it names
 * ("near 'x'"), or for an early end the end of the last token. */
size_t json_syntax_error_offset(const char *text, size_t length,
                                const struct json_error_t *e);

#endif
