/*
 * The lightmap formats lmbake writes itself, without loading the OpenImageIO module
 * (image_native.c): .exr, .hdr and .png. image_module.c sends those here and everything else
 * (reading any image, other extensions) to the module.
 */
#ifndef LMBAKE_IMAGE_NATIVE_H
#define LMBAKE_IMAGE_NATIVE_H

#include <lmbake/lmbake.h>

/* 1 if path's extension is written here: .exr and .hdr for float pixels (f32 = 1), .png for
 * 8-bit ones (f32 = 0). */
int lmb_image_native_writes(const char *path, int f32);

/* As lmb_image_write_u8 / lmb_image_write_f32 (image_adapter.h), for the extensions above. */
lmb_status lmb_image_native_write_u8(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                                     const uint8_t *pixels, lmb_error *err);
lmb_status lmb_image_native_write_f32(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                                      const float *pixels, lmb_error *err);

/* An RGB .exr in 32-bit float whatever its values (light groups: a game's sum of the groups'
 * files then matches the bake's sum to float rounding, where half float would hold 11 bits). */
lmb_status lmb_image_native_write_exr_float(const char *path, uint32_t width, uint32_t height, const float *pixels,
                                            lmb_error *err);

#endif
