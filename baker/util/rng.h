/*
 * Counter-based random numbers: every value is a pure function of (seed, stream, index),
 * so a texel's samples are the same whatever thread computes it and in whatever order:
 * bit-identical lightmaps at any thread count. The mixer is splitmix64's finalizer
 * (Steele, Lea, Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014).
 */
#ifndef LMBAKE_RNG_H
#define LMBAKE_RNG_H

#include <stdint.h>

static inline uint64_t lmb_mix64(uint64_t z)
{
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* A stream of numbers for one purpose at one place: key = (seed, a, b), e.g. (seed, texel, pass). */
typedef struct lmb_rng {
    uint64_t key, counter;
} lmb_rng;

static inline lmb_rng lmb_rng_make(uint64_t seed, uint64_t a, uint64_t b)
{
    lmb_rng r = {lmb_mix64(seed ^ lmb_mix64(a ^ lmb_mix64(b))), 0};
    return r;
}

/* Uniform in [0, 1), 53 bits. */
static inline double lmb_rng_next(lmb_rng *r)
{
    return (double)(lmb_mix64(r->key + r->counter++) >> 11) * (1.0 / 9007199254740992.0);
}

#endif
