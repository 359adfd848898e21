/* Picking a segment of a tabulated CDF (see sampling.h). */
#include "sampling.h"

uint32_t lmb_cdf_pick(const double *cdf, uint32_t count, double u, double *prob)
{
    double total = cdf[count], target = u * total;
    uint32_t lo = 0, hi = count - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (cdf[mid + 1] <= target)
            lo = mid + 1;
        else
            hi = mid;
    }
    *prob = (cdf[lo + 1] - cdf[lo]) / total;
    return lo;
}

uint32_t lmb_cdf_segment(const double *cdf, uint32_t n, double x)
{
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (cdf[mid + 1] <= x)
            lo = mid + 1;
        else
            hi = mid;
    }
    while (lo + 1 < n && !(cdf[lo + 1] > cdf[lo])) /* never a segment of zero weight */
        lo++;
    return lo;
}
