/* Deterministic, well-stratified sample points.
 *
 * Each consumer asks for a 2D point by (pixel, sample index, dimension
 * pair).  Every pair is the first two dimensions of the Sobol sequence,
 * Owen-scrambled with a hash of (seed, pixel, pair) and with the sample
 * index shuffled the same way, so pairs are stratified on their own and
 * independent of each other (Burley 2020, "Practical Hash-based Owen
 * Scrambling").  Results depend only on the arguments, never on threads.
 */
#ifndef ZT_UTIL_SAMPLER_H
#define ZT_UTIL_SAMPLER_H

#include <stdint.h>

#include "util/sampler_tables.h"

static inline uint32_t sampler_hash(uint32_t x)
{
    /* A strong 32-bit integer mix (lowbias32 by C. Wellons). */
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

static inline uint32_t sampler_hash3(uint32_t a, uint32_t b, uint32_t c)
{
    return sampler_hash(a ^ sampler_hash(b ^ sampler_hash(c + 0x9e3779b9U)));
}

static inline uint32_t sampler_reverse_bits(uint32_t x)
{
    x = __builtin_bswap32(x);
    x = ((x >> 1) & 0x55555555U) | ((x & 0x55555555U) << 1);
    x = ((x >> 2) & 0x33333333U) | ((x & 0x33333333U) << 2);
    return ((x >> 4) & 0x0f0f0f0fU) | ((x & 0x0f0f0f0fU) << 4);
}

/* Laine-Karras style permutation: each bit is flipped depending only on
 * the bits below it, which on reversed bits is a nested uniform scramble. */
static inline uint32_t sampler_lk_permute(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cU;
    x ^= x * 0xb82f1e52U;
    x ^= x * 0xc7afe638U;
    x ^= x * 0x8d22f6e6U;
    return x;
}

static inline uint32_t sampler_owen(uint32_t x, uint32_t seed)
{
    return sampler_reverse_bits(sampler_lk_permute(sampler_reverse_bits(x), seed));
}

/* Second Sobol dimension (the first is the bit-reversed index), with its
 * bits reversed: the XOR of the generator matrix columns of the index's
 * set bits, by a table of reversed columns (which saves the reversal the
 * scramble would start with). */
static inline uint32_t sampler_sobol1_reversed(uint32_t index)
{
    return sampler_sobol1_reversed_bytes[0][index & 255U] ^
           sampler_sobol1_reversed_bytes[1][(index >> 8) & 255U] ^
           sampler_sobol1_reversed_bytes[2][(index >> 16) & 255U] ^
           sampler_sobol1_reversed_bytes[3][index >> 24];
}

static inline float sampler_to_float(uint32_t x)
{
    return (float)(x >> 8) * (1.0f / 16777216.0f); /* in [0, 1) */
}

/* Two reversals in one: reverse_bits of the 64-bit (hi, lo) is
 * (reverse_bits(lo), reverse_bits(hi)), for about the work of one. */
static inline uint64_t sampler_reverse_bits64(uint64_t x)
{
    x = __builtin_bswap64(x);
    x = ((x >> 1) & 0x5555555555555555U) | ((x & 0x5555555555555555U) << 1);
    x = ((x >> 2) & 0x3333333333333333U) | ((x & 0x3333333333333333U) << 2);
    return ((x >> 4) & 0x0f0f0f0f0f0f0f0fU) | ((x & 0x0f0f0f0f0f0f0f0fU) << 4);
}

/* The scramble seed of (pixel key, dimension pair).  It does not depend
 * on the sample index: callers may compute it once per pixel. */
static inline uint32_t sampler_pair_seed(uint32_t key, uint32_t pair)
{
    return sampler_hash(key ^ (pair * 0x9e3779b9U + 0x51ed270bU));
}

/* The sample point of the pair with seed h (sampler_pair_seed) for the
 * sample whose index, bit-reversed, is rev_index (shared by all pairs). */
static inline void sampler_get2_seeded(uint32_t h, uint32_t rev_index,
                                       float out[2])
{
    /* Shuffling keeps the low bits a permutation of each aligned block of
     * indices; keeping 20 of them bounds the work below and still gives
     * distinct points for up to 2^20 samples per pixel. */
    uint32_t i = sampler_reverse_bits(sampler_lk_permute(rev_index, h)) & 0xfffffU;
    /* Dimension 0 is reverse_bits(i), so its scramble needs one reversal;
     * both outputs are reversed together. */
    uint32_t s0 = sampler_lk_permute(i, h * 0x9e3779b9U + 1U);
    uint32_t s1 = sampler_lk_permute(sampler_sobol1_reversed(i), h * 0x85ebca6bU + 2U);
    uint64_t r = sampler_reverse_bits64((uint64_t)s0 << 32 | s1);
    out[0] = sampler_to_float((uint32_t)r);
    out[1] = sampler_to_float((uint32_t)(r >> 32));
}

/* The sample point for (pixel key, sample index, dimension pair). */
static inline void sampler_get2(uint32_t key, uint32_t index, uint32_t pair,
                                float out[2])
{
    sampler_get2_seeded(sampler_pair_seed(key, pair), sampler_reverse_bits(index), out);
}

/* A small per-sample random stream (PCG32's RXS-M-XS output on an LCG) for
 * choices that need no stratification: light and lobe choice, roulette,
 * and the dimensions of deep path vertices. */
typedef struct sampler_stream {
    uint32_t state;
} sampler_stream;

static inline sampler_stream sampler_stream_start(uint32_t key, uint32_t index)
{
    sampler_stream s = {sampler_hash3(key ^ 0x2545f491U, index, 0x68e31da4U)};
    return s;
}

static inline float sampler_next(sampler_stream *s)
{
    uint32_t x = s->state;
    s->state = x * 747796405U + 2891336453U;
    uint32_t w = ((x >> ((x >> 28) + 4U)) ^ x) * 277803737U;
    return sampler_to_float((w >> 22) ^ w);
}

#endif
