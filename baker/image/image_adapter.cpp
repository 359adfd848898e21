/*
 * OpenImageIO adapter (see image_adapter.h): the only place lmbake touches OIIO's C++ API.
 */
#include "image_adapter.h"
#ifndef LMB_IMAGES_AS_MODULE
extern "C" {
#include "image_native.h"
}
#endif

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

namespace {

bool ends_with(const std::string &s, const char *suffix)
{
    std::string x(suffix);
    return s.size() >= x.size() && s.compare(s.size() - x.size(), x.size(), x) == 0;
}

lmb_status write_image(const char *path, uint32_t w, uint32_t h, uint32_t ch, OIIO::TypeDesc type,
                       const void *pixels, lmb_error *err)
{
    std::string target(path), tmp = target + ".part";
    /* the extension picks the format: keep it on the temporary name */
    size_t dot = target.find_last_of('.');
    if (dot != std::string::npos)
        tmp = target.substr(0, dot) + ".part" + target.substr(dot);
    auto out = OIIO::ImageOutput::create(target);
    if (!out)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: no image writer for this extension: %s", path,
                             OIIO::geterror().c_str());
    OIIO::TypeDesc stored = type;
    if (ends_with(target, ".exr")) {
        /* half float holds up to 65504: sunlight (up to ~120,000 lux) would turn to Inf, so an
         * atlas with a larger value is stored in 32-bit float */
        stored = OIIO::TypeDesc::HALF;
        if (type == OIIO::TypeDesc::FLOAT) {
            const float *f = static_cast<const float *>(pixels);
            for (size_t i = 0; i < (size_t)w * h * ch; i++)
                if (!(std::fabs(f[i]) <= 65504.0f)) {
                    stored = OIIO::TypeDesc::FLOAT;
                    break;
                }
        }
    }
    OIIO::ImageSpec spec((int)w, (int)h, (int)ch, stored);
    if (ends_with(target, ".exr"))
        spec.attribute("compression", "zip");
    /* 4 channels are data (RGBM), not colour with associated alpha: stored as given */
    if (ch == 4)
        spec.attribute("oiio:UnassociatedAlpha", 1);
    /* no time stamp: the same bake must give byte-identical files */
    spec.attribute("DateTime", "");
    if (!out->open(tmp, spec) || !out->write_image(type, pixels) || !out->close()) {
        std::string msg = out->geterror();
        std::remove(tmp.c_str());
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write image: %s", path, msg.c_str());
    }
    if (std::rename(tmp.c_str(), target.c_str()) != 0) {
        std::remove(tmp.c_str());
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot move the finished image into place", path);
    }
    return LMB_OK;
}

} // namespace

extern "C" lmb_status lmb_image_write_u8(const char *path, uint32_t w, uint32_t h, uint32_t ch, const uint8_t *pixels,
                                         lmb_error *err)
{
#ifndef LMB_IMAGES_AS_MODULE /* linked in (sanitizer, fuzz builds): the same writers as the module build's */
    if (lmb_image_native_writes(path, 0))
        return lmb_image_native_write_u8(path, w, h, ch, pixels, err);
#endif
    try {
        return write_image(path, w, h, ch, OIIO::TypeDesc::UINT8, pixels, err);
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: image writer failed: %s", path, e.what());
    }
}

extern "C" lmb_status lmb_image_write_f32(const char *path, uint32_t w, uint32_t h, uint32_t ch, const float *pixels,
                                          lmb_error *err)
{
#ifndef LMB_IMAGES_AS_MODULE
    if (lmb_image_native_writes(path, 1))
        return lmb_image_native_write_f32(path, w, h, ch, pixels, err);
#endif
    try {
        return write_image(path, w, h, ch, OIIO::TypeDesc::FLOAT, pixels, err);
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: image writer failed: %s", path, e.what());
    }
}

