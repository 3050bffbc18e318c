/* The value position index (see json_positions.h). */
#include "scene/json_positions.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/source_map.h"
#include "scene/text_scan.h"

struct json_positions {
    int valid;
    size_t root;
    /* The members of each container, contiguous per container. */
    size_t *key_at;
    size_t *value_at;
    size_t slots;
    /* Open addressing: container pointer -> its first member slot. */
    const json_t **table_node;
    size_t *table_first;
    size_t table_mask;
};

typedef struct walker {
    json_positions *pos;
    const char *text;
    size_t length;
    size_t cursor;    /* scan position in the text */
    size_t used;      /* member slots handed out */
} walker;

/* The start of the next key or value in the text, and moves past it. */
static size_t next_token(walker *w)
{
    const char *s = w->text;
    size_t n = w->length, i = w->cursor;
    while (i < n && (scan_is_space(s[i]) || s[i] == ':' || s[i] == ',' ||
                     s[i] == '}' || s[i] == ']'))
        i++;
    if (i >= n)
        return SOURCE_OFFSET_UNKNOWN;
    if (s[i] == '"')
        w->cursor = scan_string_end(s, n, i);
    else if (s[i] == '{' || s[i] == '[')
        w->cursor = i + 1;
    else
        w->cursor = scan_word_end(s, n, i);
    return i;
}

static size_t hash_node(const json_t *node, size_t mask)
{
    uint64_t h = (uint64_t)(uintptr_t)node;
    h ^= h >> 29;
    h *= 0x9E3779B97F4A7C15ULL;
    return (size_t)(h >> 32) & mask;
}

static void table_put(json_positions *pos, const json_t *node, size_t first)
{
    size_t i = hash_node(node, pos->table_mask);
    while (pos->table_node[i])
        i = (i + 1) & pos->table_mask;
    pos->table_node[i] = node;
    pos->table_first[i] = first;
}

static size_t table_get(const json_positions *pos, const json_t *node)
{
    if (!pos->valid || !node)
        return SOURCE_OFFSET_UNKNOWN;
    size_t i = hash_node(node, pos->table_mask);
    while (pos->table_node[i]) {
        if (pos->table_node[i] == node)
            return pos->table_first[i];
        i = (i + 1) & pos->table_mask;
    }
    return SOURCE_OFFSET_UNKNOWN;
}

static size_t container_size(const json_t *node)
{
    if (json_is_object(node))
        return json_object_size(node);
    return json_is_array(node) ? json_array_size(node) : 0;
}

/* Counts containers and their members, to size the tables. */
static void count(const json_t *node, size_t *containers, size_t *members,
                  int depth)
{
    if (!json_is_object(node) && !json_is_array(node))
        return;
    ++*containers;
    *members += container_size(node);
    if (depth > 4096)
        return;
    if (json_is_object(node)) {
        const char *key;
        json_t *child;
        json_object_foreach((json_t *)node, key, child)
            count(child, containers, members, depth + 1);
    } else {
        for (size_t i = 0; i < json_array_size(node); i++)
            count(json_array_get(node, i), containers, members, depth + 1);
    }
}

static int token_matches(const walker *w, size_t at, const json_t *node)
{
    char c = w->text[at];
    if (json_is_object(node))
        return c == '{';
    if (json_is_array(node))
        return c == '[';
    if (json_is_string(node))
        return c == '"';
    return c != '{' && c != '[' && c != '"';
}

/* Pairs node (and everything under it) with the next tokens of the text;
 * *at receives the node's own offset.  Returns 0 on a mismatch. */
