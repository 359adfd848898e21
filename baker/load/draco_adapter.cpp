/* The Draco adapter (see draco_adapter.h). */
#include "draco_adapter.h"

#include <draco/compression/decode.h>

#include <cstdint>
#include <memory>
#include <new>

struct lmb_draco_mesh {
    std::unique_ptr<draco::Mesh> mesh;
};

extern "C" lmb_status lmb_draco_decode(const uint8_t *bytes, size_t size, lmb_draco_mesh **out, uint32_t *points,
                                       uint32_t *faces, lmb_error *err)
{
    *out = nullptr;
    try {
        draco::DecoderBuffer buf;
        buf.Init(reinterpret_cast<const char *>(bytes), size);
        draco::Decoder dec;
        auto res = dec.DecodeMeshFromBuffer(&buf);
        if (!res.ok())
            return lmb_error_set(err, LMB_ERR_INPUT, "the Draco stream does not decode: %s",
                                 res.status().error_msg_string().c_str());
        std::unique_ptr<lmb_draco_mesh> m(new lmb_draco_mesh());
        m->mesh = std::move(res).value();
        *points = (uint32_t)m->mesh->num_points();
        *faces = (uint32_t)m->mesh->num_faces();
        *out = m.release();
        return LMB_OK;
    } catch (const std::bad_alloc &) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory decoding a Draco stream");
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INPUT, "the Draco stream does not decode: %s", e.what());
    }
}

extern "C" void lmb_draco_indices(const lmb_draco_mesh *m, uint32_t *out)
{
    for (draco::FaceIndex f(0); f < m->mesh->num_faces(); ++f)
        for (int k = 0; k < 3; k++)
            out[3 * (size_t)f.value() + (size_t)k] = m->mesh->face(f)[k].value();
}

namespace {

template <typename T>
int convert(const draco::PointAttribute *a, const draco::Mesh &mesh, int32_t components, void *out)
{
    T *o = static_cast<T *>(out);
    for (draco::PointIndex p(0); p < mesh.num_points(); ++p)
        if (!a->ConvertValue<T>(a->mapped_index(p), (int8_t)components, o + (size_t)p.value() * (size_t)components))
            return 0;
    return 1;
}

} // namespace

extern "C" int lmb_draco_attribute(const lmb_draco_mesh *m, int32_t id, int32_t component_type, int32_t components,
                                   void *out)
{
    const draco::PointAttribute *a = id >= 0 ? m->mesh->GetAttributeByUniqueId((uint32_t)id) : nullptr;
    if (!a || components < 1 || components > 16)
        return 0;
    switch (component_type) {
    case 5120: return convert<int8_t>(a, *m->mesh, components, out);
    case 5121: return convert<uint8_t>(a, *m->mesh, components, out);
    case 5122: return convert<int16_t>(a, *m->mesh, components, out);
    case 5123: return convert<uint16_t>(a, *m->mesh, components, out);
    case 5125: return convert<uint32_t>(a, *m->mesh, components, out);
    case 5126: return convert<float>(a, *m->mesh, components, out);
    default: return 0;
    }
}

extern "C" void lmb_draco_free(lmb_draco_mesh *m)
{
    delete m;
}
