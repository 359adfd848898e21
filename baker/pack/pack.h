/*
 * The pack stage: places charts (triangles in texel units, from the unwrapper after
 * scaling to the texel density) into atlases no larger than max_size, each chart rotated
 * to its minimal bounding box, separated by `padding` texels beyond the texels it touches
 * (its conservative raster footprint) plus one texel for bilinear filtering, so that no
 * texel is reachable from two charts. Deterministic: the same input gives the same output.
 */
#ifndef LMBAKE_PACK_H
#define LMBAKE_PACK_H

#include <lmbake/lmbake.h>

typedef struct lmb_pack_chart {
    uint32_t triangle_count;
    const double *uv; /* 6 per triangle: chart-local coordinates in texel units */
    uint32_t group;   /* with lmb_pack_options.grouped: charts of one group share an atlas (an instance) */
} lmb_pack_chart;

typedef struct lmb_pack_options {
    uint32_t max_size; /* atlas side limit, texels */
    uint32_t padding;  /* texels between footprints */
    int grouped;       /* every group lands whole in one atlas; a group that cannot is an error */
    uint32_t threads;  /* charts' footprints are made on this many threads (0: all cores); the
                          packing itself, and so its result, does not depend on it */
    uint32_t block;    /* > 1: charts on a grid of block x block texels, no block shared by two
                          (block-compressed lightmaps: a block holds one chart's light, so the
                          encoder does not quantize two charts' light together); 0 or 1: none */
} lmb_pack_options;

/* The block size a config's outputs want the atlas packed on: 4 when a lightmap is written in a
 * 4 x 4 block format (output.ktx2_format bc6h or astc_hdr), else 1. */
uint32_t lmb_pack_block_for(const lmb_config *cfg);

/* Chart-local uv -> atlas texel coordinates: x = m[0] u + m[1] v + m[2], y = m[3] u + m[4] v + m[5]
 * (a rotation, possibly with a flip, and a translation: lengths are kept). */
typedef struct lmb_pack_placement {
    uint32_t atlas;
    double m[6];
} lmb_pack_placement;

typedef struct lmb_pack_result {
    uint32_t atlas_count;
    uint32_t *width, *height; /* per atlas, each <= max_size, cropped to what is used */
    lmb_pack_placement *placements; /* one per input chart */
    uint32_t failed_group;          /* after LMB_ERR_INPUT: the group that does not fit one atlas */
    uint32_t failed_chart;          /* after LMB_ERR_INPUT: a chart of it (too large alone), or UINT32_MAX */
} lmb_pack_result;

/* Fills out (caller frees with lmb_pack_result_free). A chart whose footprint cannot fit in
 * max_size x max_size is LMB_ERR_INPUT naming its index and size (lower the density); so is,
 * when grouped, a group whose footprints cannot share one atlas: found before placing
 * anything when their area exceeds it, else as soon as the group fails in an empty atlas.
 * out->failed_group / failed_chart say which. Time grows with charts and the area they
 * cover, not with the empty area searched or the number of atlases. */
lmb_status lmb_pack_charts(const lmb_pack_chart *charts, uint32_t count, const lmb_pack_options *opt,
                           lmb_pack_result *out, lmb_error *err);

void lmb_pack_result_free(lmb_pack_result *r);

/* The chart's minimal-area bounding box (the orientation the packer uses), in its units. */
void lmb_pack_chart_box(const lmb_pack_chart *c, double *w, double *h);

#endif