extern "C" lmb_status lmb_image_size(const char *name, const uint8_t *bytes, size_t size, uint32_t *w, uint32_t *h,
                                      lmb_error *err)
{
    try {
        OIIO::Filesystem::IOMemReader mem(bytes, bytes ? size : 0);
        auto in = OIIO::ImageInput::open(name, nullptr, bytes ? &mem : nullptr);
        if (!in)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot read image: %s", name, OIIO::geterror().c_str());
        *w = (uint32_t)(in->spec().width > 0 ? in->spec().width : 0);
        *h = (uint32_t)(in->spec().height > 0 ? in->spec().height : 0);
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot read image: %s", name, e.what());
    }
}

extern "C" lmb_status lmb_image_read_rgb(const char *name, const uint8_t *bytes, size_t size, uint32_t *w, uint32_t *h,
                                         float **rgb, lmb_error *err)
{
    try {
        *rgb = nullptr;
        OIIO::Filesystem::IOMemReader mem(bytes, bytes ? size : 0);
        auto in = OIIO::ImageInput::open(name, nullptr, bytes ? &mem : nullptr);
        if (!in)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot read image: %s", name, OIIO::geterror().c_str());
        const OIIO::ImageSpec &spec = in->spec();
        int ch = spec.nchannels;
        if (spec.width <= 0 || spec.height <= 0 || ch <= 0 || (size_t)spec.width * spec.height > (size_t)1 << 28)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: unusable image size %dx%d", name, spec.width, spec.height);
        std::vector<float> px((size_t)spec.width * spec.height * ch);
        if (!in->read_image(0, 0, 0, ch, OIIO::TypeDesc::FLOAT, px.data()))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot decode image: %s", name, in->geterror().c_str());
        float *out = (float *)std::malloc((size_t)spec.width * spec.height * 3 * sizeof(float) + 1);
        if (!out)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", name);
        for (size_t i = 0; i < (size_t)spec.width * spec.height; i++)
            for (int c = 0; c < 3; c++)
                out[3 * i + c] = px[i * ch + (ch >= 3 ? c : 0)];
        *w = (uint32_t)spec.width;
        *h = (uint32_t)spec.height;
        *rgb = out;
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: image reader failed: %s", name, e.what());
    }
}

extern "C" lmb_status lmb_image_read_alpha(const char *name, const uint8_t *bytes, size_t size, uint32_t factor,
                                           uint32_t *w, uint32_t *h, float **alpha, lmb_error *err)
{
    try {
        *alpha = nullptr;
        OIIO::Filesystem::IOMemReader mem(bytes, bytes ? size : 0);
        auto in = OIIO::ImageInput::open(name, nullptr, bytes ? &mem : nullptr);
        if (!in)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot read image: %s", name, OIIO::geterror().c_str());
        const OIIO::ImageSpec &spec = in->spec();
        int ch = spec.nchannels, a = spec.alpha_channel >= 0 ? spec.alpha_channel : ch == 4 ? 3 : ch == 2 ? 1 : -1;
        if (spec.width <= 0 || spec.height <= 0 || factor == 0)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: unusable image size %dx%d", name, spec.width, spec.height);
        if (a < 0)
            return LMB_OK;
        size_t iw = (size_t)spec.width, ih = (size_t)spec.height;
        size_t ow = (iw + factor - 1) / factor, oh = (ih + factor - 1) / factor;
        float *out = (float *)std::calloc(ow * oh + 1, sizeof(float));
        if (!out)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", name);
        std::vector<float> band(iw * factor);
        for (size_t oy = 0; oy < oh; oy++) {
            size_t y0 = oy * factor, y1 = std::min(y0 + factor, ih);
            if (!in->read_scanlines(0, 0, spec.y + (int)y0, spec.y + (int)y1, 0, a, a + 1, OIIO::TypeDesc::FLOAT,
                                    band.data())) {
                std::free(out);
                return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot decode alpha: %s", name, in->geterror().c_str());
            }
            for (size_t y = 0; y < y1 - y0; y++)
                for (size_t x = 0; x < iw; x++)
                    out[oy * ow + x / factor] += band[y * iw + x];
            for (size_t ox = 0; ox < ow; ox++) {
                size_t cols = std::min((ox + 1) * factor, iw) - ox * factor;
                out[oy * ow + ox] /= (float)(cols * (y1 - y0));
            }
        }
        *w = (uint32_t)ow;
        *h = (uint32_t)oh;
        *alpha = out;
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: image reader failed: %s", name, e.what());
    }
}

