/*
 * KTX 2.0 lightmaps (output.formats ktx2) and irradiance volumes (probes/probe_volume.c): one 2D
 * or 3D texture, one layer, one level or a full mip chain (2D), in an HDR format engines sample
 * directly: a packed float format (4 or 8 bytes per texel) or a block-compressed one (BC6H or
 * ASTC 4 x 4 HDR, 1 byte per texel on the GPU). The container follows the KTX 2.0 specification (Khronos,
 * "KTX File Format Specification", version 2.0): header, level index, a Basic Data Format
 * Descriptor (Khronos Data Format Specification 1.3, the samples KTX-Software's dfdutils
 * gives each vkFormat), key/value data (KTXorientation "rd", KTXwriter) and the level, with
 * optional Zstandard supercompression (scheme 2, Debian's libzstd).
 */
#ifndef LMBAKE_KTX2_H
#define LMBAKE_KTX2_H

#include <lmbake/lmbake.h>

#include <stddef.h>
#include <stdint.h>

/* The formats: lmb_ktx2_format (include/lmbake/lmbake.h, output.ktx2_format). */

/* How a KTX2 file is written. */
typedef struct lmb_ktx2_options {
    lmb_ktx2_format format;
    int zstd_level; /* > 0: Zstandard supercompression at that level; 0: none */
    int mipmaps;    /* 2D only: 1: every level down to 1 x 1, each the 2 x 2 box average of the one above */
    int threads;    /* block encoders' threads (0: all); the bytes do not depend on it */
    const uint8_t *care; /* may be NULL; w x h, nonzero where a lookup reads the texel: the block
                            encoders fit those (level 0; the mip levels weigh all texels alike) */
} lmb_ktx2_options;

/* What writing a file found: texels above the format's range, clamped (the block formats; the
 * packed ones clamp silently to their own largest value, far above any lightmap's). */
typedef struct lmb_ktx2_report {
    uint64_t clamped;
    double encode_seconds; /* the block encoder's time over every level */
} lmb_ktx2_report;

/* The Zstandard level lightmaps are written with: zstd's default is 3; 12 gains a few % on
 * lightmaps and still writes a 1024^2 atlas in well under a second. */
#define LMB_KTX2_ZSTD_LEVEL 12

/* The vkFormat number of a format. */
uint32_t lmb_ktx2_vkformat(lmb_ktx2_format f);

/* Texel encoders (round to nearest; negative and NaN -> 0; beyond the range -> its largest value). */
uint32_t lmb_pack_e5b9g9r9(float r, float g, float b);
uint32_t lmb_pack_b10g11r11(float r, float g, float b);
uint16_t lmb_float_to_half(float v);

/* Whether format f is block-compressed (4 x 4 texels in 16 bytes). */
int lmb_ktx2_is_block(lmb_ktx2_format f);

/* The whole file for a w x h RGB float image (rows top to bottom) in *out (malloc'd, the caller
 * frees) and its size; report (may be NULL) says what was clamped. */
lmb_status lmb_ktx2_encode(uint32_t w, uint32_t h, const float *rgb, const lmb_ktx2_options *o, uint8_t **out,
                           size_t *size, lmb_ktx2_report *report, lmb_error *err);

/* The same for a 3D texture of w x h x d texels (slices front to back, each rows top to bottom;
 * KTXorientation "rdi"), one level, a packed format; d = 0 is lmb_ktx2_encode's 2D texture. */
lmb_status lmb_ktx2_encode_3d(uint32_t w, uint32_t h, uint32_t d, const float *rgb, const lmb_ktx2_options *o,
                              uint8_t **out, size_t *size, lmb_ktx2_report *report, lmb_error *err);

/* The texels a bilinear lookup at a surface point reads, from an atlas's texel states: every
 * texel within 2 (Chebyshev) of a chart's texel, valid or inside geometry (w x h, 1 or 0;
 * malloc'd, NULL when out of memory). Two, not one: a chart's edge can cross texels that hold
 * no gather point (empty, filled by dilation), and a lookup on that edge reads one further.
 * Block encoders spend their precision on these (lmb_ktx2_options.care). */
uint8_t *lmb_ktx2_lookup_texels(const uint8_t *state, uint32_t w, uint32_t h);

/* lmb_ktx2_encode (lmb_ktx2_encode_3d) written to path. */
lmb_status lmb_ktx2_write(const char *path, uint32_t w, uint32_t h, const float *rgb, const lmb_ktx2_options *o,
                          lmb_ktx2_report *report, lmb_error *err);
lmb_status lmb_ktx2_write_3d(const char *path, uint32_t w, uint32_t h, uint32_t d, const float *rgb,
                             const lmb_ktx2_options *o, lmb_error *err);

#endif
