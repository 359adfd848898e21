/*
 * The bake's own image formats written without OpenImageIO (image_native.h): .exr through
 * OpenEXR's C library (OpenEXRCore), .png through libpng, .hdr through stb's
 * image writer. Loading the OpenImageIO module makes the dynamic loader bind Debian's build of
 * it with its 261 shared libraries (FFmpeg, GStreamer, OpenCV, ...): about 0.38 s of a bake
 * that only writes its lightmaps (docs/testing.md); these three libraries load in milliseconds.
 * The files hold what the module wrote: .exr as half float with ZIP compression (32-bit float
 * when a value is beyond half's range), channels R, G, B; no time stamp anywhere (the same bake
 * gives byte-identical files). Each file is written to a temporary name beside the target
 * (NAME.part.EXT) and renamed into place: a failed write never leaves a partial file.
 */
#include "image_native.h"

#include <OpenEXR/openexr.h>
#include <Imath/half.h>
#include <png.h>
#include <stb_image_write.h>

#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* zlib's level for the .exr (ZIP) and .png files: 4 rather than zlib's default 6, half the
 * time for a few per cent of bytes (docs/output.md, "Files": the figures). */
#define LMB_ZIP_LEVEL 4

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : "";
}

int lmb_image_native_writes(const char *path, int f32)
{
    const char *ext = extension(path);
    return f32 ? strcmp(ext, ".exr") == 0 || strcmp(ext, ".hdr") == 0 : strcmp(ext, ".png") == 0;
}

/* NAME.part.EXT beside NAME.EXT: the extension stays last, as the module's names did. */
static int part_name(const char *path, char *out, size_t size)
{
    const char *ext = extension(path);
    int n = snprintf(out, size, "%.*s.part%s", (int)(ext - path), path, ext);
    return n > 0 && (size_t)n < size;
}

static lmb_status move_into_place(const char *tmp, const char *path, lmb_error *err)
{
    if (rename(tmp, path) != 0) {
        int e = errno;
        remove(tmp);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot move the finished image into place: %s", path,
                             strerror(e));
    }
    return LMB_OK;
}

/* libpng's error handler: the message kept, then back to write_png's setjmp. */
static void png_failed(png_structp png, png_const_charp message)
{
    char *keep = png_get_error_ptr(png);
    snprintf(keep, 256, "%s", message);
    png_longjmp(png, 1);
}

static void png_warned(png_structp png, png_const_charp message)
{
    (void)png;
    (void)message;
}

/* The file written through libpng's full API rather than its simplified one, whose zlib level
 * cannot be set: LMB_ZIP_LEVEL, with libpng's adaptive row filters. */
static lmb_status write_png(const char *tmp, const char *path, uint32_t w, uint32_t h, uint32_t channels,
                            const uint8_t *pixels, lmb_error *err)
{
    static const int types[] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                PNG_COLOR_TYPE_RGBA};
    if (channels < 1 || channels > 4)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: %u channels cannot be a PNG", path, channels);
    FILE *f = fopen(tmp, "wb");
    if (!f)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write image: %s", path, strerror(errno));
    char message[256] = "";
    png_bytep *rows = malloc(((size_t)h + 1) * sizeof *rows);
    png_structp png = rows ? png_create_write_struct(PNG_LIBPNG_VER_STRING, message, png_failed, png_warned) : NULL;
    png_infop info = png ? png_create_info_struct(png) : NULL;
    int ok = info != NULL;
    if (!ok)
        snprintf(message, sizeof message, "out of memory");
    else if (setjmp(png_jmpbuf(png)))
        ok = 0;
    else {
        for (uint32_t y = 0; y < h; y++) /* RGBM's 4th channel is data: stored as given */
            rows[y] = (png_bytep)(pixels + (size_t)y * w * channels);
        png_init_io(png, f);
        png_set_compression_level(png, LMB_ZIP_LEVEL);
        png_set_IHDR(png, info, w, h, 8, types[channels], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                     PNG_FILTER_TYPE_DEFAULT);
        png_write_info(png, info);
        png_write_image(png, rows);
        png_write_end(png, NULL);
    }
    png_destroy_write_struct(png ? &png : NULL, info ? &info : NULL);
    free(rows);
    if (fclose(f) != 0 && ok) {
        ok = 0;
        snprintf(message, sizeof message, "%s", strerror(errno));
    }
    if (!ok) {
        remove(tmp);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write image: %s", path, message);
    }
    return LMB_OK;
}

static lmb_status write_hdr(const char *tmp, const char *path, uint32_t w, uint32_t h, uint32_t channels,
                            const float *pixels, lmb_error *err)
{
    errno = 0;
    if (!stbi_write_hdr(tmp, (int)w, (int)h, (int)channels, pixels)) {
        int e = errno;
        remove(tmp);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write image: %s", path,
                             e ? strerror(e) : "the Radiance writer failed");
    }
    return LMB_OK;
}

