/*
 * Randomised quasi-Monte Carlo points in [0, 1)^2: the first two dimensions of Sobol's sequence
 * (a (0, 2)-sequence: every power-of-two run of 2^k points from index 0 puts one point in each
 * of 2^k elementary boxes of any shape), randomised by a hash-based Owen scramble of the index
 * and of each coordinate (Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020,
 * section 3; the permutation is Laine and Karras's, with Burley's constants). A scrambled net
 * is unbiased for any integrand, like independent samples, and its error falls faster where the
 * integrand is smooth (area lights without occluders) and like N^-3/4 across a shadow edge.
 * Every point is a pure function of (key, index): thread count and order do not matter.
 */
#ifndef LMBAKE_QMC_H
#define LMBAKE_QMC_H

#include <stdint.h>

static inline uint32_t lmb_qmc_reverse(uint32_t x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

/* Laine-Karras permutation of bit-reversed x: each bit flips as a hash of the bits below it. */
static inline uint32_t lmb_qmc_lk_permute(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* Nested uniform (Owen) scramble of the 32-bit fixed-point x. */
static inline uint32_t lmb_qmc_owen(uint32_t x, uint32_t seed)
{
    return lmb_qmc_reverse(lmb_qmc_lk_permute(lmb_qmc_reverse(x), seed));
}

static inline uint32_t lmb_qmc_hash(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ull;
    x ^= x >> 33;
    return (uint32_t)x;
}

/* Sobol's second dimension before its final bit reversal: the Pascal matrix mod 2 applied to i.
 * Bit k of the result is the XOR of i's bits j with C(j, k) odd, that is (Lucas) with j a
 * superset of k's bits: a superset sum over the five bits of a bit position, one shift and
 * mask each (Burley's paper, section 3, loops over the 32 columns instead; same values,
 * checked against that loop in tests/unit/test_qmc.c). */
static inline uint32_t lmb_qmc_pascal(uint32_t i)
{
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0F0F0F0Fu;
    i ^= (i >> 8) & 0x00FF00FFu;
    i ^= (i >> 16) & 0x0000FFFFu;
    return i;
}

/* One scrambled sequence: its three scramble seeds (the index's and each coordinate's), hashed
 * from its key once rather than at every point. */
typedef struct lmb_qmc_seq {
    uint32_t index_seed, x_seed, y_seed;
} lmb_qmc_seq;

static inline lmb_qmc_seq lmb_qmc_sequence(uint64_t key)
{
    lmb_qmc_seq q = {lmb_qmc_hash(key), lmb_qmc_hash(key ^ 0x9E3779B97F4A7C15ull),
                     lmb_qmc_hash(key ^ 0xD1B54A32D192ED03ull)};
    return q;
}

/* Point `index` of the scrambled sequence q: u[0], u[1] in [0, 1). Dimension 0 is van der
 * Corput's (the bit reversal of the scrambled index), dimension 1 the Pascal matrix's; each is
 * Owen-scrambled, reverse(permute(reverse(.))), whose inner reversal undoes the sequence's own. */
static inline void lmb_qmc_point(const lmb_qmc_seq *q, uint32_t index, double u[2])
{
    uint32_t i = lmb_qmc_owen(index, q->index_seed);
    uint32_t x = lmb_qmc_reverse(lmb_qmc_lk_permute(i, q->x_seed));
    uint32_t y = lmb_qmc_reverse(lmb_qmc_lk_permute(lmb_qmc_pascal(i), q->y_seed));
    u[0] = x * (1.0 / 4294967296.0);
    u[1] = y * (1.0 / 4294967296.0);
}

/* Point `index` of the scrambled sequence `key` (lmb_qmc_point with its seeds hashed here). */
static inline void lmb_qmc_2d(uint64_t key, uint32_t index, double u[2])
{
    lmb_qmc_seq q = lmb_qmc_sequence(key);
    lmb_qmc_point(&q, index, u);
}

#endif
