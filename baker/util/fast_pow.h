/*
 * x^a for x in (0, 1] and a >= 0, four at a time in single precision (GCC/Clang vector
 * extensions: one SSE register), as exp2(a log2 x). Guided gathering evaluates a cosine-power
 * lobe (sampling.h) per lobe per sample, and libm's expf + logf were a third of its overhead.
 *   log2: x = m 2^e with m in [sqrt(1/2), sqrt(2)); log2 m = 2/ln 2 atanh(t), t = (m-1)/(m+1),
 *         |t| <= 0.1716, by its series to t^7 (truncation < 5e-8).
 *   exp2: y = i + f, i = round(y), |f| <= 1/2; 2^f by its Taylor series to f^6 (truncation
 *         < 2e-7 relative); 2^i through the exponent bits; y < -126 gives 0.
 * Worst relative error 1.5e-5 over x in (0, 1], a in [0, 1000] (libm's expf(a logf x): 8e-6),
 * dominated by the rounding of y = a log2 x: a weight needs no more.
 */
#ifndef LMBAKE_FAST_POW_H
#define LMBAKE_FAST_POW_H

#include <stdint.h>
#include <string.h>

typedef float lmb_f4 __attribute__((vector_size(16)));
typedef int32_t lmb_i4 __attribute__((vector_size(16)));

/* Lane-wise mask ? a : b (mask lanes all ones or all zeros; C has no ?: on vectors). */
static inline lmb_f4 lmb_select_f4(lmb_i4 mask, lmb_f4 a, lmb_f4 b)
{
    lmb_i4 ia, ib;
    memcpy(&ia, &a, sizeof ia);
    memcpy(&ib, &b, sizeof ib);
    ia = (mask & ia) | (~mask & ib);
    memcpy(&a, &ia, sizeof a);
    return a;
}

static inline lmb_f4 lmb_log2_f4(lmb_f4 x)
{
    lmb_i4 bits;
    memcpy(&bits, &x, sizeof bits);
    lmb_i4 e = ((bits >> 23) & 0xFF) - 127;
    lmb_i4 mbits = (bits & 0x007FFFFF) | 0x3F800000; /* mantissa in [1, 2) */
    lmb_f4 m;
    memcpy(&m, &mbits, sizeof m);
    lmb_i4 big = m > 1.41421356f; /* all ones where m >= sqrt 2: halve it, e + 1 */
    m = lmb_select_f4(big, m * 0.5f, m);
    e = e - big;
    lmb_f4 t = (m - 1.0f) / (m + 1.0f), t2 = t * t;
    lmb_f4 s = t * (2.8853900817779268f + t2 * (0.9617966939259756f + t2 * (0.5770780163555854f + t2 * 0.4121985831111324f)));
    return s + __builtin_convertvector(e, lmb_f4);
}

static inline lmb_f4 lmb_exp2_f4(lmb_f4 y)
{
    lmb_f4 lo = {-126, -126, -126, -126};
    lmb_i4 under = y < lo;
    y = lmb_select_f4(under, lo, y);
    lmb_f4 r = y + 0.5f;
    lmb_i4 i = __builtin_convertvector(r, lmb_i4);      /* truncation toward 0 */
    i = i + (__builtin_convertvector(i, lmb_f4) > r);   /* floor(y + 1/2): -1 where truncation rounded up */
    lmb_f4 f = (y - __builtin_convertvector(i, lmb_f4)) * 0.6931471805599453f; /* |f| <= ln 2 / 2 */
    lmb_f4 p = 1.0f + f * (1.0f + f * (0.5f + f * (1.0f / 6 + f * (1.0f / 24 + f * (1.0f / 120 + f * (1.0f / 720))))));
    lmb_i4 pbits;
    memcpy(&pbits, &p, sizeof pbits);
    pbits = (pbits + (i << 23)) & ~under;
    memcpy(&p, &pbits, sizeof p);
    return p;
}

/* x^a per lane; x <= 0 gives 0. */
static inline lmb_f4 lmb_pow_f4(lmb_f4 x, lmb_f4 a)
{
    lmb_i4 pos = x > 0.0f;
    lmb_f4 p = lmb_exp2_f4(a * lmb_log2_f4(lmb_select_f4(pos, x, (lmb_f4){1, 1, 1, 1})));
    return lmb_select_f4(pos, p, (lmb_f4){0, 0, 0, 0});
}

#endif
