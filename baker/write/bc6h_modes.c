/*
 * BC6H's block layouts (see bc6h_modes.h). Each mode's endpoint bits as runs, in block order
 * after the mode field, as the format's tables list them ("rw[9:0]" = the red channel of
 * endpoint w, bits 0 to 9; w x y z are region 0's two endpoints, then region 1's). A one-region
 * block's indices start at bit 65, a two-region block's (after the 5-bit partition) at 82.
 */
#include "bc6h_modes.h"

#include <string.h>

enum { WR, WG, WB, XR, XG, XB, YR, YG, YB, ZR, ZG, ZB, D = LMB_BC6H_PARTITION };
#define R(f, first, count) {f, first, count}

const lmb_bc6h_mode lmb_bc6h_modes[LMB_BC6H_MODES] = {
    /* two regions, 3-bit indices */
    {0x00, 2, 2, 10, {5, 5, 5}, 20,
     {R(YG, 4, 1), R(YB, 4, 1), R(ZB, 4, 1), R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 5), R(ZG, 4, 1),
      R(YG, 0, 4), R(XG, 0, 5), R(ZB, 0, 1), R(ZG, 0, 4), R(XB, 0, 5), R(ZB, 1, 1), R(YB, 0, 4), R(YR, 0, 5),
      R(ZB, 2, 1), R(ZR, 0, 5), R(ZB, 3, 1), R(D, 0, 5)}},
    {0x01, 2, 2, 7, {6, 6, 6}, 22,
     {R(YG, 5, 1), R(ZG, 4, 2), R(WR, 0, 7), R(ZB, 0, 2), R(YB, 4, 1), R(WG, 0, 7), R(YB, 5, 1), R(ZB, 2, 1),
      R(YG, 4, 1), R(WB, 0, 7), R(ZB, 3, 1), R(ZB, 5, 1), R(ZB, 4, 1), R(XR, 0, 6), R(YG, 0, 4), R(XG, 0, 6),
      R(ZG, 0, 4), R(XB, 0, 6), R(YB, 0, 4), R(YR, 0, 6), R(ZR, 0, 6), R(D, 0, 5)}},
    {0x02, 5, 2, 11, {5, 4, 4}, 19,
     {R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 5), R(WR, 10, 1), R(YG, 0, 4), R(XG, 0, 4), R(WG, 10, 1),
      R(ZB, 0, 1), R(ZG, 0, 4), R(XB, 0, 4), R(WB, 10, 1), R(ZB, 1, 1), R(YB, 0, 4), R(YR, 0, 5), R(ZB, 2, 1),
      R(ZR, 0, 5), R(ZB, 3, 1), R(D, 0, 5)}},
    {0x06, 5, 2, 11, {4, 5, 4}, 21,
     {R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 4), R(WR, 10, 1), R(ZG, 4, 1), R(YG, 0, 4), R(XG, 0, 5),
      R(WG, 10, 1), R(ZG, 0, 4), R(XB, 0, 4), R(WB, 10, 1), R(ZB, 1, 1), R(YB, 0, 4), R(YR, 0, 4), R(ZB, 0, 1),
      R(ZB, 2, 1), R(ZR, 0, 4), R(YG, 4, 1), R(ZB, 3, 1), R(D, 0, 5)}},
    {0x0a, 5, 2, 11, {4, 4, 5}, 20,
     {R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 4), R(WR, 10, 1), R(YB, 4, 1), R(YG, 0, 4), R(XG, 0, 4),
      R(WG, 10, 1), R(ZB, 0, 1), R(ZG, 0, 4), R(XB, 0, 5), R(WB, 10, 1), R(YB, 0, 4), R(YR, 0, 4), R(ZB, 1, 2),
      R(ZR, 0, 4), R(ZB, 4, 1), R(ZB, 3, 1), R(D, 0, 5)}},
    {0x0e, 5, 2, 9, {5, 5, 5}, 20,
     {R(WR, 0, 9), R(YB, 4, 1), R(WG, 0, 9), R(YG, 4, 1), R(WB, 0, 9), R(ZB, 4, 1), R(XR, 0, 5), R(ZG, 4, 1),
      R(YG, 0, 4), R(XG, 0, 5), R(ZB, 0, 1), R(ZG, 0, 4), R(XB, 0, 5), R(ZB, 1, 1), R(YB, 0, 4), R(YR, 0, 5),
      R(ZB, 2, 1), R(ZR, 0, 5), R(ZB, 3, 1), R(D, 0, 5)}},
    {0x12, 5, 2, 8, {6, 5, 5}, 19,
     {R(WR, 0, 8), R(ZG, 4, 1), R(YB, 4, 1), R(WG, 0, 8), R(ZB, 2, 1), R(YG, 4, 1), R(WB, 0, 8), R(ZB, 3, 2),
      R(XR, 0, 6), R(YG, 0, 4), R(XG, 0, 5), R(ZB, 0, 1), R(ZG, 0, 4), R(XB, 0, 5), R(ZB, 1, 1), R(YB, 0, 4),
      R(YR, 0, 6), R(ZR, 0, 6), R(D, 0, 5)}},
    {0x16, 5, 2, 8, {5, 6, 5}, 22,
     {R(WR, 0, 8), R(ZB, 0, 1), R(YB, 4, 1), R(WG, 0, 8), R(YG, 5, 1), R(YG, 4, 1), R(WB, 0, 8), R(ZG, 5, 1),
      R(ZB, 4, 1), R(XR, 0, 5), R(ZG, 4, 1), R(YG, 0, 4), R(XG, 0, 6), R(ZG, 0, 4), R(XB, 0, 5), R(ZB, 1, 1),
      R(YB, 0, 4), R(YR, 0, 5), R(ZB, 2, 1), R(ZR, 0, 5), R(ZB, 3, 1), R(D, 0, 5)}},
    {0x1a, 5, 2, 8, {5, 5, 6}, 22,
     {R(WR, 0, 8), R(ZB, 1, 1), R(YB, 4, 1), R(WG, 0, 8), R(YB, 5, 1), R(YG, 4, 1), R(WB, 0, 8), R(ZB, 5, 1),
      R(ZB, 4, 1), R(XR, 0, 5), R(ZG, 4, 1), R(YG, 0, 4), R(XG, 0, 5), R(ZB, 0, 1), R(ZG, 0, 4), R(XB, 0, 6),
      R(YB, 0, 4), R(YR, 0, 5), R(ZB, 2, 1), R(ZR, 0, 5), R(ZB, 3, 1), R(D, 0, 5)}},
    {0x1e, 5, 2, 6, {0, 0, 0}, 23,
     {R(WR, 0, 6), R(ZG, 4, 1), R(ZB, 0, 2), R(YB, 4, 1), R(WG, 0, 6), R(YG, 5, 1), R(YB, 5, 1), R(ZB, 2, 1),
      R(YG, 4, 1), R(WB, 0, 6), R(ZG, 5, 1), R(ZB, 3, 1), R(ZB, 5, 1), R(ZB, 4, 1), R(XR, 0, 6), R(YG, 0, 4),
      R(XG, 0, 6), R(ZG, 0, 4), R(XB, 0, 6), R(YB, 0, 4), R(YR, 0, 6), R(ZR, 0, 6), R(D, 0, 5)}},
    /* one region, 4-bit indices */
    {0x03, 5, 1, 10, {0, 0, 0}, 6,
     {R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 10), R(XG, 0, 10), R(XB, 0, 10)}},
    {0x07, 5, 1, 11, {9, 9, 9}, 9,
     {R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 9), R(WR, 10, 1), R(XG, 0, 9), R(WG, 10, 1), R(XB, 0, 9),
      R(WB, 10, 1)}},
    {0x0b, 5, 1, 12, {8, 8, 8}, 9,
     {R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 8), R(WR, 11, -2), R(XG, 0, 8), R(WG, 11, -2), R(XB, 0, 8),
      R(WB, 11, -2)}},
    {0x0f, 5, 1, 16, {4, 4, 4}, 9,
     {R(WR, 0, 10), R(WG, 0, 10), R(WB, 0, 10), R(XR, 0, 4), R(WR, 15, -6), R(XG, 0, 4), R(WG, 15, -6), R(XB, 0, 4),
      R(WB, 15, -6)}},
};

