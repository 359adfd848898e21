/*
 * A BC6H_UFLOAT encoder (vkFormat 143, DXGI_FORMAT_BC6H_UF16): 4 x 4 texels of unsigned half
 * floats in 16 bytes, 1 byte per texel on the GPU, what desktop and console engines sample
 * lightmaps from. Debian has no BC6H encoder (libnvtt-dev is 2.0.8, older than BC6H), so
 * lmbake carries this one; the tests read its blocks back through OpenImageIO's DDS reader,
 * a decoder written by others (docs/output.md).
 *
 * The format (Microsoft, "BC6H Format", Direct3D 11 documentation; Khronos Data Format
 * Specification 1.3, "BC6H"): a block holds a mode, two endpoints per region and a 4-bit index
 * per texel (3 for the anchor texel) into 16 weights between the endpoints. Endpoints are
 * quantized half-float bit patterns; the decoder interpolates them as integers, so BC6H
 * interpolates in a domain close to log2 of the value: its error is relative, as a lightmap's
 * should be. This encoder uses the four one-region modes (11: 10-bit endpoints; 12, 13, 14:
 * an 11-, 12- or 16-bit endpoint and a 9-, 8- or 4-bit difference to the other), and keeps,
 * per block, the mode whose decoded texels lie closest to the input in that domain.
 */
#ifndef LMBAKE_BC6H_H
#define LMBAKE_BC6H_H

#include <stddef.h>
#include <stdint.h>

/* BC6H's largest value (the largest finite half float); input above it is clamped. */
#define LMB_BC6H_MAX 65504.0f

/* The blocks of a w x h RGB float image (3 floats per texel, rows top to bottom) into blocks:
 * ceil(w / 4) x ceil(h / 4) blocks of 16 bytes, rows of blocks top to bottom (a block past the
 * image's edge repeats its last row or column). Negative and NaN values are 0. care (may be
 * NULL: all weigh 1) weighs each texel's error in its block's fit (w x h): 0 for a texel no
 * lookup reads (it weighs 1/1000), else its weight; so a block that holds a chart's edge and
 * padding spends its precision on the chart. Runs on `threads` threads (0: all), the same bytes on any count. Returns the number of texels
 * with a channel above LMB_BC6H_MAX (clamped). */
uint64_t lmb_bc6h_encode(uint32_t w, uint32_t h, const float *rgb, const uint8_t *care, int threads, uint8_t *blocks);

/* The bytes lmb_bc6h_encode writes for a w x h image. */
size_t lmb_bc6h_size(uint32_t w, uint32_t h);

#endif
