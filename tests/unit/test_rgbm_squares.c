/*
 * RGBM encoding (baker/write/rgbm.c): the round trip within 1% of the texel's largest
 * channel from range 1e-5 to the range, zero, clamping counted only for valid texels, the
 * auto range; and the rectangles of instances with a fixed layout (baker/pack/rects.c): placed
 * without overlap, padding apart, inside their atlases, a group in one atlas, a new atlas when
 * one is full, a group too large for any atlas refused.
 */
#include "check.h"

#include "pack/rects.h"
#include "texels/dilate.h"
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

static void test_rects(void)
{
    /* groups: {0: 100, 20}, {1: 40}, {2: 64 x 32, 16}, {3: 100}, {4: 30} */
    const lmb_rect_item items[7] = {{100, 100, 0}, {20, 20, 0}, {40, 40, 1}, {64, 32, 2}, {16, 16, 2}, {100, 100, 3},
                                    {30, 30, 4}};
    const uint32_t n = 7, pad = 2, max = 128;
    lmb_rect_result r;
    lmb_error err;
    CHECK_INT(lmb_place_rects(items, n, pad, 1, max, &r, &err), LMB_OK);
    CHECK(r.atlas_count >= 2); /* two 100s cannot share a 128 atlas */
    for (uint32_t i = 0; i < n; i++) {
        CHECK(r.atlas[i] < r.atlas_count);
        CHECK(r.x[i] + items[i].w <= r.width[r.atlas[i]] && r.y[i] + items[i].h <= r.height[r.atlas[i]]);
        CHECK(r.width[r.atlas[i]] <= max && r.height[r.atlas[i]] <= max);
        for (uint32_t j = i + 1; j < n; j++) {
            if (items[i].group == items[j].group)
                CHECK_INT(r.atlas[i], r.atlas[j]); /* a group shares one atlas */
            if (r.atlas[i] != r.atlas[j])
                continue;
            int apart = r.x[i] + items[i].w + pad <= r.x[j] || r.x[j] + items[j].w + pad <= r.x[i] ||
                        r.y[i] + items[i].h + pad <= r.y[j] || r.y[j] + items[j].h + pad <= r.y[i];
            CHECK(apart);
        }
    }
    for (uint32_t a = 0; a < r.atlas_count; a++)
        CHECK(r.width[a] % 4 == 0 && r.height[a] % 4 == 0);
    lmb_rect_result_free(&r);
    /* a group larger than an atlas: refused, naming it */
    const lmb_rect_item big[3] = {{10, 10, 0}, {100, 100, 1}, {100, 100, 1}};
    CHECK_INT(lmb_place_rects(big, 3, pad, 1, max, &r, &err), LMB_ERR_INPUT);
    CHECK_INT(r.failed_group, 1);
    lmb_rect_result_free(&r);
}

int main(void)
{
    test_rgbm_round_trip();
    test_rgbm_clamp();
    test_rects();
    return check_failures();
}
