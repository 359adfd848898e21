/*
 * Rectangles on shelves: the placement of instances whose TEXCOORD_1 layout is fixed before
 * packing (a mesh's own, atlas.keep_uv1; one layout shared by EXT_mesh_gpu_instancing copies),
 * each a w x h rectangle of a shared atlas, never rotated (an engine maps the layout with one
 * scale and offset). Items of one group land in one atlas (the copies of one instanced node
 * share a material, so one lightmap texture).
 */
#ifndef LMBAKE_RECTS_H
#define LMBAKE_RECTS_H

#include <lmbake/lmbake.h>

typedef struct lmb_rect_item {
    uint32_t w, h;  /* texels */
    uint32_t group; /* items of one group share an atlas; groups are placed in the order given */
} lmb_rect_item;

typedef struct lmb_rect_result {
    uint32_t atlas_count;
    uint32_t *width, *height; /* per atlas, multiples of 4, cropped to what is used */
    uint32_t *atlas, *x, *y;  /* per item */
    uint32_t failed_group;    /* after LMB_ERR_INPUT: the group that does not fit one atlas */
} lmb_rect_result;

/* Places items (grouped runs in the order given; within a group largest first) on shelves
 * `padding` texels apart in atlases of at most max_size a side; with block > 1 every item's
 * corner on the block grid and the gaps rounded up to it (no block holds two items: a
 * block-compressed lightmap's copies are encoded apart, as pack.h's charts are). A group that does not fit
 * what is left of the current atlas starts a new one; one that does not fit an empty atlas is
 * LMB_ERR_INPUT (out->failed_group). Free out with lmb_rect_result_free, also after an error. */
lmb_status lmb_place_rects(const lmb_rect_item *items, uint32_t n, uint32_t padding, uint32_t block,
                           uint32_t max_size, lmb_rect_result *out, lmb_error *err);
void lmb_rect_result_free(lmb_rect_result *r);

#endif
