/*
 * The lightmap images of one atlas (see atlas_images.h): EXR (the accurate one), Radiance
 * .hdr, a tonemapped PNG preview and, when asked, KTX2, RGBM and the texel mask; every file
 * but the mask holds what output.scale says. The files of an atlas are encoded at once, a file
 * per thread.
 */
#include "atlas_images.h"

#include "image/image_adapter.h"
#include "image/image_native.h"
#include "ktx2.h"
#include "rgbm.h"
#include "texels/dilate.h"
#include "util/lmb_math.h"
#include "util/select.h"

#include <omp.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Tonemapped 8-bit preview of irradiance: exposure maps the 95th percentile of the valid
 * texels' luminance to 0.8 before Reinhard x/(1+x) and the sRGB curve. For a quick look
 * only; the EXR is the lightmap. */
static void tonemap(const float *rgb, const uint8_t *valid, uint32_t w, uint32_t h, int threads, uint8_t *out)
{
    size_t n = (size_t)w * h, m = 0;
    float *lum = malloc((n + 1) * sizeof *lum);
    double scale = 1.0;
    if (lum) {
        for (size_t i = 0; i < n; i++)
            if (valid[i] == LMB_TEXEL_VALID)
                lum[m++] = 0.2126f * rgb[3 * i] + 0.7152f * rgb[3 * i + 1] + 0.0722f * rgb[3 * i + 2];
        if (m) {
            double p95 = lmb_select_kth(lum, m, (size_t)(0.95 * (double)(m - 1)));
            scale = p95 > 0 ? 0.8 / p95 : 1.0;
        }
        free(lum);
    }
#pragma omp parallel for num_threads(threads) schedule(static)
    for (size_t i = 0; i < 3 * n; i++) {
        double x = rgb[i] * scale, y = x / (1.0 + x);
        y = y <= 0.0031308 ? 12.92 * y : 1.055 * pow(y, 1 / 2.4) - 0.055;
        out[i] = (uint8_t)(y <= 0 ? 0 : y >= 1 ? 255 : lround(y * 255.0));
    }
}

/* One file to write: float or 8-bit pixels through OpenImageIO, or float pixels as KTX2. */
typedef enum image_kind { IMAGE_F32, IMAGE_U8, IMAGE_KTX2, IMAGE_EXR_FLOAT } image_kind;

typedef struct image_job {
    image_kind kind;
    char path[8600];
    uint32_t channels;
    const float *f32;
    const uint8_t *u8;
    lmb_ktx2_options ktx2;
    lmb_ktx2_report *ktx2_report; /* may be NULL */
} image_job;

/* Writes the files of jobs[0..n) at once, a file per thread (each encoder runs on one thread,
 * and the files do not depend on each other); the error is the first job's that failed. */
static lmb_status write_images(const image_job *jobs, int n, uint32_t w, uint32_t h, int threads, lmb_error *err)
{
    lmb_error errs[16];
    lmb_status sts[16];
    if (n > 16)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lightmap images: %d files at once", n);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int k = 0; k < n; k++) {
        const image_job *j = &jobs[k];
        errs[k] = (lmb_error){LMB_OK, ""};
        sts[k] = j->kind == IMAGE_F32         ? lmb_image_write_f32(j->path, w, h, j->channels, j->f32, &errs[k])
                 : j->kind == IMAGE_U8        ? lmb_image_write_u8(j->path, w, h, j->channels, j->u8, &errs[k])
                 : j->kind == IMAGE_EXR_FLOAT ? lmb_image_native_write_exr_float(j->path, w, h, j->f32, &errs[k])
                                              : lmb_ktx2_write(j->path, w, h, j->f32, &j->ktx2, j->ktx2_report, &errs[k]);
    }
    for (int k = 0; k < n; k++)
        if (sts[k] != LMB_OK) {
            *err = errs[k];
            return sts[k];
        }
    return LMB_OK;
}

