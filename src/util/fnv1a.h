/* 64-bit FNV-1a over values in little-endian order: the same hash on every
 * machine, for fingerprints that files carry (forest files, checkpoints). */
#ifndef ZT_UTIL_FNV1A_H
#define ZT_UTIL_FNV1A_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "util/vec3.h"

#define FNV1A_START 0xcbf29ce484222325ull

typedef struct fnv1a { uint64_t h; } fnv1a;

static inline void fnv_bytes(fnv1a *h, const unsigned char *b, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        h->h ^= b[i];
        h->h *= 0x100000001b3ull;
    }
}

static inline void fnv_u64(fnv1a *h, uint64_t v)
{
    unsigned char b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    fnv_bytes(h, b, 8);
}

static inline void fnv_i32(fnv1a *h, int v) { fnv_u64(h, (uint64_t)(int64_t)v); }

static inline void fnv_f64(fnv1a *h, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    fnv_u64(h, u);
}

static inline void fnv_v3(fnv1a *h, vec3 v)
{
    fnv_f64(h, v.x);
    fnv_f64(h, v.y);
    fnv_f64(h, v.z);
}

#endif