const uint16_t lmb_bc6h_partitions[32] = {
    0xCCCC, 0x8888, 0xEEEE, 0xECC8, 0xC880, 0xFEEC, 0xFEC8, 0xEC80, 0xC800, 0xFFEC, 0xFE80,
    0xE800, 0xFFE8, 0xFF00, 0xFFF0, 0xF000, 0xF710, 0x008E, 0x7100, 0x08CE, 0x008C, 0x7310,
    0x3100, 0x8CCE, 0x088C, 0x3110, 0x6666, 0x366C, 0x17E8, 0x0FF0, 0x718E, 0x399C};

const uint8_t lmb_bc6h_anchor2[32] = {15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
                                      15, 2,  8,  2,  2,  8,  8,  15, 2,  8,  2,  2,  8,  8,  2,  2};

const int lmb_bc6h_weights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};
const int lmb_bc6h_weights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};

int lmb_bc6h_unquantize(int q, int bits)
{
    if (bits >= 15)
        return q;
    if (q == 0)
        return 0;
    if (q == (1 << bits) - 1)
        return 0xffff;
    return ((q << 16) + 0x8000) >> bits;
}

static void put_bits(uint8_t block[16], int *at, uint32_t value, int count)
{
    for (int k = 0; k < count; k++, (*at)++)
        if ((value >> k) & 1u)
            block[*at >> 3] |= (uint8_t)(1u << (*at & 7));
}

void lmb_bc6h_pack(int m, const int q[4][3], int partition, const int idx[16], uint8_t block[16])
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[m];
    int stored[4][3];
    for (int e = 0; e < 2 * md->regions; e++)
        for (int c = 0; c < 3; c++)
            stored[e][c] = e > 0 && md->delta[c] ? (q[e][c] - q[0][c]) & ((1 << md->delta[c]) - 1) : q[e][c];
    memset(block, 0, 16);
    int at = 0;
    put_bits(block, &at, md->value, md->mode_bits);
    for (int r = 0; r < md->runs; r++) {
        const lmb_bc6h_run *run = &md->run[r];
        int n = run->count > 0 ? run->count : -run->count, step = run->count > 0 ? 1 : -1;
        uint32_t v = run->field == LMB_BC6H_PARTITION ? (uint32_t)partition
                                                      : (uint32_t)stored[run->field / 3][run->field % 3];
        for (int k = 0; k < n; k++)
            put_bits(block, &at, (v >> (run->first + step * k)) & 1u, 1);
    }
    int ib = md->regions == 1 ? 4 : 3, anchor2 = md->regions == 2 ? lmb_bc6h_anchor2[partition] : -1;
    for (int i = 0; i < 16; i++)
        put_bits(block, &at, (uint32_t)idx[i], i == 0 || i == anchor2 ? ib - 1 : ib);
}
