/*
 * KTX2 texel encoders (baker/write/ktx2.c) at the edges of their formats: zero, NaN and
 * negatives to 0, values past the range to its largest, round-to-nearest-even ties, half
 * subnormals, and the shared exponent chosen so the largest channel keeps 9 bits; the
 * container's fixed bytes (identifier, level index) for a 1 x 1 image; BC6H's layouts (every
 * mode's fields fill its block exactly, every endpoint bit once) and a mip chain's levels
 * (smallest first, each at a multiple of 16, its size ceil(w/4) x ceil(h/4) x 16).
 */
#include "check.h"

#include "write/bc6h.h"
#include "write/bc6h_modes.h"
#include "write/ktx2.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double e5b9g9r9_channel(uint32_t v, int c)
{
    return (double)((v >> (9 * c)) & 511u) * ldexp(1.0, (int)(v >> 27) - 15 - 9);
}

static void test_half(void)
{
    CHECK_INT(lmb_float_to_half(0.0f), 0);
    CHECK_INT(lmb_float_to_half(1.0f), 0x3c00);
    CHECK_INT(lmb_float_to_half(-2.0f), 0xc000);
    CHECK_INT(lmb_float_to_half(65504.0f), 0x7bff);
    CHECK_INT(lmb_float_to_half(1e9f), 0x7bff);            /* past the range: the largest */
    CHECK_INT(lmb_float_to_half(NAN), 0);
    CHECK_INT(lmb_float_to_half(1.0f + 1.0f / 2048), 0x3c00); /* a tie: to even */
    CHECK_INT(lmb_float_to_half(1.0f + 3.0f / 2048), 0x3c02); /* a tie: to even, up */
    CHECK_INT(lmb_float_to_half(ldexpf(1.0f, -24)), 0x0001);  /* the smallest subnormal */
    CHECK_INT(lmb_float_to_half(ldexpf(1.0f, -26)), 0);       /* below half of it */
}

static void test_e5b9g9r9(void)
{
    CHECK_INT(lmb_pack_e5b9g9r9(0, 0, 0) & 0x7ffffffu, 0);
    uint32_t v = lmb_pack_e5b9g9r9(1.0f, 0.5f, 0.25f);
    CHECK_NEAR(e5b9g9r9_channel(v, 0), 1.0, 0);
    CHECK_NEAR(e5b9g9r9_channel(v, 1), 0.5, 0);
    CHECK_NEAR(e5b9g9r9_channel(v, 2), 0.25, 0);
    v = lmb_pack_e5b9g9r9(1e9f, -3.0f, NAN); /* past the range, negative, NaN */
    CHECK_NEAR(e5b9g9r9_channel(v, 0), 65408.0, 0);
    CHECK_NEAR(e5b9g9r9_channel(v, 1), 0.0, 0);
    CHECK_NEAR(e5b9g9r9_channel(v, 2), 0.0, 0);
    /* 1023.9 rounds up to 1024: the exponent grows so the mantissa fits 9 bits */
    v = lmb_pack_e5b9g9r9(1023.9f, 1.0f, 0.0f);
    CHECK_NEAR(e5b9g9r9_channel(v, 0), 1024.0, 0);
    CHECK((v & 511u) <= 511u && (v & 511u) == 256u);
    for (int k = 0; k < 1000; k++) { /* every channel within 2^-9 of the largest */
        float c[3] = {(float)rand() / RAND_MAX * 100, (float)rand() / RAND_MAX * 10, (float)rand() / RAND_MAX};
        v = lmb_pack_e5b9g9r9(c[0], c[1], c[2]);
        for (int j = 0; j < 3; j++)
            CHECK(fabs(e5b9g9r9_channel(v, j) - c[j]) <= ldexp(c[0] > c[1] ? c[0] : c[1], -9) + 1e-12);
    }
}

static double small_value(uint32_t v, int mantissa)
{
    uint32_t e = v >> mantissa, f = v & ((1u << mantissa) - 1u);
    return e ? (1 + (double)f / (1u << mantissa)) * ldexp(1.0, (int)e - 15) : (double)f * ldexp(1.0, -14 - mantissa);
}

static void test_b10g11r11(void)
{
    uint32_t v = lmb_pack_b10g11r11(1.0f, 2.0f, 0.5f);
    CHECK_NEAR(small_value(v & 0x7ffu, 6), 1.0, 0);
    CHECK_NEAR(small_value((v >> 11) & 0x7ffu, 6), 2.0, 0);
    CHECK_NEAR(small_value(v >> 22, 5), 0.5, 0);
    v = lmb_pack_b10g11r11(1e9f, -1.0f, 1e9f);
    CHECK_NEAR(small_value(v & 0x7ffu, 6), 65024.0, 0);
    CHECK_NEAR(small_value((v >> 11) & 0x7ffu, 6), 0.0, 0);
    CHECK_NEAR(small_value(v >> 22, 5), 64512.0, 0);
    /* 1 + 1/128 is half way between 11-bit neighbours 1 and 1 + 1/64: to even (1) */
    CHECK_NEAR(small_value(lmb_pack_b10g11r11(1.0f + 1.0f / 128, 0, 0) & 0x7ffu, 6), 1.0, 0);
}

