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

/* Point `index` of the scrambled sequence `key`: u[0], u[1] in [0, 1). */
static inline void lmb_qmc_2d(uint64_t key, uint32_t index, double u[2])
{
    uint32_t i = lmb_qmc_owen(index, lmb_qmc_hash(key));
    uint32_t x = lmb_qmc_reverse(i), y = 0; /* dimension 0: van der Corput */
    for (uint32_t v = 0x80000000u; i; i >>= 1, v ^= v >> 1) /* dimension 1: Pascal's matrix mod 2 */
        if (i & 1)
            y ^= v;
    x = lmb_qmc_owen(x, lmb_qmc_hash(key ^ 0x9E3779B97F4A7C15ull));
    y = lmb_qmc_owen(y, lmb_qmc_hash(key ^ 0xD1B54A32D192ED03ull));
    u[0] = x * (1.0 / 4294967296.0);
    u[1] = y * (1.0 / 4294967296.0);
}

#endif
