/*
 * astcenc behind astc_adapter.h: one context per image (profile HDR_RGB_LDR_A, 4 x 4 blocks,
 * the "medium" effort preset), the image as RGBA32F with alpha 1, compressed by every thread of
 * an OpenMP team (astcenc schedules the blocks among the threads it is given).
 */
#include "astc_adapter.h"

#include <astcenc.h>
#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <vector>

size_t lmb_astc_size(uint32_t w, uint32_t h)
{
    return (size_t)((w + 3) / 4) * ((h + 3) / 4) * 16;
}

lmb_status lmb_astc_hdr_encode(uint32_t w, uint32_t h, const float *rgb, int threads, uint8_t *blocks,
                                          uint64_t *clamped, lmb_error *err)
{
    const float max_half = 65504.0f;
    std::vector<float> rgba;
    try {
        rgba.resize((size_t)w * h * 4);
    } catch (...) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "astc: out of memory for a %ux%u image", w, h);
    }
    uint64_t over = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        int texel_over = 0;
        for (int c = 0; c < 3; c++) {
            float v = rgb[3 * i + c];
            v = v > 0 ? v : 0.0f; /* NaN too */
            if (v > max_half) {
                v = max_half;
                texel_over = 1;
            }
            rgba[4 * i + c] = v;
        }
        rgba[4 * i + 3] = 1.0f;
        over += (uint64_t)texel_over;
    }
    if (clamped)
        *clamped = over;
    unsigned n = (unsigned)(threads > 0 ? threads : omp_get_max_threads());
    astcenc_config config;
    astcenc_error e = astcenc_config_init(ASTCENC_PRF_HDR_RGB_LDR_A, 4, 4, 1, ASTCENC_PRE_MEDIUM, 0, &config);
    astcenc_context *ctx = nullptr;
    if (e == ASTCENC_SUCCESS)
        e = astcenc_context_alloc(&config, n, &ctx);
    if (e != ASTCENC_SUCCESS)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "astc: %s", astcenc_get_error_string(e));
    void *slices[1] = {rgba.data()};
    astcenc_image image = {w, h, 1, ASTCENC_TYPE_F32, slices};
    const astcenc_swizzle swizzle = {ASTCENC_SWZ_R, ASTCENC_SWZ_G, ASTCENC_SWZ_B, ASTCENC_SWZ_A};
    size_t size = lmb_astc_size(w, h);
    astcenc_error first = ASTCENC_SUCCESS;
#pragma omp parallel num_threads(n)
    {
        astcenc_error r = astcenc_compress_image(ctx, &image, &swizzle, blocks, size, (unsigned)omp_get_thread_num());
#pragma omp critical(lmb_astc_error)
        if (r != ASTCENC_SUCCESS && first == ASTCENC_SUCCESS)
            first = r;
    }
    astcenc_context_free(ctx);
    if (first != ASTCENC_SUCCESS)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "astc: %s", astcenc_get_error_string(first));
    return LMB_OK;
}
