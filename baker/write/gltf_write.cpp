/*
 * glTF output through tinygltf (see gltf_write.h): the write half of the tinygltf adapter.
 * New vertex data goes into one new buffer; each new attribute gets its own buffer view.
 * Attributes lmbake does not decode (TANGENT, COLOR_n, TEXCOORD_2+, ...) are gathered
 * byte-wise through the vertex map when they are plain (non-sparse) accessors; others
 * are dropped. Morph targets of a lightmapped primitive are dropped (a baked lightmap is
 * for the rest pose).
 */
#include "gltf_write.h"

#include "../load/gltf_doc.hpp"
#include "gltf_buffers.hpp"
#include "gltf_prune.hpp"
#include "rgbm.h"

#include <cstdio>
#include <cstring>
#include <map>
#include <utility>
#include <vector>

namespace lmb_gltf_out {

int new_buffer(tinygltf::Model &m)
{
    for (size_t i = 0; i < m.buffers.size(); i++)
        if (m.buffers[i].name == "lmbake")
            return (int)i;
    tinygltf::Buffer b;
    b.name = "lmbake";
    m.buffers.push_back(b);
    return (int)m.buffers.size() - 1;
}

/* Appends bytes as a new buffer view (4-byte aligned); returns the view index. */
int add_view(writer &w, const void *data, size_t size, int target)
{
    auto &buf = w.m.buffers[(size_t)w.buffer].data;
    while (buf.size() % 4)
        buf.push_back(0);
    tinygltf::BufferView v;
    v.buffer = w.buffer;
    v.byteOffset = buf.size();
    v.byteLength = size;
    v.target = target;
    const unsigned char *p = static_cast<const unsigned char *>(data);
    buf.insert(buf.end(), p, p + size);
    w.m.bufferViews.push_back(v);
    return (int)w.m.bufferViews.size() - 1;
}

int add_float_accessor(writer &w, const float *data, uint32_t count, int comps, bool minmax)
{
    tinygltf::Accessor a;
    a.bufferView = add_view(w, data, sizeof(float) * comps * count, TINYGLTF_TARGET_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = count;
    a.type = comps == 2 ? TINYGLTF_TYPE_VEC2 : TINYGLTF_TYPE_VEC3;
    if (minmax && count) {
        a.minValues.assign((size_t)comps, 1e300);
        a.maxValues.assign((size_t)comps, -1e300);
        for (uint32_t i = 0; i < count; i++)
            for (int c = 0; c < comps; c++) {
                double v = data[(size_t)i * comps + c];
                a.minValues[(size_t)c] = std::min(a.minValues[(size_t)c], v);
                a.maxValues[(size_t)c] = std::max(a.maxValues[(size_t)c], v);
            }
    }
    w.m.accessors.push_back(a);
    return (int)w.m.accessors.size() - 1;
}

} // namespace lmb_gltf_out

namespace {

using tinygltf::Value;
using namespace lmb_gltf_out;

/* Gathers a plain accessor's elements through `source`; -1 if it cannot be copied. */
int gather_accessor(writer &w, int index, const uint32_t *source, uint32_t count)
{
    const tinygltf::Accessor src = w.m.accessors[(size_t)index];
    if (src.sparse.isSparse || src.bufferView < 0)
        return -1;
    const tinygltf::BufferView view = w.m.bufferViews[(size_t)src.bufferView];
    int stride = src.ByteStride(view);
    size_t elem = (size_t)tinygltf::GetComponentSizeInBytes((uint32_t)src.componentType) *
                  (size_t)tinygltf::GetNumComponentsInType((uint32_t)src.type);
    if (stride <= 0 || elem == 0)
        return -1;
    const auto &data = w.m.buffers[(size_t)view.buffer].data;
    std::vector<unsigned char> out(elem * count);
    for (uint32_t i = 0; i < count; i++) {
        size_t at = view.byteOffset + src.byteOffset + (size_t)source[i] * (size_t)stride;
        if (source[i] >= src.count || at + elem > data.size())
            return -1;
        std::memcpy(&out[(size_t)i * elem], &data[at], elem);
    }
    tinygltf::Accessor a = src;
    a.byteOffset = 0;
    a.count = count;
    a.minValues.clear();
    a.maxValues.clear();
    a.bufferView = add_view(w, out.data(), out.size(), TINYGLTF_TARGET_ARRAY_BUFFER);
    w.m.accessors.push_back(a);
    return (int)w.m.accessors.size() - 1;
}

bool identity_rect(const double so[4])
{
    return so[0] == 1 && so[1] == 1 && so[2] == 0 && so[3] == 0;
}

/* The texture's extras.lightmap (lmb_gltf_add_lightmap_texture), or an empty object. */
Value::Object texture_lightmap_extras(const tinygltf::Model &m, int texture)
{
    if (texture < 0 || (size_t)texture >= m.textures.size())
        return Value::Object();
    const Value &x = m.textures[(size_t)texture].extras;
    if (!x.IsObject() || !x.Has("lightmap") || !x.Get("lightmap").IsObject())
        return Value::Object();
    return x.Get("lightmap").Get<Value::Object>();
}

int lightmapped_material(const lmb_gltf_doc &doc, tinygltf::Model &m, int material, int texture, int direction_texture,
                         const double so[4], std::map<std::string, int> &cache)
{
    char key[256];
    std::snprintf(key, sizeof key, "%d %d %.17g %.17g %.17g %.17g", material, texture, so[0], so[1], so[2], so[3]);
    auto it = cache.find(key);
    if (it != cache.end())
        return it->second;
    tinygltf::Material mat = material >= 0 ? m.materials[(size_t)material] : tinygltf::Material();
    if (material < 0)
        mat.name = "default";
    if (material < 0 && doc.has_default_albedo) { /* as the bake saw it: materials.default.albedo */
        mat.pbrMetallicRoughness.baseColorFactor = {doc.default_albedo[0], doc.default_albedo[1], doc.default_albedo[2],
                                                    1.0};
        mat.pbrMetallicRoughness.metallicFactor = 0.0;
    }
    mat.name += " (lightmap)";
    Value::Object lm = texture_lightmap_extras(m, texture);
    bool radiance = lm.count("scale") && lm["scale"].IsString() && lm["scale"].Get<std::string>() == "radiance";
    Value::Object ext;
    ext["index"] = Value(texture);
    ext["texCoord"] = Value(1);
    ext["intensity"] = Value(radiance ? 3.14159265358979323846 : 1.0); /* texel x intensity = E */
    if (!identity_rect(so)) {
        Value::Object tt;
        tt["scale"] = Value(Value::Array{Value(so[0]), Value(so[1])});
        tt["offset"] = Value(Value::Array{Value(so[2]), Value(so[3])});
        Value::Object exts;
        exts["KHR_texture_transform"] = Value(tt);
        ext["extensions"] = Value(exts);
    }
    mat.extensions["MOZ_lightmap"] = Value(ext);
    if (direction_texture >= 0) {
        Value::Object extras = mat.extras.IsObject() ? mat.extras.Get<Value::Object>() : Value::Object();
        Value::Object dir;
        dir["index"] = Value(direction_texture);
        dir["texCoord"] = Value(1);
        dir["encoding"] = Value(std::string("rgb = (D + 1) / 2, linear; D = the light's mean direction, world space, |D| <= 1"));
        dir["decode"] = Value(std::string("E(n') = E * max(0, 1 + 1.5 dot(D, n')) / (1 + 1.5 dot(D, n)); E: MOZ_lightmap, n: the vertex normal"));
        extras["lightmap_directional"] = Value(dir);
        mat.extras = Value(extras);
    }
    m.materials.push_back(mat);
    int index = (int)m.materials.size() - 1;
    cache[key] = index;
    return index;
}

void use_extension(tinygltf::Model &m, const char *name)
{
    for (const auto &e : m.extensionsUsed)
        if (e == name)
            return;
    m.extensionsUsed.push_back(name);
}

tinygltf::Primitive rebuild(writer &w, const tinygltf::Primitive &orig, const lmb_gltf_prim_out &p)
{
    tinygltf::Primitive q;
    q.material = orig.material;
    q.mode = TINYGLTF_MODE_TRIANGLES;
    q.extras = orig.extras;
    q.attributes["POSITION"] = add_float_accessor(w, p.positions, p.vertex_count, 3, true);
    if (p.normals)
        q.attributes["NORMAL"] = add_float_accessor(w, p.normals, p.vertex_count, 3, false);
    q.attributes["TEXCOORD_1"] = add_float_accessor(w, p.uv1, p.vertex_count, 2, false);
    /* glTF requires TEXCOORD_n to start at 0: a primitive without UV0 gets the lightmap UVs
     * there too (no texture of its material reads them) */
    q.attributes["TEXCOORD_0"] = p.uv0 ? add_float_accessor(w, p.uv0, p.vertex_count, 2, false) : q.attributes["TEXCOORD_1"];
    for (const auto &attr : orig.attributes) {
        if (attr.first == "POSITION" || attr.first == "NORMAL" || attr.first == "TEXCOORD_0" || attr.first == "TEXCOORD_1")
            continue;
        int a = gather_accessor(w, attr.second, p.source, p.vertex_count);
        if (a >= 0)
            q.attributes[attr.first] = a;
    }
    tinygltf::Accessor ix;
    ix.bufferView = add_view(w, p.indices, sizeof(uint32_t) * 3 * p.triangle_count, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    ix.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    ix.count = 3 * (size_t)p.triangle_count;
    ix.type = TINYGLTF_TYPE_SCALAR;
    w.m.accessors.push_back(ix);
    q.indices = (int)w.m.accessors.size() - 1;
    return q;
}

std::string base64(const std::vector<unsigned char> &in)
{
    static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        unsigned v = (unsigned)in[i] << 16 | (unsigned)in[i + 1] << 8 | in[i + 2];
        out += t[v >> 18 & 63]; out += t[v >> 12 & 63]; out += t[v >> 6 & 63]; out += t[v & 63];
    }
    if (i + 1 == in.size()) {
        unsigned v = (unsigned)in[i] << 16;
        out += t[v >> 18 & 63]; out += t[v >> 12 & 63]; out += "==";
    } else if (i + 2 == in.size()) {
        unsigned v = (unsigned)in[i] << 16 | (unsigned)in[i + 1] << 8;
        out += t[v >> 18 & 63]; out += t[v >> 12 & 63]; out += t[v >> 6 & 63]; out += '=';
    }
    return out;
}

/* Images keep their URIs (lmbake does not re-encode textures); an image that came as a data
 * URI (tinygltf drops the string on load) is written back as one from its kept bytes. */
bool keep_image(const std::string *, const std::string *, const tinygltf::Image *image, bool, std::string *out_uri,
                void *)
{
    if (!image->uri.empty() || image->bufferView >= 0 || image->image.empty())
        return false;
    *out_uri = "data:" + (image->mimeType.empty() ? std::string("application/octet-stream") : image->mimeType) +
               ";base64," + base64(image->image);
    return true;
}

} // namespace

extern "C" int32_t lmb_gltf_add_lightmap_texture(lmb_gltf_doc *doc, const lmb_gltf_lightmap_files *f, lmb_error *err)
{
    try {
        tinygltf::Model &m = doc->model;
        tinygltf::Image png, hdr;
        png.uri = f->png;
        png.mimeType = "image/png";
        hdr.uri = f->hdr;
        m.images.push_back(png);
        m.images.push_back(hdr);
        tinygltf::Texture t;
        t.source = (int)m.images.size() - 2;
        Value::Object rgbe;
        rgbe["source"] = Value((int)m.images.size() - 1);
        t.extensions["MOZ_texture_rgbe"] = Value(rgbe);
        Value::Object files, lm;
        const std::pair<const char *, const char *> named[] = {
            {"exr", f->exr}, {"hdr", f->hdr}, {"png", f->png}, {"ktx2", f->ktx2}, {"rgbm", f->rgbm},
            {"directionPng", f->direction_png}, {"directionExr", f->direction_exr}, {"directionKtx2", f->direction_ktx2},
            {"shadowmask", f->shadowmask}};
        for (const auto &n : named)
            if (n.second)
                files[n.first] = Value(std::string(n.second));
        lm["atlas"] = Value((int)f->atlas);
        lm["width"] = Value((int)f->width);
        lm["height"] = Value((int)f->height);
        lm["scale"] = Value(std::string(f->radiance ? "radiance" : "irradiance"));
        lm["unit"] = Value(std::string(f->radiance ? "nits (E / pi)" : "lux (E)"));
        lm["files"] = Value(files);
        if (f->rgbm) {
            Value::Object r;
            r["range"] = Value(f->rgbm_range);
            r["decode"] = Value(std::string(LMB_RGBM_DECODE));
            lm["rgbm"] = Value(r);
        }
        if (f->ktx2) {
            Value::Object k;
            k["vkFormat"] = Value((int)f->ktx2_vkformat);
            lm["ktx2"] = Value(k);
        }
        if (f->groups) {
            Value::Array groups;
            for (uint32_t g = 0; g < f->groups; g++) {
                Value::Object one, gf;
                gf["exr"] = Value(std::string(f->group_exr[g]));
                gf["hdr"] = Value(std::string(f->group_hdr[g]));
                if (f->group_ktx2[g])
                    gf["ktx2"] = Value(std::string(f->group_ktx2[g]));
                one["name"] = Value(std::string(f->group_name[g]));
                one["scale"] = Value(f->group_scale[g]);
                one["intensity"] = Value(Value::Array{Value(f->group_intensity[g][0]), Value(f->group_intensity[g][1]),
                                                      Value(f->group_intensity[g][2])});
                one["files"] = Value(gf);
                groups.push_back(Value(one));
            }
            lm["groups"] = Value(groups);
        }
        Value::Object extras;
        extras["lightmap"] = Value(lm);
        t.extras = Value(extras);
        m.textures.push_back(t);
        use_extension(m, "MOZ_lightmap");
        use_extension(m, "MOZ_texture_rgbe");
        return (int32_t)m.textures.size() - 1;
    } catch (const std::exception &e) {
        lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: %s", e.what());
        return -1;
    }
}

extern "C" int32_t lmb_gltf_add_direction_texture(lmb_gltf_doc *doc, const char *png_uri, lmb_error *err)
{
    try {
        tinygltf::Model &m = doc->model;
        tinygltf::Image png;
        png.uri = png_uri;
        png.mimeType = "image/png";
        m.images.push_back(png);
        tinygltf::Texture t;
        t.source = (int)m.images.size() - 1;
        m.textures.push_back(t);
        return (int32_t)m.textures.size() - 1;
    } catch (const std::exception &e) {
        lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: %s", e.what());
        return -1;
    }
}

extern "C" lmb_status lmb_gltf_lightmap_instanced_node(lmb_gltf_doc *doc, uint32_t node, const lmb_gltf_prim_out *prims,
                                                       uint32_t count, int32_t texture, int32_t direction_texture,
                                                       const float *scale_offsets, uint32_t copies, lmb_error *err)
{
    static const double identity[4] = {1, 1, 0, 0};
    lmb_status st = lmb_gltf_lightmap_node(doc, node, prims, count, texture, direction_texture, identity, err);
    if (st != LMB_OK)
        return st;
    try {
        tinygltf::Model &m = doc->model;
        writer w{m, new_buffer(m)};
        tinygltf::Node &n = m.nodes[node];
        std::vector<float> scale(2 * (size_t)copies), offset(2 * (size_t)copies);
        for (uint32_t k = 0; k < copies; k++) {
            scale[2 * k] = scale_offsets[4 * k];
            scale[2 * k + 1] = scale_offsets[4 * k + 1];
            offset[2 * k] = scale_offsets[4 * k + 2];
            offset[2 * k + 1] = scale_offsets[4 * k + 3];
        }
        int a_scale = add_float_accessor(w, scale.data(), copies, 2, false);
        int a_offset = add_float_accessor(w, offset.data(), copies, 2, false);
        m.bufferViews[(size_t)m.accessors[(size_t)a_scale].bufferView].target = 0; /* instance data, not a vertex buffer */
        m.bufferViews[(size_t)m.accessors[(size_t)a_offset].bufferView].target = 0;
        Value::Object ext = n.extensions["EXT_mesh_gpu_instancing"].Get<Value::Object>();
        Value::Object attrs = ext.count("attributes") && ext["attributes"].IsObject() ? ext["attributes"].Get<Value::Object>()
                                                                                      : Value::Object();
        attrs["_LIGHTMAP_SCALE"] = Value(a_scale);
        attrs["_LIGHTMAP_OFFSET"] = Value(a_offset);
        ext["attributes"] = Value(attrs);
        n.extensions["EXT_mesh_gpu_instancing"] = Value(ext);
        Value::Object extras = n.extras.Get<Value::Object>();
        Value::Object lm = extras["lightmap"].Get<Value::Object>();
        lm.erase("scaleOffset");
        lm["perInstance"] = Value(std::string("EXT_mesh_gpu_instancing attributes _LIGHTMAP_SCALE, _LIGHTMAP_OFFSET: "
                                              "uv_atlas = TEXCOORD_1 * scale + offset"));
        extras["lightmap"] = Value(lm);
        n.extras = Value(extras);
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: node %u's instance rectangles: %s", node, e.what());
    }
}

namespace {

/* Node `node`'s extras.lightmap: its atlas, texCoord, rectangle and files (from the texture). */
void node_lightmap_extras(tinygltf::Model &m, tinygltf::Node &n, int texture, const double so[4])
{
    Value::Object tex = texture_lightmap_extras(m, texture), lm;
    lm["atlas"] = tex.count("atlas") ? tex["atlas"] : Value(0);
    lm["texCoord"] = Value(1);
    lm["scaleOffset"] = Value(Value::Array{Value(so[0]), Value(so[1]), Value(so[2]), Value(so[3])});
    lm["scale"] = tex.count("scale") ? tex["scale"] : Value(std::string("irradiance"));
    lm["files"] = tex.count("files") ? tex["files"] : Value(Value::Object());
    if (tex.count("groups"))
        lm["groups"] = tex["groups"];
    Value::Object extras = n.extras.IsObject() ? n.extras.Get<Value::Object>() : Value::Object();
    extras["lightmap"] = Value(lm);
    n.extras = Value(extras);
}

/* The lightmapped copy of node's mesh; material_rect (NULL: none) goes into its materials'
 * MOZ_lightmap as KHR_texture_transform, node_rect into the node's extras. */
lmb_status lightmap_node(lmb_gltf_doc *doc, uint32_t node, const lmb_gltf_prim_out *prims, uint32_t count, int32_t texture,
                         int32_t direction_texture, const double *material_rect, const double node_rect[4],
                         const char *label, lmb_error *err)
{
    static const double identity[4] = {1, 1, 0, 0};
    const double *mr = material_rect ? material_rect : identity;
    try {
        tinygltf::Model &m = doc->model;
        writer w{m, new_buffer(m)};
        tinygltf::Node &n = m.nodes[node];
        tinygltf::Mesh mesh = m.meshes[(size_t)n.mesh];
        mesh.name = (mesh.name.empty() ? std::string("mesh") : mesh.name) + " (" +
                    (label ? std::string(label) : n.name.empty() ? "node " + std::to_string(node) : n.name) +
                    " lightmap)";
        mesh.weights.clear();
        for (uint32_t k = 0; k < count; k++) {
            const lmb_gltf_prim_out &p = prims[k];
            tinygltf::Primitive q = rebuild(w, mesh.primitives[p.gltf_primitive], p);
            q.material = lightmapped_material(*doc, m, q.material, texture, direction_texture, mr, doc->lightmap_materials);
            mesh.primitives[p.gltf_primitive] = q;
        }
        if (!identity_rect(mr))
            use_extension(m, "KHR_texture_transform");
        node_lightmap_extras(m, n, texture, node_rect);
        m.meshes.push_back(mesh);
        doc->replaced_meshes.push_back(m.nodes[node].mesh);
        m.nodes[node].mesh = (int)m.meshes.size() - 1;
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: node %u: %s", node, e.what());
    }
}

} // namespace

extern "C" lmb_status lmb_gltf_lightmap_node(lmb_gltf_doc *doc, uint32_t node, const lmb_gltf_prim_out *prims,
                                             uint32_t count, int32_t texture, int32_t direction_texture,
                                             const double scale_offset[4], lmb_error *err)
{
    return lightmap_node(doc, node, prims, count, texture, direction_texture, scale_offset, scale_offset, nullptr, err);
}

extern "C" lmb_status lmb_gltf_lightmap_shared_mesh(lmb_gltf_doc *doc, uint32_t node, const lmb_gltf_prim_out *prims,
                                                    uint32_t count, int32_t texture, int32_t direction_texture,
                                                    const double scale_offset[4], lmb_error *err)
{
    return lightmap_node(doc, node, prims, count, texture, direction_texture, nullptr, scale_offset, "shared", err);
}

extern "C" lmb_status lmb_gltf_share_lightmapped_mesh(lmb_gltf_doc *doc, uint32_t node, uint32_t from_node,
                                                      int32_t texture, const double scale_offset[4], lmb_error *err)
{
    try {
        tinygltf::Model &m = doc->model;
        tinygltf::Node &n = m.nodes[node];
        doc->replaced_meshes.push_back(n.mesh);
        n.mesh = m.nodes[from_node].mesh;
        node_lightmap_extras(m, n, texture, scale_offset);
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: node %u: %s", node, e.what());
    }
}

extern "C" void lmb_gltf_set_default_albedo(lmb_gltf_doc *doc, const double albedo[3])
{
    doc->has_default_albedo = true;
    for (int k = 0; k < 3; k++)
        doc->default_albedo[k] = albedo[k];
}

extern "C" lmb_status lmb_gltf_set_light_modes(lmb_gltf_doc *doc, const lmb_light *lights, uint32_t count,
                                               lmb_error *err)
{
    try {
        tinygltf::Model &m = doc->model;
        bool mixed = false;
        for (uint32_t i = 0; i < count; i++)
            mixed |= lights[i].mode != LMB_LIGHT_BAKED;
        if (!mixed)
            return LMB_OK;
        Value::Object channels;
        for (uint32_t i = 0; i < count; i++) {
            const lmb_light &l = lights[i];
            if (l.gltf_light >= m.lights.size())
                continue;
            tinygltf::Light &gl = m.lights[l.gltf_light];
            Value::Object extras = gl.extras.IsObject() ? gl.extras.Get<Value::Object>() : Value::Object();
            Value::Object lm;
            lm["mode"] = Value(std::string(lmb_light_mode_name(l.mode)));
            lm["inLightmap"] = Value(std::string(l.mode == LMB_LIGHT_BAKED      ? "direct and indirect"
                                                 : l.mode == LMB_LIGHT_INDIRECT ? "indirect only: draw its direct light"
                                                                                : "nothing: draw it"));
            if (l.shadowmask_channel >= 0) {
                std::string ch(1, "RGBA"[l.shadowmask_channel]);
                lm["shadowmaskChannel"] = Value(ch);
                channels[ch] = Value(std::string(l.name));
            }
            if (!extras.count("lightmap") || !extras["lightmap"].IsObject()) { /* its first node decides */
                extras["lightmap"] = Value(lm);
                gl.extras = Value(extras);
            }
        }
        if (!channels.empty())
            for (auto &t : m.textures) {
                if (!t.extras.IsObject() || !t.extras.Has("lightmap"))
                    continue;
                Value::Object extras = t.extras.Get<Value::Object>();
                Value::Object lm = extras["lightmap"].Get<Value::Object>();
                Value::Object sm;
                sm["lights"] = Value(channels);
                sm["meaning"] = Value(std::string("per channel the share of the light's shadow rays that reach it, 0..1 "
                                                  "(8-bit, linear); the engine multiplies the light's real-time direct "
                                                  "light by it"));
                lm["shadowmask"] = Value(sm);
                extras["lightmap"] = Value(lm);
                t.extras = Value(extras);
            }
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: cannot name the lights' bake modes: %s", e.what());
    }
}

extern "C" lmb_status lmb_gltf_set_records(lmb_gltf_doc *doc, const char *uri, uint32_t count, lmb_error *err)
{
    try {
        tinygltf::Asset &asset = doc->model.asset;
        Value::Object extras = asset.extras.IsObject() ? asset.extras.Get<Value::Object>() : Value::Object();
        Value::Object lmbake = extras.count("lmbake") && extras["lmbake"].IsObject()
                                   ? extras["lmbake"].Get<Value::Object>() : Value::Object();
        Value::Object records;
        records["uri"] = Value(std::string(uri));
        records["count"] = Value((int)count);
        records["layout"] = Value(std::string("float32le x y z reach"));
        lmbake["irradianceCacheRecords"] = Value(records);
        extras["lmbake"] = Value(lmbake);
        asset.extras = Value(extras);
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: cannot name the records file: %s", e.what());
    }
}

lmb_status lmb_gltf_save(lmb_gltf_doc *doc, const char *path, const char *bin_name, lmb_error *err)
{
    try {
        tinygltf::Model &m = doc->model;
        std::string stem(bin_name);
        size_t dot = stem.rfind('.');
        if (dot != std::string::npos)
            stem = stem.substr(0, dot);
        lmb_gltf_prune_replaced(doc);
        lmb_gltf_add_probes(doc);
        for (size_t i = 0; i < m.buffers.size(); i++) {
            if (m.buffers[i].name == "lmbake")
                m.buffers[i].uri = bin_name;
            else if (m.buffers[i].uri.empty() || m.buffers[i].uri.rfind("data:", 0) == 0)
                m.buffers[i].uri = stem + "-input" + std::to_string(i) + ".bin";
        }
        m.asset.generator = "lmbake " LMB_VERSION_STRING;
        tinygltf::TinyGLTF g;
        g.SetImageWriter(keep_image, nullptr);
        if (!g.WriteGltfSceneToFile(&m, path, false, false, true, false))
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write the glTF", path);
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write the glTF: %s", path, e.what());
    }
}
