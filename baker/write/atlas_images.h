/*
 * Writing one atlas's lightmap: <stem>-lightmap-N.exr (linear irradiance, half float or 32-bit
 * when beyond half's range), .hdr (the glTF references it), .png (tonemapped preview: the
 * 95th percentile of valid texels' luminance at 0.8, Reinhard, sRGB) and, with output.formats
 * mask, -mask.png (255 valid, 128 inside geometry, 0 padding); with ktx2, .ktx2 (write/ktx2.h,
 * output.ktx2_format and output.ktx2_supercompression); with rgbm, -rgbm.png (write/rgbm.h);
 * with output.directional, -dir.exr and -dir.png (and -dir.ktx2 in half floats with ktx2).
 * Lightmap files hold output.scale's quantity: E (lux) or E / pi.
 */
#ifndef LMBAKE_ATLAS_IMAGES_H
#define LMBAKE_ATLAS_IMAGES_H

#include <lmbake/lmbake.h>

#include "ktx2.h"

/* What writing an atlas decided, for the glTF and the log. */
typedef struct lmb_atlas_output {
    double rgbm_range;     /* rgbm: the range written */
    uint64_t rgbm_clamped; /* rgbm: valid texels above it, clamped */
    lmb_ktx2_report ktx2;  /* ktx2: texels above the block format's range, clamped */
} lmb_atlas_output;

/* irradiance: 3 floats per atlas texel (E, lux); valid: LMB_TEXEL_* per texel. Files go into dir.
 * exr_float: the .exr in 32-bit float (light groups), else half float where every value fits. */
lmb_status lmb_write_atlas_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t atlas,
                                  const float *irradiance, const uint8_t *valid, uint32_t width, uint32_t height,
                                  int exr_float, lmb_atlas_output *info, lmb_error *err);

/* The directional atlas (output.directional; docs/artists.md): d holds the
 * light's mean direction D per texel (3 floats, world space, |D| <= 1).
 * <stem>-lightmap-N-dir.exr holds D as floats, <stem>-lightmap-N-dir.png (the glTF references
 * it) (D + 1) / 2 in 8 bits, linear. */
lmb_status lmb_write_direction_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t atlas,
                                      const float *d, uint32_t width, uint32_t height, lmb_error *err);

/* <stem>-lightmap-N.hdr alone in dir: irradiance (3 floats per texel) as output.scale says, as the
 * lightmap's own .hdr is written (the watch's stages, watch/stages_out.h). */
lmb_status lmb_write_hdr_image(const lmb_config *cfg, const char *dir, const char *stem, uint32_t atlas,
                               const float *irradiance, uint32_t width, uint32_t height, lmb_error *err);

/* A light group's lightmap (docs/light-groups.md): <stem>-lightmap-N-group-NAME.exr (32-bit
 * float) and .hdr, and with output.formats' ktx2 a .ktx2 in output.ktx2's format (its blocks
 * chosen for the texels a lookup reads, valid: LMB_TEXEL_* per texel, as the level's own);
 * irradiance (3 floats per texel) as output.scale says; a game blends the groups' files.
 * ktx2 (may be NULL) receives the KTX2's clamped texels. */
lmb_status lmb_write_group_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t atlas,
                                  const char *group, const float *irradiance, const uint8_t *valid, uint32_t width,
                                  uint32_t height, lmb_ktx2_report *ktx2, lmb_error *err);

/* Those files' paths in dir: paths[0] the .exr, paths[1] the .hdr, paths[2] the .ktx2 when
 * output.formats asks for KTX2. Returns how many (2 or 3). */
#define LMB_GROUP_IMAGE_PATH 8600
#define LMB_GROUP_FILES 3
uint32_t lmb_group_image_paths(const lmb_config *cfg, const char *dir, const char *stem, uint32_t atlas,
                               const char *group, char paths[LMB_GROUP_FILES][LMB_GROUP_IMAGE_PATH]);

/* output.shadowmask: <stem>-lightmap-N-shadowmask.png, RGBA8, per channel a light's visibility
 * (4 floats per texel in [0, 1]), linear. */
lmb_status lmb_write_shadowmask_image(const char *dir, const char *stem, uint32_t atlas, const float *v, uint32_t width,
                                      uint32_t height, lmb_error *err);

#endif
