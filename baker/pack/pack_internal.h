/*
 * Shared by the pack stage's files: footprint.c turns a chart into texel masks (its
 * minimal box, the texels it touches, dilated), pack.c places masks in atlases.
 */
#ifndef LMBAKE_PACK_INTERNAL_H
#define LMBAKE_PACK_INTERNAL_H

#include "pack.h"

/* A chart's footprint in one orientation: w x h texels, bit rows of `words` words. */
typedef struct lmb_mask {
    uint32_t w, h, words;
    uint64_t *bits;
    uint32_t *first; /* per row: first set column, or w if none */
    uint32_t *last;  /* per row: last set column (valid when first < w) */
    uint32_t *run;   /* per row: longest run of set bits (an atlas row needs a free run this long) */
    uint8_t *solid;  /* per row: the set bits are one run from first to last */
    uint32_t widest_row; /* the row with the longest run: tested first */
} lmb_mask;

typedef struct lmb_pack_item {
    uint32_t chart;
    uint32_t group;
    double m[4];  /* rotation chart uv -> box frame */
    double lo[2]; /* rotated bounds: lo placed at (border, border) */
    lmb_mask shape[4]; /* footprint dilated by padding + 1, tested against the atlas; k: turned k x 90 degrees */
    lmb_mask occ[4];   /* footprint dilated by 1 (the bilinear reach), what the atlas records */
    uint64_t area;     /* set texels of shape[0] */
    uint64_t shape_hash; /* of shape[0]'s size and bits: identical masks share it */
    uint64_t occ_area; /* set texels of occ[0]: footprints never share one, so their sum bounds an atlas */
} lmb_pack_item;

/* Returns 1 when ready, 0 when out of memory, 2 when the chart's box (*bw x *bh, padding
 * included) exceeds max_size: checked before any mask is allocated. */
int lmb_pack_prepare(const lmb_pack_chart *c, uint32_t index, uint32_t border, uint32_t max_size, lmb_pack_item *it,
                     double *bw, double *bh);

void lmb_mask_free(lmb_mask *m);

static inline int lmb_mask_bit(const lmb_mask *m, uint32_t x, uint32_t y)
{
    return (int)(m->bits[(size_t)y * m->words + x / 64] >> (x % 64) & 1);
}

#endif
