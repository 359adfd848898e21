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
    double lo[2]; /* rotated bounds: lo placed at off (texels) in the masks' frame */
    uint32_t off[2];  /* border, plus the sub-block shift with blocks */
    uint32_t block;   /* mask cells are block x block texels (1: texels) */
    lmb_mask shape[4]; /* footprint dilated by padding + 1, tested against the atlas; k: turned k x 90 degrees */
    lmb_mask occ[4];   /* footprint dilated by 1 (the bilinear reach), what the atlas records */
    uint64_t area;     /* set cells of shape[0] */
    uint64_t shape_hash; /* of shape[0]'s size and bits: identical masks share it */
    uint64_t occ_area; /* set texels of occ[0]: footprints never share one, so their sum bounds an atlas */
} lmb_pack_item;

/* Returns 1 when ready, 0 when out of memory, 2 when the chart's box (*bw x *bh, padding
 * included) exceeds max_size: checked before any mask is allocated. block > 1: the masks'
 * cells are blocks of block x block texels (every block a texel of the mask touches). */
int lmb_pack_prepare(const lmb_pack_chart *c, uint32_t index, uint32_t border, uint32_t block, uint32_t max_size,
                     lmb_pack_item *it, double *bw, double *bh);

void lmb_mask_free(lmb_mask *m);

static inline int lmb_mask_bit(const lmb_mask *m, uint32_t x, uint32_t y)
{
    return (int)(m->bits[(size_t)y * m->words + x / 64] >> (x % 64) & 1);
}

/* One atlas's occupancy for placement (atlas_space.c): bit rows of recorded footprints and,
 * per row, what the search skips by. */
typedef struct lmb_atlas {
    uint32_t size, words, width; /* width: the part in use for placement */
    uint64_t *rows;
    uint32_t *free_from; /* per row: every column before it is occupied */
    uint32_t *max_run;   /* per row: the longest free run inside width */
    uint32_t used_w, used_h;
    uint32_t open_row;   /* rows below it are full up to `width` */
    uint64_t free_area;  /* texels not recorded by any footprint */
    uint32_t generation; /* bumped when occupancy shrinks or the width grows: older hints are void */
} lmb_atlas;

int lmb_atlas_open(lmb_atlas *a, uint32_t size, uint32_t width);
void lmb_atlas_free(lmb_atlas *a);
/* Placement width := size (rows are re-measured; hints of this atlas become void). */
void lmb_atlas_widen(lmb_atlas *a);
/* Bottom-left first fit of m inside a->width, starting at (from_y, from_x) (no earlier
 * position fits: an identical mask's earlier first fit); 1 with (*ox, *oy). */
int lmb_atlas_find(lmb_atlas *a, const lmb_mask *m, uint32_t from_y, uint32_t from_x, uint32_t *ox, uint32_t *oy);
/* Records footprint m at (x, y) (area: its set texels), or clears it exactly. */
void lmb_atlas_occupy(lmb_atlas *a, const lmb_mask *m, uint32_t x, uint32_t y, uint64_t area);
void lmb_atlas_vacate(lmb_atlas *a, const lmb_mask *m, uint32_t x, uint32_t y, uint64_t area);

#endif
