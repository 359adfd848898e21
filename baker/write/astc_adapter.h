/*
 * ASTC 4 x 4 HDR blocks (vkFormat 1000066000, ASTC_4x4_SFLOAT_BLOCK: 16 bytes per 4 x 4 texels,
 * 1 byte per texel on the GPU), what mobile GPUs sample HDR lightmaps from, encoded by Arm's
 * astcenc (Debian's libastcenc-dev) behind this C header: RGB in the HDR profile, alpha 1.
 */
#ifndef LMBAKE_ASTC_ADAPTER_H
#define LMBAKE_ASTC_ADAPTER_H

#include <lmbake/lmbake.h>

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The bytes a w x h image takes: ceil(w / 4) x ceil(h / 4) blocks of 16. */
size_t lmb_astc_size(uint32_t w, uint32_t h);

/* The blocks of a w x h RGB float image (3 floats per texel, rows top to bottom; negative and NaN
 * values are 0, values above 65504 are clamped and counted into *clamped) into blocks, on
 * `threads` threads (0: all; each block is encoded alone, so any count gives the same bytes). */
lmb_status lmb_astc_hdr_encode(uint32_t w, uint32_t h, const float *rgb, int threads, uint8_t *blocks,
                               uint64_t *clamped, lmb_error *err);

#ifdef __cplusplus
}
#endif

#endif
