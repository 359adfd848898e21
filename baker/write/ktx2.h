/*
 * KTX 2.0 lightmaps (output.formats ktx2) and irradiance volumes (probes/probe_volume.c): one 2D
 * or 3D texture, one level, one layer, in an HDR
 * format engines sample directly. The container follows the KTX 2.0 specification (Khronos,
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

typedef enum lmb_ktx2_format {
    LMB_KTX2_E5B9G9R9 = 0,  /* vkFormat 123 E5B9G9R9_UFLOAT_PACK32: shared exponent, 2^-9 relative */
    LMB_KTX2_B10G11R11 = 1, /* vkFormat 122 B10G11R11_UFLOAT_PACK32: what bevy's Cornell box ships */
    LMB_KTX2_RGBA16F = 2    /* vkFormat 97 R16G16B16A16_SFLOAT: half floats, alpha 1 */
} lmb_ktx2_format;

/* The Zstandard level lightmaps are written with: zstd's default is 3; 12 gains a few % on
 * lightmaps and still writes a 1024^2 atlas in well under a second. */
#define LMB_KTX2_ZSTD_LEVEL 12

/* The vkFormat number of a format. */
uint32_t lmb_ktx2_vkformat(lmb_ktx2_format f);

/* Texel encoders (round to nearest; negative and NaN -> 0; beyond the range -> its largest value). */
uint32_t lmb_pack_e5b9g9r9(float r, float g, float b);
uint32_t lmb_pack_b10g11r11(float r, float g, float b);
uint16_t lmb_float_to_half(float v);

/* The whole file for a w x h RGB float image (rows top to bottom) in *out (malloc'd, the caller
 * frees) and its size. zstd_level > 0: Zstandard supercompression at that level; 0: none. */
lmb_status lmb_ktx2_encode(uint32_t w, uint32_t h, const float *rgb, lmb_ktx2_format f, int zstd_level,
                           uint8_t **out, size_t *size, lmb_error *err);

/* The same for a 3D texture of w x h x d texels (slices front to back, each rows top to bottom;
 * KTXorientation "rdi"); d = 0 is lmb_ktx2_encode's 2D texture. */
lmb_status lmb_ktx2_encode_3d(uint32_t w, uint32_t h, uint32_t d, const float *rgb, lmb_ktx2_format f, int zstd_level,
                              uint8_t **out, size_t *size, lmb_error *err);

/* lmb_ktx2_encode (lmb_ktx2_encode_3d) written to path. */
lmb_status lmb_ktx2_write(const char *path, uint32_t w, uint32_t h, const float *rgb, lmb_ktx2_format f,
                          int zstd_level, lmb_error *err);
lmb_status lmb_ktx2_write_3d(const char *path, uint32_t w, uint32_t h, uint32_t d, const float *rgb,
                             lmb_ktx2_format f, int zstd_level, lmb_error *err);

#endif