static int walk(walker *w, const json_t *node, size_t *at, int depth)
{
    *at = next_token(w);
    if (*at == SOURCE_OFFSET_UNKNOWN || !token_matches(w, *at, node) ||
        depth > 4096)
        return 0;
    if (!json_is_object(node) && !json_is_array(node))
        return 1;
    json_positions *pos = w->pos;
    size_t first = w->used, n = container_size(node);
    w->used += n;
    table_put(pos, node, first);
    if (json_is_object(node)) {
        const char *key;
        json_t *child;
        size_t i = first;
        json_object_foreach((json_t *)node, key, child) {
            pos->key_at[i] = next_token(w);
            if (pos->key_at[i] == SOURCE_OFFSET_UNKNOWN || w->text[pos->key_at[i]] != '"')
                return 0;
            if (!walk(w, child, &pos->value_at[i], depth + 1))
                return 0;
            i++;
        }
    } else {
        for (size_t i = 0; i < n; i++) {
            pos->key_at[first + i] = SOURCE_OFFSET_UNKNOWN;
            if (!walk(w, json_array_get(node, i), &pos->value_at[first + i], depth + 1))
                return 0;
        }
    }
    return 1;
}

json_positions *json_positions_build(const char *text, size_t length,
                                     const json_t *root)
{
    json_positions *pos = calloc(1, sizeof *pos);
    if (!pos)
        return NULL;
    size_t containers = 0, members = 0;
    count(root, &containers, &members, 0);
    size_t table_size = 16;
    while (table_size < 2 * containers)
        table_size *= 2;
    pos->table_mask = table_size - 1;
    pos->table_node = calloc(table_size, sizeof *pos->table_node);
    pos->table_first = calloc(table_size, sizeof *pos->table_first);
    pos->key_at = malloc((members + 1) * sizeof *pos->key_at);
    pos->value_at = malloc((members + 1) * sizeof *pos->value_at);
    pos->slots = members;
    if (!pos->table_node || !pos->table_first || !pos->key_at || !pos->value_at) {
        json_positions_free(pos);
        return NULL;
    }
    walker w = {pos, text, length, 0, 0};
    pos->valid = walk(&w, root, &pos->root, 0);
    return pos;
}

void json_positions_free(json_positions *pos)
{
    if (!pos)
        return;
    free(pos->key_at);
    free(pos->value_at);
    free(pos->table_node);
    free(pos->table_first);
    free(pos);
}

size_t json_positions_root(const json_positions *pos)
{
    return pos && pos->valid ? pos->root : SOURCE_OFFSET_UNKNOWN;
}

/* The member slot of key in object, or SOURCE_OFFSET_UNKNOWN. */
static size_t member_slot(const json_positions *pos, const json_t *obj,
                          const char *key)
{
    size_t first = table_get(pos, obj);
    if (first == SOURCE_OFFSET_UNKNOWN || !json_is_object(obj))
        return SOURCE_OFFSET_UNKNOWN;
    size_t i = 0;
    const char *k;
    json_t *child;
    json_object_foreach((json_t *)obj, k, child) {
        if (strcmp(k, key) == 0)
            return first + i;
        i++;
    }
    return SOURCE_OFFSET_UNKNOWN;
}

size_t json_positions_member(const json_positions *pos, const json_t *obj,
                             const char *key)
{
    size_t slot = pos ? member_slot(pos, obj, key) : SOURCE_OFFSET_UNKNOWN;
    return slot == SOURCE_OFFSET_UNKNOWN ? slot : pos->value_at[slot];
}

size_t json_positions_key(const json_positions *pos, const json_t *obj,
                          const char *key)
{
    size_t slot = pos ? member_slot(pos, obj, key) : SOURCE_OFFSET_UNKNOWN;
    return slot == SOURCE_OFFSET_UNKNOWN ? slot : pos->key_at[slot];
}

size_t json_positions_element(const json_positions *pos, const json_t *array,
                              size_t index)
{
    size_t first = pos ? table_get(pos, array) : SOURCE_OFFSET_UNKNOWN;
    if (first == SOURCE_OFFSET_UNKNOWN || !json_is_array(array) ||
        index >= json_array_size(array))
        return SOURCE_OFFSET_UNKNOWN;
    return pos->value_at[first + index];
}
