/*
 * RGBM encoding (baker/write/rgbm.c): the round trip within 1% of the texel's largest
 * channel from range 1e-5 to the range, zero, clamping counted only for valid texels, the
 * auto range; and the squares of kept-TEXCOORD_1 instances (baker/pack/keep_uv1.c): placed
 * without overlap, padding apart, inside their atlases, a new atlas when one is full.
 */
#include "check.h"

#include "pack/keep_uv1.h"
#include "post/dilate.h"
#include "write/rgbm.h"

#include <stdlib.h>

static void test_rgbm_round_trip(void)
{
    const double range = 64;
    double worst = 0;
    for (int k = 0; k <= 500; k++) { /* 1e-5 .. 1 of the range, and colours */
        double top = range * pow(10.0, -5.0 * k / 500.0);
        float rgb[3] = {(float)top, (float)(top * (k % 7) / 7.0), (float)(top * (k % 3) / 3.0)};
        uint8_t valid = LMB_TEXEL_VALID, px[4];
        CHECK_INT(lmb_rgbm_encode(rgb, &valid, 1, range, px), 0);
        double back[3];
        lmb_rgbm_decode(px, range, back);
        for (int c = 0; c < 3; c++) {
            double e = fabs(back[c] - rgb[c]) / top;
            worst = e > worst ? e : worst;
        }
    }
    CHECK(worst <= 0.01);
    float zero[3] = {0, 0, 0};
    uint8_t valid = LMB_TEXEL_VALID, px[4];
    lmb_rgbm_encode(zero, &valid, 1, range, px);
    CHECK(px[0] == 0 && px[1] == 0 && px[2] == 0 && px[3] == 0);
}

static void test_rgbm_clamp(void)
{
    float rgb[9] = {100, 1, 1, 100, 1, 1, 1, 2, 3};
    uint8_t valid[3] = {LMB_TEXEL_VALID, LMB_TEXEL_INSIDE, LMB_TEXEL_VALID}, px[12];
    CHECK_INT(lmb_rgbm_encode(rgb, valid, 3, 10, px), 1); /* the inside texel is not counted */
    double back[3];
    lmb_rgbm_decode(px, 10, back);
    CHECK_NEAR(back[0], 10, 1e-9); /* clamped to the range */
    CHECK_NEAR(lmb_rgbm_range(0, rgb, valid, 3), 128, 0); /* auto: 100 -> 128 */
    CHECK_NEAR(lmb_rgbm_range(5, rgb, valid, 3), 5, 0);
    float one[3] = {1, 0.5f, 0};
    CHECK_NEAR(lmb_rgbm_range(0, one, valid, 1), 1, 0); /* a power of two stays */
    float dark[3] = {0, 0, 0};
    CHECK_NEAR(lmb_rgbm_range(0, dark, valid, 1), 1, 0);
}

static void test_squares(void)
{
    const uint32_t n = 7, side[7] = {100, 40, 40, 64, 16, 100, 30}, pad = 2, max = 128;
    uint32_t atlas_of[7], x[7], y[7], count = 0, *w = NULL, *h = NULL;
    lmb_error err;
    CHECK_INT(lmb_place_squares(side, n, pad, max, atlas_of, x, y, &count, &w, &h, &err), LMB_OK);
    CHECK(count >= 2); /* two 100s cannot share a 128 atlas */
    for (uint32_t i = 0; i < n; i++) {
        CHECK(atlas_of[i] < count);
        CHECK(x[i] + side[i] <= w[atlas_of[i]] && y[i] + side[i] <= h[atlas_of[i]]);
        CHECK(w[atlas_of[i]] <= max && h[atlas_of[i]] <= max);
        for (uint32_t j = i + 1; j < n; j++) {
            if (atlas_of[i] != atlas_of[j])
                continue;
            int apart = x[i] + side[i] + pad <= x[j] || x[j] + side[j] + pad <= x[i] || y[i] + side[i] + pad <= y[j] ||
                        y[j] + side[j] + pad <= y[i];
            CHECK(apart);
        }
    }
    for (uint32_t a = 0; a < count; a++)
        CHECK(w[a] % 4 == 0 && h[a] % 4 == 0);
    free(w);
    free(h);
}

int main(void)
{
    test_rgbm_round_trip();
    test_rgbm_clamp();
    test_squares();
    return check_failures();
}
