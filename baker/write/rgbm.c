/* RGBM encoding of a lightmap (see rgbm.h). */
#include "rgbm.h"

#include "texels/dilate.h"

#include <math.h>

double lmb_rgbm_range(double range, const float *rgb, const uint8_t *valid, size_t texels)
{
    if (range > 0)
        return range;
    double top = 0;
    for (size_t i = 0; i < texels; i++)
        for (int c = 0; valid[i] == LMB_TEXEL_VALID && c < 3; c++)
            top = rgb[3 * i + c] > top ? rgb[3 * i + c] : top;
    double r = 1;
    if (top > 0)
        r = ldexp(1.0, (int)ceil(log2(top)));
    while (top > 0 && r < top) /* log2's rounding */
        r *= 2;
    return r;
}

uint64_t lmb_rgbm_encode(const float *rgb, const uint8_t *valid, size_t texels, double range, uint8_t *rgbm)
{
    uint64_t clamped = 0;
    for (size_t i = 0; i < texels; i++) {
        double x[3], m = 0;
        int over = 0;
        for (int c = 0; c < 3; c++) {
            double v = rgb[3 * i + c] / range;
            over |= v > 1;
            v = v > 1 ? 1 : v > 0 ? v : 0;
            x[c] = sqrt(v);
            m = x[c] > m ? x[c] : m;
        }
        clamped += over && valid[i] == LMB_TEXEL_VALID;
        double a8 = ceil(m * 255.0 - 1e-9);
        a8 = a8 < 0 ? 0 : a8 > 255 ? 255 : a8;
        for (int c = 0; c < 3; c++) {
            double q = a8 > 0 ? floor(x[c] / (a8 / 255.0) * 255.0 + 0.5) : 0;
            rgbm[4 * i + c] = (uint8_t)(q > 255 ? 255 : q);
        }
        rgbm[4 * i + 3] = (uint8_t)a8;
    }
    return clamped;
}

void lmb_rgbm_decode(const uint8_t rgbm[4], double range, double out[3])
{
    double a = rgbm[3] / 255.0;
    for (int c = 0; c < 3; c++) {
        double x = rgbm[c] / 255.0 * a;
        out[c] = range * x * x;
    }
}
