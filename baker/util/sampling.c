/* Picking a segment of a tabulated CDF (see sampling.h). */
#include "sampling.h"

/* The first k < n with cdf[k + 1] > x (n - 1 when none): binary search. */
static uint32_t first_above(const double *cdf, uint32_t n, double x)
{
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (cdf[mid + 1] <= x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

uint32_t lmb_cdf_pick(const double *cdf, uint32_t count, double u, double *prob)
{
    double total = cdf[count];
    uint32_t k = first_above(cdf, count, u * total);
    *prob = (cdf[k + 1] - cdf[k]) / total;
    return k;
}

uint32_t lmb_cdf_segment(const double *cdf, uint32_t n, double x)
{
    uint32_t k = first_above(cdf, n, x);
    while (k + 1 < n && !(cdf[k + 1] > cdf[k])) /* never a segment of zero weight */
        k++;
    return k;
}