static int image_threads(const lmb_config *cfg)
{
    return cfg->threads ? (int)cfg->threads : omp_get_max_threads();
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

lmb_status lmb_write_atlas_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a,
                                  const float *irradiance, const uint8_t *valid, uint32_t w, uint32_t h, int exr_float,
                                  lmb_atlas_output *info, lmb_error *err)
{
    memset(info, 0, sizeof *info);
    size_t n = (size_t)w * h;
    int threads = image_threads(cfg);
    float *rgb = scaled_copy(cfg, irradiance, n);
    uint8_t *png = malloc(3 * n + 1), *rgbm = NULL, *mask = NULL, *care = NULL;
    if ((cfg->output_formats & LMB_OUTPUT_RGBM))
        rgbm = malloc(4 * n + 1);
    if ((cfg->output_formats & LMB_OUTPUT_MASK))
        mask = malloc(n + 1);
    image_job *jobs = calloc(6, sizeof *jobs);
    lmb_status st = LMB_OK;
    if (!rgb || !png || !jobs || ((cfg->output_formats & LMB_OUTPUT_RGBM) && !rgbm) ||
        ((cfg->output_formats & LMB_OUTPUT_MASK) && !mask))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "lightmap images: out of memory");
    int count = 0;
    if (st == LMB_OK && (cfg->output_formats & LMB_OUTPUT_EXR)) {
        jobs[count] = (image_job){exr_float ? IMAGE_EXR_FLOAT : IMAGE_F32, "", 3, rgb, NULL, {0}, NULL};
        snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u.exr", dir, stem, a);
    }
    /* the glTF references the .hdr and .png: written whatever the formats say */
    if (st == LMB_OK) {
        jobs[count] = (image_job){IMAGE_F32, "", 3, rgb, NULL, {0}, NULL};
        snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u.hdr", dir, stem, a);
        tonemap(rgb, valid, w, h, threads, png);
        jobs[count] = (image_job){IMAGE_U8, "", 3, NULL, png, {0}, NULL};
        snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u.png", dir, stem, a);
    }
    if (st == LMB_OK && (cfg->output_formats & LMB_OUTPUT_KTX2)) {
        lmb_ktx2_format f = (lmb_ktx2_format)cfg->ktx2_format;
        care = lmb_ktx2_lookup_texels(valid, w, h);
        if (!care)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "lightmap images: out of memory");
        /* a block encoder is the one long job: it runs first, alone, on every thread */
        lmb_ktx2_options o = {f, cfg->ktx2_zstd ? LMB_KTX2_ZSTD_LEVEL : 0, cfg->ktx2_mipmaps,
                              lmb_ktx2_is_block(f) ? threads : 1, care};
        jobs[count] = (image_job){IMAGE_KTX2, "", 3, rgb, NULL, o, &info->ktx2};
        snprintf(jobs[count].path, sizeof jobs->path, "%s/%s-lightmap-%u.ktx2", dir, stem, a);
        if (st == LMB_OK && lmb_ktx2_is_block(f))
            st = write_images(&jobs[count], 1, w, h, 1, err);
        else
            count++;
    }
    if (st == LMB_OK && rgbm) {
        info->rgbm_range = lmb_rgbm_range(cfg->rgbm_range, rgb, valid, n);
        info->rgbm_clamped = lmb_rgbm_encode(rgb, valid, n, info->rgbm_range, rgbm);
        jobs[count] = (image_job){IMAGE_U8, "", 4, NULL, rgbm, {0}, NULL};
        snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u-rgbm.png", dir, stem, a);
    }
    if (st == LMB_OK && mask) {
        for (size_t i = 0; i < n; i++)
            mask[i] = valid[i] == LMB_TEXEL_VALID ? 255 : valid[i] == LMB_TEXEL_INSIDE ? 128 : 0;
        jobs[count] = (image_job){IMAGE_U8, "", 1, NULL, mask, {0}, NULL};
        snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u-mask.png", dir, stem, a);
    }
    if (st == LMB_OK)
        st = write_images(jobs, count, w, h, threads, err);
    free(jobs);
    free(rgb);
    free(png);
    free(rgbm);
    free(mask);
    free(care);
    return st;
}

lmb_status lmb_write_hdr_image(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a,
                               const float *irradiance, uint32_t w, uint32_t h, lmb_error *err)
{
    float *rgb = scaled_copy(cfg, irradiance, (size_t)w * h);
    if (!rgb)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lightmap images: out of memory");
    image_job job = {IMAGE_F32, "", 3, rgb, NULL, {0}, NULL};
    snprintf(job.path, sizeof job.path, "%s/%s-lightmap-%u.hdr", dir, stem, a);
    lmb_status st = write_images(&job, 1, w, h, image_threads(cfg), err);
    free(rgb);
    return st;
}

