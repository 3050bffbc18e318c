/* Token boundaries of JSON-like text, shared by the two scanners of the
 * loader (the legacy group rewrite and the value position index).  They only
 * need to know where strings, brackets and bare words start and end; the
 * JSON itself is parsed by jansson. */
#ifndef ZT_SCENE_TEXT_SCAN_H
#define ZT_SCENE_TEXT_SCAN_H

#include <stddef.h>

static inline int scan_is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* Characters that end a bare word (a number or a literal). */
static inline int scan_is_delimiter(char c)
{
    return scan_is_space(c) || c == '{' || c == '}' || c == '[' || c == ']' ||
           c == ':' || c == ',' || c == '"';
}

static inline size_t scan_skip_space(const char *s, size_t n, size_t i)
{
    while (i < n && scan_is_space(s[i]))
        i++;
    return i;
}

/* s[i] is an opening quote: the index just past the closing quote, or n
 * when the string is unterminated. */
static inline size_t scan_string_end(const char *s, size_t n, size_t i)
{
    for (i++; i < n; i++) {
        if (s[i] == '\\')
            i++;
        else if (s[i] == '"')
            return i + 1;
    }
    return n;
}

/* s[i] starts a bare word: the index just past it.  Always advances. */
static inline size_t scan_word_end(const char *s, size_t n, size_t i)
{
    for (i++; i < n && !scan_is_delimiter(s[i]); i++)
        ;
    return i;
}

#endif