static void test_container(void)
{
    float rgb[3] = {1.0f, 2.0f, 3.0f};
    uint8_t *data;
    size_t size;
    lmb_error err = {LMB_OK, ""};
    lmb_ktx2_options o = {LMB_KTX2_RGBA16F, 0, 0, 1, NULL};
    CHECK_INT(lmb_ktx2_encode(1, 1, rgb, &o, &data, &size, NULL, &err), LMB_OK);
    static const uint8_t id[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
    CHECK(size > 80 && memcmp(data, id, 12) == 0);
    uint32_t vk, levels;
    uint64_t offset, length;
    memcpy(&vk, data + 12, 4);
    memcpy(&levels, data + 40, 4);
    memcpy(&offset, data + 80, 8);
    memcpy(&length, data + 88, 8);
    CHECK_INT(vk, 97);
    CHECK_INT(levels, 1);
    CHECK(length == 8 && offset + length == size && offset % 8 == 0); /* the level last, aligned */
    uint16_t half[4];
    memcpy(half, data + offset, 8);
    CHECK_INT(half[0], 0x3c00);
    CHECK_INT(half[1], 0x4000);
    CHECK_INT(half[2], 0x4200);
    CHECK_INT(half[3], 0x3c00); /* alpha 1 */
    free(data);
}

/* Each mode's mode field, endpoint runs, partition and indices fill 128 bits, and each endpoint
 * bit of its precision (w's bits; x, y, z: their difference's bits or w's) appears once. */
static void test_bc6h_layouts(void)
{
    for (int m = 0; m < LMB_BC6H_MODES; m++) {
        const lmb_bc6h_mode *md = &lmb_bc6h_modes[m];
        int seen[13][16] = {{0}}, bits = md->mode_bits;
        for (int r = 0; r < md->runs; r++) {
            const lmb_bc6h_run *run = &md->run[r];
            int n = run->count > 0 ? run->count : -run->count, step = run->count > 0 ? 1 : -1;
            for (int k = 0; k < n; k++)
                seen[run->field][run->first + step * k]++;
            bits += n;
        }
        int indices = md->regions == 1 ? 16 * 4 - 1 : 16 * 3 - 2;
        CHECK_INT(bits + indices, 128);
        for (int e = 0; e < 2 * md->regions; e++)
            for (int c = 0; c < 3; c++) {
                int want = e > 0 && md->delta[c] ? md->delta[c] : md->bits;
                for (int b = 0; b < 16; b++)
                    CHECK_INT(seen[3 * e + c][b], b < want ? 1 : 0);
            }
        for (int b = 0; b < 16; b++)
            CHECK_INT(seen[LMB_BC6H_PARTITION][b], md->regions == 2 && b < 5 ? 1 : 0);
    }
    /* every partition's second anchor lies in region 1 */
    for (int p = 0; p < 32; p++)
        CHECK_INT((lmb_bc6h_partitions[p] >> lmb_bc6h_anchor2[p]) & 1, 1);
}

/* A 13 x 6 BC6H image with a mip chain: 4 levels (13x6, 6x3, 3x1, 1x1), stored smallest first. */
static void test_block_levels(void)
{
    float rgb[13 * 6 * 3];
    for (int i = 0; i < 13 * 6 * 3; i++)
        rgb[i] = 0.5f + (float)(i % 7);
    lmb_ktx2_options o = {LMB_KTX2_BC6H, 0, 1, 1, NULL};
    uint8_t *data;
    size_t size;
    lmb_error err = {LMB_OK, ""};
    lmb_ktx2_report rep = {0, 0};
    CHECK_INT(lmb_ktx2_encode(13, 6, rgb, &o, &data, &size, &rep, &err), LMB_OK);
    uint32_t vk, type_size, levels;
    memcpy(&vk, data + 12, 4);
    memcpy(&type_size, data + 16, 4);
    memcpy(&levels, data + 40, 4);
    CHECK_INT(vk, 143);
    CHECK_INT(type_size, 1);
    CHECK_INT(levels, 4);
    static const uint32_t w[4] = {13, 6, 3, 1}, h[4] = {6, 3, 1, 1};
    uint64_t prev = UINT64_MAX;
    for (uint32_t k = 0; k < 4; k++) {
        uint64_t at, len, raw;
        memcpy(&at, data + 80 + 24 * k, 8);
        memcpy(&len, data + 88 + 24 * k, 8);
        memcpy(&raw, data + 96 + 24 * k, 8);
        CHECK(len == (uint64_t)((w[k] + 3) / 4) * ((h[k] + 3) / 4) * 16 && raw == len);
        CHECK(at % 16 == 0 && at + len <= size && at < prev); /* smaller levels lie earlier */
        prev = at;
    }
    CHECK_INT((int)rep.clamped, 0);
    free(data);
    /* a texel past BC6H's range is clamped and counted */
    rgb[0] = 1e6f;
    o.mipmaps = 0;
    CHECK_INT(lmb_ktx2_encode(13, 6, rgb, &o, &data, &size, &rep, &err), LMB_OK);
    CHECK_INT((int)rep.clamped, 1);
    free(data);
}

int main(void)
{
    test_bc6h_layouts();
    test_block_levels();
    test_half();
    test_e5b9g9r9();
    test_b10g11r11();
    test_container();
    return check_failures();
}
