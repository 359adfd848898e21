/*
 * The post stage's image filters (baker/post): fireflies spread to their neighbours keep the
 * light's sum, lower the spike to the bound and leave smooth light alone (a ramp and a
 * Gaussian hot spot two texels wide are not fireflies); padding and texels inside geometry
 * are neither read nor changed.
 */
#include "check.h"

#include "texels/dilate.h"
#include "post/fireflies.h"

#include <stdlib.h>

#define W 32
#define H 24

static double lum_sum(const float *rgb, const uint8_t *state)
{
    double s = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        if (state[i] == LMB_TEXEL_VALID)
            s += 0.2126 * rgb[3 * i] + 0.7152 * rgb[3 * i + 1] + 0.0722 * rgb[3 * i + 2];
    return s;
}

static void test_fireflies(void)
{
    float rgb[3 * W * H], before[3 * W * H];
    uint8_t state[W * H];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            state[i] = x >= 28 ? LMB_TEXEL_EMPTY : (x == 0 && y < 4) ? LMB_TEXEL_INSIDE : LMB_TEXEL_VALID;
            double ramp = 1.0 + 0.05 * x, dx = x - 20, dy = y - 6;
            double hot = 6.0 * exp(-(dx * dx + dy * dy) / (2 * 2.0 * 2.0)); /* a hot spot, sigma 2 texels */
            rgb[3 * i] = (float)(ramp + hot);
            rgb[3 * i + 1] = (float)(0.8 * (ramp + hot));
            rgb[3 * i + 2] = (float)(0.5 * (ramp + hot));
        }
    size_t spike = (size_t)15 * W + 8;
    for (int c = 0; c < 3; c++)
        rgb[3 * spike + c] *= 100.0f;
    memcpy(before, rgb, sizeof rgb);
    double sum0 = lum_sum(rgb, state);
    lmb_firefly_stats st = {0, 0, 0};
    lmb_error err;
    CHECK(lmb_fireflies_spread(rgb, state, W, H, 0, &st, &err) == LMB_OK);
    CHECK_INT(st.texels, 1);
    CHECK_NEAR(lum_sum(rgb, state) / sum0, 1.0, 1e-6);   /* moved, not removed */
    CHECK_NEAR(st.total, sum0, 1e-6 * sum0);
    double l_spike = 0.2126 * rgb[3 * spike] + 0.7152 * rgb[3 * spike + 1] + 0.0722 * rgb[3 * spike + 2];
    double ramp = 1.0 + 0.05 * 8, l_ramp = ramp * (0.2126 + 0.7152 * 0.8 + 0.0722 * 0.5);
    CHECK(l_spike <= LMB_FIREFLY_FACTOR * l_ramp * 1.06); /* the median of its 5x5 is the ramp there, +-5% */
    CHECK(l_spike >= 3.5 * l_ramp);
    CHECK_NEAR(st.moved, 100.0 * l_ramp - l_spike, 1e-3 * st.moved);
    int changed = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        long x = (long)(i % W) - 8, y = (long)(i / W) - 15;
        int near = x >= -1 && x <= 1 && y >= -1 && y <= 1;
        for (int c = 0; c < 3; c++)
            if (rgb[3 * i + c] != before[3 * i + c])
                changed += !near; /* only the spike and its 8 neighbours change */
    }
    CHECK_INT(changed, 0);
}

int main(void)
{
    test_fireflies();
    return check_failures();
}