/* One OpenEXR scanline image: channels B, G, R (the file's sorted order) from interleaved RGB. */
static exr_result_t exr_write_rgb(exr_context_t ctx, uint32_t w, uint32_t h, const void *rgb, exr_pixel_type_t type)
{
    int part = 0;
    size_t bytes = type == EXR_PIXEL_HALF ? 2 : 4;
    exr_result_t rv = exr_add_part(ctx, "", EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, (int32_t)w, (int32_t)h, EXR_COMPRESSION_ZIP);
    static const char *names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3 && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctx, part, names[c], type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctx);
    int32_t lines = 1;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int started = 0;
    for (int32_t y = 0; rv == EXR_ERR_SUCCESS && y < (int32_t)h; y += lines) {
        exr_chunk_info_t chunk;
        rv = exr_write_scanline_chunk_info(ctx, part, y, &chunk);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_encoding_update(ctx, part, &chunk, &enc) : exr_encoding_initialize(ctx, part, &chunk, &enc);
        if (rv != EXR_ERR_SUCCESS)
            break;
        for (int16_t c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int offset = ch->channel_name[0] == 'R' ? 0 : ch->channel_name[0] == 'G' ? 1 : 2;
            ch->encode_from_ptr = (const uint8_t *)rgb + ((size_t)chunk.start_y * w * 3 + (size_t)offset) * bytes;
            ch->user_pixel_stride = (int32_t)(3 * bytes);
            ch->user_line_stride = (int32_t)((size_t)w * 3 * bytes);
            ch->user_data_type = (uint16_t)type;
            ch->user_bytes_per_element = (int8_t)bytes;
        }
        if (!started)
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        started = 1;
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctx, part, &enc);
    }
    if (started) {
        exr_result_t d = exr_encoding_destroy(ctx, &enc);
        if (rv == EXR_ERR_SUCCESS)
            rv = d;
    }
    return rv;
}

static lmb_status write_exr(const char *tmp, const char *path, uint32_t w, uint32_t h, uint32_t channels,
                            const float *pixels, int full_float, lmb_error *err)
{
    if (channels != 3)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: the EXR writer takes RGB, not %u channels", path, channels);
    size_t n = (size_t)w * h * 3;
    /* half float holds up to 65504: sunlight (up to ~120,000 lux) would turn to Inf, so an atlas
     * with a larger value is stored in 32-bit float */
    int fits_half = !full_float;
    for (size_t i = 0; i < n && fits_half; i++)
        fits_half = fabsf(pixels[i]) <= 65504.0f;
    uint16_t *half = NULL;
    if (fits_half) {
        half = malloc(n * sizeof *half + 1);
        if (!half)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory for the image", path);
        for (size_t i = 0; i < n; i++)
            half[i] = imath_float_to_half(pixels[i]);
    }
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.zip_level = LMB_ZIP_LEVEL;
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_write(&ctx, tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_rgb(ctx, w, h, fits_half ? (const void *)half : (const void *)pixels,
                           fits_half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT);
    exr_result_t done = ctx ? exr_finish(&ctx) : EXR_ERR_SUCCESS;
    free(half);
    if (rv == EXR_ERR_SUCCESS)
        rv = done;
    if (rv != EXR_ERR_SUCCESS) {
        remove(tmp);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write image: %s", path,
                             exr_get_default_error_message(rv));
    }
    return LMB_OK;
}

lmb_status lmb_image_native_write_u8(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                                     const uint8_t *pixels, lmb_error *err)
{
    char tmp[4096];
    if (!part_name(path, tmp, sizeof tmp))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: path too long", path);
    lmb_status st = write_png(tmp, path, width, height, channels, pixels, err);
    return st == LMB_OK ? move_into_place(tmp, path, err) : st;
}

lmb_status lmb_image_native_write_f32(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                                      const float *pixels, lmb_error *err)
{
    char tmp[4096];
    if (!part_name(path, tmp, sizeof tmp))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: path too long", path);
    lmb_status st = strcmp(extension(path), ".exr") == 0 ? write_exr(tmp, path, width, height, channels, pixels, 0, err)
                                                         : write_hdr(tmp, path, width, height, channels, pixels, err);
    return st == LMB_OK ? move_into_place(tmp, path, err) : st;
}

lmb_status lmb_image_native_write_exr_float(const char *path, uint32_t width, uint32_t height, const float *pixels,
                                            lmb_error *err)
{
    char tmp[4096];
    if (!part_name(path, tmp, sizeof tmp))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: path too long", path);
    lmb_status st = write_exr(tmp, path, width, height, 3, pixels, 1, err);
    return st == LMB_OK ? move_into_place(tmp, path, err) : st;
}
