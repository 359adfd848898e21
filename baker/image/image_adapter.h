/*
 * The OpenImageIO adapter (C header over C++): writes lightmaps, reads textures. The format follows the
 * file extension (.png, .exr, .hdr). Files are written to a temporary name beside the
 * target and renamed into place, so a failed or interrupted write never leaves a partial
 * file under the final name.
 */
#ifndef LMBAKE_IMAGE_ADAPTER_H
#define LMBAKE_IMAGE_ADAPTER_H

#include <lmbake/lmbake.h>

#ifdef __cplusplus
extern "C" {
#endif

/* 8-bit pixels, `channels` per pixel, rows top to bottom. */
lmb_status lmb_image_write_u8(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                              const uint8_t *pixels, lmb_error *err);

/* Float pixels; .exr is written as half float with zip compression, or as 32-bit float when
 * a value is beyond half's range (65504: bright sunlight in lux). */
lmb_status lmb_image_write_f32(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                               const float *pixels, lmb_error *err);

/* The size of an image from its header alone (nothing decoded): name is a file, or with bytes
 * the format hint of an in-memory image. */
lmb_status lmb_image_size(const char *name, const uint8_t *bytes, size_t size, uint32_t *w, uint32_t *h, lmb_error *err);

/* Reads an image as RGB floats (grey is replicated, alpha dropped), rows top to bottom,
 * values as stored: 8-bit formats come back sRGB-encoded in [0, 1]. From the file `name`,
 * or from memory when bytes != NULL (then `name` only picks the format by its extension).
 * The caller frees *rgb. */
lmb_status lmb_image_read_rgb(const char *name, const uint8_t *bytes, size_t size, uint32_t *width, uint32_t *height,
                              float **rgb, lmb_error *err);

/* Reads an image's alpha channel (the 4th of RGBA, the 2nd of grey + alpha) as floats in
 * [0, 1], reduced by a whole `factor` (each value the mean of the up to factor x factor pixels
 * it covers), read a band of rows at a time. An image without alpha gives *alpha = NULL (it is
 * opaque) and LMB_OK. The caller frees *alpha. */
lmb_status lmb_image_read_alpha(const char *name, const uint8_t *bytes, size_t size, uint32_t factor, uint32_t *width,
                                uint32_t *height, float **alpha, lmb_error *err);

/* A reader that decodes an image a band of rows at a time, so a large texture can be reduced
 * while it is read without holding it whole (load/textures.c). Opened from a file or from
 * memory as lmb_image_read_rgb; bytes, if given, must outlive the reader. */
typedef struct lmb_image_rows lmb_image_rows;

lmb_status lmb_image_rows_open(const char *name, const uint8_t *bytes, size_t size, lmb_image_rows **out,
                               uint32_t *width, uint32_t *height, lmb_error *err);

/* Rows y0 .. y1 - 1 (top to bottom) as RGB floats into rgb (3 x width x (y1 - y0) values),
 * with the same conventions as lmb_image_read_rgb. */
lmb_status lmb_image_rows_read(lmb_image_rows *r, uint32_t y0, uint32_t y1, float *rgb, lmb_error *err);

/* 1 if the image stores 8-bit values: then lmb_image_rows_read_u8 reads them as stored. */
int lmb_image_rows_is_u8(const lmb_image_rows *r);

/* Rows y0 .. y1 - 1 as 8-bit RGB (3 x width x (y1 - y0) bytes), values as stored (sRGB-encoded
 * for colour images). Only for images lmb_image_rows_is_u8 says are 8-bit. */
lmb_status lmb_image_rows_read_u8(lmb_image_rows *r, uint32_t y0, uint32_t y1, uint8_t *rgb, lmb_error *err);

/* Closes the reader (NULL is fine). */
void lmb_image_rows_close(lmb_image_rows *r);

#ifdef __cplusplus
}
#endif

#endif
