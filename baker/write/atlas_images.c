/*
 * The lightmap images of one atlas (see atlas_images.h): EXR (the accurate one), Radiance
 * .hdr, a tonemapped PNG preview and, when asked, KTX2, RGBM and the texel mask; every file
 * but the mask holds what output.scale says.
 */
#include "atlas_images.h"

#include "image_adapter.h"
#include "ktx2.h"
#include "rgbm.h"
#include "post/dilate.h"
#include "util/lmb_math.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Tonemapped 8-bit preview of irradiance: exposure maps the 95th percentile of the valid
 * texels' luminance to 0.8 before Reinhard x/(1+x) and the sRGB curve. For a quick look
 * only; the EXR is the lightmap. */
static void tonemap(const float *rgb, const uint8_t *valid, uint32_t w, uint32_t h, uint8_t *out)
{
    size_t n = (size_t)w * h, m = 0;
    float *lum = malloc((n + 1) * sizeof *lum);
    double scale = 1.0;
    if (lum) {
        for (size_t i = 0; i < n; i++)
            if (valid[i] == LMB_TEXEL_VALID)
                lum[m++] = 0.2126f * rgb[3 * i] + 0.7152f * rgb[3 * i + 1] + 0.0722f * rgb[3 * i + 2];
        if (m) {
            /* 95th percentile by partial selection would be faster; a sort is fine at atlas sizes */
            for (size_t gap = m / 2; gap > 0; gap /= 2)
                for (size_t i = gap; i < m; i++)
                    for (size_t j = i; j >= gap && lum[j - gap] > lum[j]; j -= gap) {
                        float t = lum[j];
                        lum[j] = lum[j - gap];
                        lum[j - gap] = t;
                    }
            double p95 = lum[(size_t)(0.95 * (double)(m - 1))];
            scale = p95 > 0 ? 0.8 / p95 : 1.0;
        }
        free(lum);
    }
    for (size_t i = 0; i < 3 * n; i++) {
        double x = rgb[i] * scale, y = x / (1.0 + x);
        y = y <= 0.0031308 ? 12.92 * y : 1.055 * pow(y, 1 / 2.4) - 0.055;
        out[i] = (uint8_t)(y <= 0 ? 0 : y >= 1 ? 255 : lround(y * 255.0));
    }
}

/* The lightmap as output.scale says: E, or E / pi (NULL when out of memory). */
static float *scaled_copy(const lmb_config *cfg, const float *rgb, size_t texels)
{
    float *out = malloc((3 * texels + 1) * sizeof *out);
    double k = cfg->output_scale == LMB_SCALE_RADIANCE ? 1.0 / LMB_PI : 1.0;
    for (size_t i = 0; out && i < 3 * texels; i++)
        out[i] = (float)(rgb[i] * k);
    return out;
}

static lmb_status write_rgbm(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a, const float *rgb,
                             const uint8_t *valid, uint32_t w, uint32_t h, lmb_atlas_output *info, lmb_error *err)
{
    size_t n = (size_t)w * h;
    uint8_t *px = malloc(4 * n + 1);
    if (!px)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "rgbm: out of memory");
    info->rgbm_range = lmb_rgbm_range(cfg->rgbm_range, rgb, valid, n);
    info->rgbm_clamped = lmb_rgbm_encode(rgb, valid, n, info->rgbm_range, px);
    char path[8600];
    snprintf(path, sizeof path, "%s/%s-lightmap-%u-rgbm.png", dir, stem, a);
    lmb_status st = lmb_image_write_u8(path, w, h, 4, px, err);
    free(px);
    return st;
}