struct lmb_image_rows {
    OIIO::Filesystem::IOMemReader mem;
    std::unique_ptr<OIIO::ImageInput> in;
    std::vector<float> band;
    std::vector<uint8_t> band_u8;
    std::string name;
    lmb_image_rows(const uint8_t *bytes, size_t size) : mem(bytes, bytes ? size : 0) {}
};

extern "C" lmb_status lmb_image_rows_open(const char *name, const uint8_t *bytes, size_t size, lmb_image_rows **out,
                                          uint32_t *w, uint32_t *h, lmb_error *err)
{
    *out = nullptr;
    try {
        std::unique_ptr<lmb_image_rows> r(new lmb_image_rows(bytes, size));
        r->name = name;
        r->in = OIIO::ImageInput::open(name, nullptr, bytes ? &r->mem : nullptr);
        if (!r->in)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot read image: %s", name, OIIO::geterror().c_str());
        const OIIO::ImageSpec &spec = r->in->spec();
        if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: unusable image size %dx%d", name, spec.width, spec.height);
        *w = (uint32_t)spec.width;
        *h = (uint32_t)spec.height;
        *out = r.release();
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot read image: %s", name, e.what());
    }
}

namespace {

/* Rows y0 .. y1 - 1 as T (float or uint8_t) into band, then as RGB into rgb. */
template <typename T>
lmb_status read_rows(lmb_image_rows *r, std::vector<T> &band, OIIO::TypeDesc type, uint32_t y0, uint32_t y1, T *rgb,
                     lmb_error *err)
{
    try {
        const OIIO::ImageSpec &spec = r->in->spec();
        int ch = spec.nchannels;
        size_t w = (size_t)spec.width, rows = y1 - y0;
        band.resize(w * rows * (size_t)ch);
        if (!r->in->read_scanlines(0, 0, spec.y + (int)y0, spec.y + (int)y1, 0, 0, ch, type, band.data()))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot decode rows %u..%u: %s", r->name.c_str(), y0, y1 - 1,
                                 r->in->geterror().c_str());
        for (size_t i = 0; i < w * rows; i++)
            for (int c = 0; c < 3; c++)
                rgb[3 * i + c] = band[i * ch + (ch >= 3 ? c : 0)];
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: image reader failed: %s", r->name.c_str(), e.what());
    }
}

} // namespace

extern "C" lmb_status lmb_image_rows_read(lmb_image_rows *r, uint32_t y0, uint32_t y1, float *rgb, lmb_error *err)
{
    return read_rows(r, r->band, OIIO::TypeDesc::FLOAT, y0, y1, rgb, err);
}

extern "C" int lmb_image_rows_is_u8(const lmb_image_rows *r)
{
    return r->in->spec().format == OIIO::TypeDesc::UINT8;
}

extern "C" lmb_status lmb_image_rows_read_u8(lmb_image_rows *r, uint32_t y0, uint32_t y1, uint8_t *rgb, lmb_error *err)
{
    return read_rows(r, r->band_u8, OIIO::TypeDesc::UINT8, y0, y1, rgb, err);
}

extern "C" void lmb_image_rows_close(lmb_image_rows *r)
{
    delete r;
}

#ifdef LMB_IMAGES_AS_MODULE
/* Built as liblmbake-images.so (image_module.h): the table is the module's one exported symbol. */
#include "image_module.h"

extern "C" __attribute__((visibility("default"))) const lmb_image_api *lmb_images_module_api(void)
{
    static const lmb_image_api api = {LMB_IMAGE_API_VERSION, lmb_image_write_u8,   lmb_image_write_f32,
                                      lmb_image_size,        lmb_image_read_rgb,   lmb_image_rows_open,
                                      lmb_image_rows_read,   lmb_image_rows_is_u8, lmb_image_rows_read_u8,
                                      lmb_image_rows_close,  lmb_image_read_alpha};
    return &api;
}
#endif
