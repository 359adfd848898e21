/*
 * The k-th smallest of an array of floats by selection (Hoare's partition with a median-of-
 * three pivot), O(n) expected: percentiles of a million texels without sorting them.
 */
#ifndef LMBAKE_UTIL_SELECT_H
#define LMBAKE_UTIL_SELECT_H

#include <stddef.h>

/* The value a sort would put at v[k] (0-based; k < n, n > 0). v is reordered. */
float lmb_select_kth(float *v, size_t n, size_t k);

#endif