lmb_status lmb_write_atlas_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a,
                                  const float *irradiance, const uint8_t *valid, uint32_t w, uint32_t h,
                                  lmb_atlas_output *info, lmb_error *err)
{
    char path[8600];
    memset(info, 0, sizeof *info);
    float *rgb = scaled_copy(cfg, irradiance, (size_t)w * h);
    if (!rgb)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lightmap images: out of memory");
    lmb_status st = LMB_OK;
    if (cfg->output_formats & LMB_OUTPUT_EXR) {
        snprintf(path, sizeof path, "%s/%s-lightmap-%u.exr", dir, stem, a);
        st = lmb_image_write_f32(path, w, h, 3, rgb, err);
    }
    /* the glTF references the .hdr and .png: write them whatever the formats say */
    if (st == LMB_OK) {
        snprintf(path, sizeof path, "%s/%s-lightmap-%u.hdr", dir, stem, a);
        st = lmb_image_write_f32(path, w, h, 3, rgb, err);
    }
    if (st == LMB_OK) {
        uint8_t *png = malloc((size_t)w * h * 3 + 1);
        if (!png)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "png: out of memory");
        if (png) {
            tonemap(rgb, valid, w, h, png);
            snprintf(path, sizeof path, "%s/%s-lightmap-%u.png", dir, stem, a);
            st = lmb_image_write_u8(path, w, h, 3, png, err);
        }
        free(png);
    }
    if (st == LMB_OK && (cfg->output_formats & LMB_OUTPUT_KTX2)) {
        snprintf(path, sizeof path, "%s/%s-lightmap-%u.ktx2", dir, stem, a);
        st = lmb_ktx2_write(path, w, h, rgb, (lmb_ktx2_format)cfg->ktx2_format, cfg->ktx2_zstd ? LMB_KTX2_ZSTD_LEVEL : 0,
                            err);
    }
    if (st == LMB_OK && (cfg->output_formats & LMB_OUTPUT_RGBM))
        st = write_rgbm(cfg, dir, stem, a, rgb, valid, w, h, info, err);
    if (st == LMB_OK && (cfg->output_formats & LMB_OUTPUT_MASK)) {
        uint8_t *mask = malloc((size_t)w * h + 1);
        if (!mask)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "mask: out of memory");
        for (size_t i = 0; mask && i < (size_t)w * h; i++)
            mask[i] = valid[i] == LMB_TEXEL_VALID ? 255 : valid[i] == LMB_TEXEL_INSIDE ? 128 : 0;
        snprintf(path, sizeof path, "%s/%s-lightmap-%u-mask.png", dir, stem, a);
        if (mask)
            st = lmb_image_write_u8(path, w, h, 1, mask, err);
        free(mask);
    }
    free(rgb);
    return st;
}

lmb_status lmb_write_direction_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a,
                                      const float *d, uint32_t w, uint32_t h, lmb_error *err)
{
    char path[8600];
    snprintf(path, sizeof path, "%s/%s-lightmap-%u-dir.exr", dir, stem, a);
    lmb_status st = lmb_image_write_f32(path, w, h, 3, d, err);
    if (st != LMB_OK)
        return st;
    uint8_t *png = malloc((size_t)w * h * 3 + 1);
    if (!png)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "png: out of memory");
    for (size_t i = 0; i < (size_t)w * h * 3; i++) { /* (D + 1) / 2, linear: a data texture, not a colour */
        double v = 0.5 * ((double)d[i] + 1.0);
        png[i] = (uint8_t)(v <= 0 ? 0 : v >= 1 ? 255 : lround(v * 255.0));
    }
    snprintf(path, sizeof path, "%s/%s-lightmap-%u-dir.png", dir, stem, a);
    st = lmb_image_write_u8(path, w, h, 3, png, err);
    free(png);
    if (st == LMB_OK && (cfg->output_formats & LMB_OUTPUT_KTX2)) { /* signed: half floats */
        snprintf(path, sizeof path, "%s/%s-lightmap-%u-dir.ktx2", dir, stem, a);
        st = lmb_ktx2_write(path, w, h, d, LMB_KTX2_RGBA16F, cfg->ktx2_zstd ? LMB_KTX2_ZSTD_LEVEL : 0, err);
    }
    return st;
}

lmb_status lmb_write_shadowmask_image(const char *dir, const char *stem, uint32_t a, const float *v, uint32_t w,
                                      uint32_t h, lmb_error *err)
{
    char path[8600];
    uint8_t *png = malloc((size_t)w * h * 4 + 1);
    if (!png)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "shadowmask: out of memory");
    for (size_t i = 0; i < (size_t)w * h * 4; i++)
        png[i] = (uint8_t)(v[i] <= 0 ? 0 : v[i] >= 1 ? 255 : lround(v[i] * 255.0));
    snprintf(path, sizeof path, "%s/%s-lightmap-%u-shadowmask.png", dir, stem, a);
    lmb_status st = lmb_image_write_u8(path, w, h, 4, png, err);
    free(png);
    return st;
}
