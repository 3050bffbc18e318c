/* Offsets to lines and columns, through the inserts of the legacy rewrite. */
#include "scene/source_map.h"

#include <jansson.h>
#include <stdlib.h>
#include <string.h>

int source_map_init(source_map *map, const char *text, size_t length,
                    const legacy_text *rewrite)
{
    memset(map, 0, sizeof *map);
    map->text = text;
    map->length = length;
    size_t lines = 1;
    for (size_t i = 0; i < length; i++)
        lines += text[i] == '\n';
    map->line_starts = malloc(lines * sizeof *map->line_starts);
    if (!map->line_starts)
        return 0;
    map->line_starts[0] = 0;
    map->line_count = 1;
    for (size_t i = 0; i < length; i++)
        if (text[i] == '\n')
            map->line_starts[map->line_count++] = i + 1;
    if (rewrite && rewrite->insert_count) {
        map->shift_before = malloc(rewrite->insert_count * sizeof(size_t));
        if (!map->shift_before)
            return 0;
        map->inserts = rewrite->inserts;
        map->insert_count = rewrite->insert_count;
        size_t shift = 0;
        for (size_t k = 0; k < map->insert_count; k++) {
            map->shift_before[k] = shift;
            shift += map->inserts[k].length;
        }
    }
    return 1;
}

void source_map_free(source_map *map)
{
    free(map->line_starts);
    free(map->shift_before);
    memset(map, 0, sizeof *map);
}

size_t source_map_original(const source_map *map, size_t parsed)
{
    if (parsed == SOURCE_OFFSET_UNKNOWN)
        return parsed;
    /* The last insert that starts at or before `parsed`. */
    size_t lo = 0, hi = map->insert_count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (map->inserts[mid].offset <= parsed)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo == 0)
        return parsed;
    const legacy_insert *ins = &map->inserts[lo - 1];
    size_t shift = map->shift_before[lo - 1];
    if (parsed < ins->offset + ins->length)
        return ins->offset - shift;
    return parsed - shift - ins->length;
}

int source_map_locate(const source_map *map, size_t original, int *line,
                      int *column)
{
    if (original == SOURCE_OFFSET_UNKNOWN)
        return 0;
    if (original > map->length)
        original = map->length;
    size_t lo = 0, hi = map->line_count;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (map->line_starts[mid] <= original)
            lo = mid;
        else
            hi = mid;
    }
    int col = 1;
    for (size_t i = map->line_starts[lo]; i < original; i++)
        col += ((unsigned char)map->text[i] & 0xC0) != 0x80;
    *line = (int)(lo + 1);
    *column = col;
    return 1;
}

size_t json_syntax_error_offset(const char *text, size_t length,
                                const struct json_error_t *e)
{
    size_t pos = e->position > 0 ? (size_t)e->position : 0;
    if (pos > length)
        pos = length;
    if (strstr(e->text, "near end of file")) {
        while (pos > 0 && strchr(" \t\r\n", text[pos - 1]))
            pos--;
        return pos;
    }
    const char *near = strstr(e->text, "near '");
    const char *last = strrchr(e->text, '\'');
    if (near && last > near + 6) {
        size_t len = (size_t)(last - (near + 6));
        if (len <= pos && memcmp(text + pos - len, near + 6, len) == 0)
            return pos - len;
    }
    return pos > 0 ? pos - 1 : 0;
}
