/*
 * OpenImageIO adapter (see image_adapter.h): the only place lmbake touches OIIO's C++ API.
 */
#include "image_adapter.h"

#include <OpenImageIO/imageio.h>

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
    if (ends_with(target, ".exr"))
        stored = OIIO::TypeDesc::HALF;
    OIIO::ImageSpec spec((int)w, (int)h, (int)ch, stored);
    if (ends_with(target, ".exr"))
        spec.attribute("compression", "zip");
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
    try {
        return write_image(path, w, h, ch, OIIO::TypeDesc::UINT8, pixels, err);
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: image writer failed: %s", path, e.what());
    }
}

extern "C" lmb_status lmb_image_write_f32(const char *path, uint32_t w, uint32_t h, uint32_t ch, const float *pixels,
                                          lmb_error *err)
{
    try {
        return write_image(path, w, h, ch, OIIO::TypeDesc::FLOAT, pixels, err);
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: image writer failed: %s", path, e.what());
    }
}
