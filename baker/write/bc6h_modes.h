/*
 * BC6H's block layouts (Microsoft, "BC6H Format", Direct3D 11 documentation; Khronos Data Format
 * Specification 1.3, section "BC6H"): the 14 modes' endpoint precisions and where each endpoint
 * bit lies in the 128-bit block, the 32 two-region partitions and their second anchors, and the
 * packing of one block from quantized endpoints and indices. The encoder (bc6h.c) searches;
 * this file only knows the format.
 */
#ifndef LMBAKE_BC6H_MODES_H
#define LMBAKE_BC6H_MODES_H

#include <stdint.h>

#define LMB_BC6H_MODES 14

/* A run of endpoint bits in the block: field (endpoint e x 3 + channel c, e: 0 w, 1 x, 2 y, 3 z;
 * LMB_BC6H_PARTITION: the partition number), its first bit and how many follow, upward (count
 * > 0) or downward (count < 0: first, first - 1, ...). */
typedef struct lmb_bc6h_run {
    uint8_t field, first;
    int8_t count;
} lmb_bc6h_run;

#define LMB_BC6H_PARTITION 12

typedef struct lmb_bc6h_mode {
    uint8_t value;     /* the mode field's value */
    uint8_t mode_bits; /* 2 or 5 */
    uint8_t regions;   /* 1 or 2 */
    uint8_t bits;      /* endpoint w's precision (and every endpoint's when untransformed) */
    uint8_t delta[3];  /* transformed modes: x, y, z stored as signed differences from w of these
                          bits per channel; 0: stored whole */
    uint8_t runs;
    lmb_bc6h_run run[26];
} lmb_bc6h_mode;

extern const lmb_bc6h_mode lmb_bc6h_modes[LMB_BC6H_MODES];

/* Two-region partitions: bit i set = texel i (row-major) in region 1; the texel that anchors
 * region 1 (region 0's anchor is texel 0). */
extern const uint16_t lmb_bc6h_partitions[32];
extern const uint8_t lmb_bc6h_anchor2[32];

/* Interpolation weights (of 64) for 4-bit (one region) and 3-bit (two regions) indices. */
extern const int lmb_bc6h_weights4[16];
extern const int lmb_bc6h_weights3[8];

/* The decoder's unquantization of an unsigned endpoint of `bits` bits to 16 bits. */
int lmb_bc6h_unquantize(int q, int bits);

/* Writes a block of mode m: endpoints q (regions x 2 of them, each 3 channels, already within
 * the mode's precision, differences within their bits), partition (two regions), indices idx
 * (anchors' top bit 0). */
void lmb_bc6h_pack(int m, const int q[4][3], int partition, const int idx[16], uint8_t block[16]);

#endif
