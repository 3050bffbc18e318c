/* Where each value of a parsed JSON document starts in its text.
 *
 * jansson's values do not carry positions, so a second pass over the text
 * (which jansson has already accepted) records the start of every key and
 * value in document order; a pre-order walk of the jansson tree, whose
 * objects iterate in insertion order, pairs them up.  Keys cannot repeat
 * (the loader parses with JSON_REJECT_DUPLICATES), so the two sequences
 * match one for one.  Offsets are those of the parsed text. */
#ifndef ZT_SCENE_JSON_POSITIONS_H
#define ZT_SCENE_JSON_POSITIONS_H

#include <stddef.h>
#include <jansson.h>

typedef struct json_positions json_positions;

/* Builds the index of root, the document that jansson parsed from
 * text[0..length).  Returns NULL when out of memory.  If the text and the
 * tree do not match (which should not happen), every lookup answers
 * SOURCE_OFFSET_UNKNOWN rather than a wrong place. */
json_positions *json_positions_build(const char *text, size_t length,
                                     const json_t *root);

void json_positions_free(json_positions *pos);

/* Offsets of the root value, of the value and of the key of an object's
 * member, and of an array's element; SOURCE_OFFSET_UNKNOWN if not known. */
size_t json_positions_root(const json_positions *pos);
size_t json_positions_member(const json_positions *pos, const json_t *obj,
                             const char *key);
size_t json_positions_key(const json_positions *pos, const json_t *obj,
                          const char *key);
size_t json_positions_element(const json_positions *pos, const json_t *array,
                              size_t index);

#endif