uint32_t lmb_group_image_paths(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a,
                               const char *group, char paths[LMB_GROUP_FILES][LMB_GROUP_IMAGE_PATH])
{
    snprintf(paths[0], LMB_GROUP_IMAGE_PATH, "%s/%s-lightmap-%u-group-%s.exr", dir, stem, a, group);
    snprintf(paths[1], LMB_GROUP_IMAGE_PATH, "%s/%s-lightmap-%u-group-%s.hdr", dir, stem, a, group);
    snprintf(paths[2], LMB_GROUP_IMAGE_PATH, "%s/%s-lightmap-%u-group-%s.ktx2", dir, stem, a, group);
    return cfg->output_formats & LMB_OUTPUT_KTX2 ? 3 : 2;
}

lmb_status lmb_write_group_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a,
                                  const char *group, const float *irradiance, const uint8_t *valid, uint32_t w,
                                  uint32_t h, lmb_ktx2_report *ktx2, lmb_error *err)
{
    int threads = image_threads(cfg);
    char paths[LMB_GROUP_FILES][LMB_GROUP_IMAGE_PATH];
    uint32_t count = lmb_group_image_paths(cfg, dir, stem, a, group, paths);
    float *rgb = scaled_copy(cfg, irradiance, (size_t)w * h);
    uint8_t *care = count > 2 ? lmb_ktx2_lookup_texels(valid, w, h) : NULL;
    if (!rgb || (count > 2 && !care)) {
        free(rgb);
        free(care);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lightmap images: out of memory");
    }
    image_job jobs[LMB_GROUP_FILES] = {{IMAGE_EXR_FLOAT, "", 3, rgb, NULL, {0}, NULL},
                                       {IMAGE_F32, "", 3, rgb, NULL, {0}, NULL}};
    for (uint32_t k = 0; k < count; k++)
        snprintf(jobs[k].path, sizeof jobs[k].path, "%.8599s", paths[k]);
    lmb_status st = LMB_OK;
    if (count > 2) { /* as the level's own KTX2: a block encoder runs first, alone, on every thread */
        lmb_ktx2_format f = (lmb_ktx2_format)cfg->ktx2_format;
        lmb_ktx2_options o = {f, cfg->ktx2_zstd ? LMB_KTX2_ZSTD_LEVEL : 0, cfg->ktx2_mipmaps,
                              lmb_ktx2_is_block(f) ? threads : 1, care};
        jobs[2].kind = IMAGE_KTX2;
        jobs[2].channels = 3;
        jobs[2].f32 = rgb;
        jobs[2].ktx2 = o;
        jobs[2].ktx2_report = ktx2;
        if (lmb_ktx2_is_block(f)) {
            st = write_images(&jobs[2], 1, w, h, 1, err);
            count = 2;
        }
    }
    if (st == LMB_OK)
        st = write_images(jobs, (int)count, w, h, threads, err);
    free(rgb);
    free(care);
    return st;
}

lmb_status lmb_write_direction_images(const lmb_config *cfg, const char *dir, const char *stem, uint32_t a,
                                      const float *d, uint32_t w, uint32_t h, lmb_error *err)
{
    uint8_t *png = malloc((size_t)w * h * 3 + 1);
    image_job *jobs = calloc(3, sizeof *jobs);
    if (!png || !jobs) {
        free(png);
        free(jobs);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "png: out of memory");
    }
    for (size_t i = 0; i < (size_t)w * h * 3; i++) { /* (D + 1) / 2, linear: a data texture, not a colour */
        double v = 0.5 * ((double)d[i] + 1.0);
        png[i] = (uint8_t)(v <= 0 ? 0 : v >= 1 ? 255 : lround(v * 255.0));
    }
    int count = 0;
    jobs[count] = (image_job){IMAGE_F32, "", 3, d, NULL, {0}, NULL};
    snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u-dir.exr", dir, stem, a);
    jobs[count] = (image_job){IMAGE_U8, "", 3, NULL, png, {0}, NULL};
    snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u-dir.png", dir, stem, a);
    if (cfg->output_formats & LMB_OUTPUT_KTX2) { /* signed: half floats */
        lmb_ktx2_options o = {LMB_KTX2_RGBA16F, cfg->ktx2_zstd ? LMB_KTX2_ZSTD_LEVEL : 0, cfg->ktx2_mipmaps, 1, NULL};
        jobs[count] = (image_job){IMAGE_KTX2, "", 3, d, NULL, o, NULL};
        snprintf(jobs[count++].path, sizeof jobs->path, "%s/%s-lightmap-%u-dir.ktx2", dir, stem, a);
    }
    lmb_status st = write_images(jobs, count, w, h, image_threads(cfg), err);
    free(jobs);
    free(png);
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
