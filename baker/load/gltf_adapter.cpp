/*
 * tinygltf adapter: the only place lmbake's loader touches C++. Parses the file with
 * tinygltf (images are not decoded: a no-op image loader), then copies the fields lmbake
 * reads into the plain C arrays of lmb_gltf_view. Strings point into the tinygltf model,
 * which the doc keeps alive for the writer. No C++ exception or type crosses the header.
 */
#include "gltf_adapter.h"

#include <cerrno>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "gltf_doc.hpp"
#include "uri.h"

namespace {

/* Images are not decoded (the baker reads textures through OpenImageIO when it needs
 * them); their encoded bytes are kept so the writer can re-emit data-URI images as is. */
bool skip_image(tinygltf::Image *image, const int, std::string *, std::string *, int, int,
                const unsigned char *bytes, int size, void *)
{
    if (image->uri.empty() && image->bufferView < 0 && bytes && size > 0)
        image->image.assign(bytes, bytes + size);
    return true;
}

/* tinygltf's file access, confined to the input's folder (issue 15; load/uri.h): buffers and
 * images are read only when the file they name, symbolic links followed, lies inside it;
 * nothing is expanded (~, $VARS) and nothing is written. */
struct confined_fs {
    std::string folder;
};

bool confined_exists(const std::string &path, void *user)
{
    char real[4096];
    return lmb_path_inside(static_cast<confined_fs *>(user)->folder.c_str(), path.c_str(), real, sizeof real) != 0;
}

std::string no_expansion(const std::string &path, void *)
{
    return path;
}

bool confined_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
    char real[4096];
    if (!lmb_path_inside(static_cast<confined_fs *>(user)->folder.c_str(), path.c_str(), real, sizeof real)) {
        if (err)
            *err += "'" + path + "' is not a file inside the input's folder\n";
        return false;
    }
    FILE *f = std::fopen(real, "rb");
    if (!f) {
        if (err)
            *err += "cannot open '" + path + "'\n";
        return false;
    }
    unsigned char chunk[65536];
    size_t n;
    while ((n = std::fread(chunk, 1, sizeof chunk, f)) > 0)
        out->insert(out->end(), chunk, chunk + n);
    bool ok = !std::ferror(f);
    std::fclose(f);
    return ok;
}

bool no_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
    if (err)
        *err += "the loader writes no files\n";
    return false;
}

/* Returns obj[key] if obj is an object holding key, else nullptr. */
const tinygltf::Value *member(const tinygltf::Value &obj, const char *key)
{
    if (!obj.IsObject() || !obj.Has(key))
        return nullptr;
    return &obj.Get(key);
}

const tinygltf::Value *extension(const tinygltf::ExtensionMap &map, const char *name)
{
    auto it = map.find(name);
    return it == map.end() ? nullptr : &it->second;
}

int32_t int_member(const tinygltf::Value *obj, const char *key, int32_t fallback)
{
    const tinygltf::Value *v = obj ? member(*obj, key) : nullptr;
    return (v && v->IsNumber()) ? v->GetNumberAsInt() : fallback;
}

int components_of(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

int32_t attribute(const tinygltf::Primitive &p, const char *name)
{
    auto it = p.attributes.find(name);
    return it == p.attributes.end() ? -1 : it->second;
}

void copy_doubles(double *dst, const std::vector<double> &src, size_t n)
{
    for (size_t i = 0; i < n && i < src.size(); i++)
        dst[i] = src[i];
}

void fill_buffers(lmb_gltf_doc &d)
{
    for (const auto &b : d.model.buffers)
        d.buffers.push_back({b.data.data(), b.data.size()});
    for (const auto &v : d.model.bufferViews)
        d.buffer_views.push_back({v.buffer, v.byteOffset, v.byteLength, v.byteStride});
    for (const auto &a : d.model.accessors) {
        lmb_gltf_accessor c{};
        c.name = a.name.c_str();
        c.buffer_view = a.bufferView;
        c.offset = a.byteOffset;
        c.component_type = a.componentType;
        c.components = components_of(a.type);
        c.count = a.count;
        c.normalized = a.normalized;
        if (a.sparse.isSparse) {
            c.sparse_count = a.sparse.count < 0 ? 0 : (size_t)a.sparse.count;
            c.sparse_indices_view = a.sparse.indices.bufferView;
            c.sparse_indices_offset = a.sparse.indices.byteOffset < 0 ? 0 : (size_t)a.sparse.indices.byteOffset;
            c.sparse_indices_type = a.sparse.indices.componentType;
            c.sparse_values_view = a.sparse.values.bufferView;
            c.sparse_values_offset = a.sparse.values.byteOffset < 0 ? 0 : (size_t)a.sparse.values.byteOffset;
        } else {
            c.sparse_indices_view = c.sparse_values_view = -1;
        }
        d.accessors.push_back(c);
    }
}

void fill_meshes(lmb_gltf_doc &d)
{
    for (const auto &m : d.model.meshes) {
        lmb_gltf_mesh c{};
        c.name = m.name.c_str();
        c.first_primitive = (uint32_t)d.primitives.size();
        c.primitive_count = (uint32_t)m.primitives.size();
        for (const auto &p : m.primitives) {
            lmb_gltf_primitive q{};
            q.mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
            q.material = p.material;
            q.indices = p.indices;
            q.position = attribute(p, "POSITION");
            q.normal = attribute(p, "NORMAL");
            q.texcoord0 = attribute(p, "TEXCOORD_0");
            q.texcoord1 = attribute(p, "TEXCOORD_1");
            q.color0 = attribute(p, "COLOR_0");
            q.any_attribute = p.attributes.empty() ? -1 : p.attributes.begin()->second;
            d.primitives.push_back(q);
        }
        d.meshes.push_back(c);
    }
}

/* A string extra (lightmap_mode, lightmap_group) as written: "" when absent, "?" when not a
 * string (the loader names it). */
const char *extras_string(const tinygltf::Value &extras, const char *key)
{
    const tinygltf::Value *v = extras.IsObject() ? member(extras, key) : nullptr;
    if (!v)
        return "";
    return v->IsString() ? v->Get<std::string>().c_str() : "?";
}

/* extras.lightmap_probes: [x, y, z], integers 1..256 (docs/probes.md); 0 absent, -1 malformed. */
void probe_resolution(const tinygltf::Value &extras, int32_t out[3])
{
    out[0] = out[1] = out[2] = 0;
    const tinygltf::Value *v = extras.IsObject() ? member(extras, "lightmap_probes") : nullptr;
    if (!v)
        return;
    out[0] = out[1] = out[2] = -1;
    if (!v->IsArray() || v->ArrayLen() != 3)
        return;
    int32_t r[3];
    for (int k = 0; k < 3; k++) {
        const tinygltf::Value &e = v->Get((int)k);
        double x = e.IsNumber() ? e.GetNumberAsDouble() : -1;
        if (!(x >= 1 && x <= 256 && x == (double)(int32_t)x))
            return;
        r[k] = (int32_t)x;
    }
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

void fill_node(lmb_gltf_doc &d, const tinygltf::Node &n, lmb_gltf_node &c)
{
    c.name = n.name.c_str();
    c.mesh = n.mesh;
    c.light = int_member(extension(n.extensions, "KHR_lights_punctual"), "light", -1);
    c.first_child = (uint32_t)d.children.size();
    c.child_count = (uint32_t)n.children.size();
    d.children.insert(d.children.end(), n.children.begin(), n.children.end());
    c.has_matrix = n.matrix.size() == 16;
    copy_doubles(c.matrix, n.matrix, 16);
    c.rotation[3] = 1.0;
    c.scale[0] = c.scale[1] = c.scale[2] = 1.0;
    copy_doubles(c.translation, n.translation, 3);
    copy_doubles(c.rotation, n.rotation, 4);
    copy_doubles(c.scale, n.scale, 3);
    c.extras_lightmap = -1;
    if (!d.extras_key.empty()) {
        const tinygltf::Value *flag = member(n.extras, d.extras_key.c_str());
        if (flag && flag->IsBool())
            c.extras_lightmap = flag->Get<bool>() ? 1 : 0;
        else if (flag && flag->IsNumber())
            c.extras_lightmap = flag->GetNumberAsDouble() != 0.0;
    }
    c.lightmap_mode = extras_string(n.extras, "lightmap_mode");
    c.lightmap_group = extras_string(n.extras, "lightmap_group");
    probe_resolution(n.extras, c.lightmap_probes);
    const tinygltf::Value *gpu = extension(n.extensions, "EXT_mesh_gpu_instancing");
    const tinygltf::Value *attrs = gpu ? member(*gpu, "attributes") : nullptr;
    c.has_gpu_instancing = attrs != nullptr;
    c.gpu_translation = int_member(attrs, "TRANSLATION", -1);
    c.gpu_rotation = int_member(attrs, "ROTATION", -1);
    c.gpu_scale = int_member(attrs, "SCALE", -1);
    c.skinned = n.skin >= 0;
    c.morphing = 0;
    if (n.mesh >= 0 && (size_t)n.mesh < d.model.meshes.size())
        for (const auto &p : d.model.meshes[(size_t)n.mesh].primitives)
            c.morphing |= !p.targets.empty();
}

double number_member(const tinygltf::Value *obj, const char *key, double fallback)
{
    const tinygltf::Value *v = obj ? member(*obj, key) : nullptr;
    return (v && v->IsNumber()) ? v->GetNumberAsDouble() : fallback;
}

/* Copies up to n numbers of the array obj[key] into dst (what is missing keeps its default). */
void number_array(const tinygltf::Value *obj, const char *key, double *dst, int n)
{
    const tinygltf::Value *v = obj ? member(*obj, key) : nullptr;
    if (!v || !v->IsArray())
        return;
    for (int i = 0; i < n && i < (int)v->ArrayLen(); i++)
        if (v->Get(i).IsNumber())
            dst[i] = v->Get(i).GetNumberAsDouble();
}

/* A textureInfo's fields and its KHR_texture_transform object `t` (may be null), as written. */
lmb_gltf_texture_info texture_info(int32_t index, int32_t texcoord, const tinygltf::Value *t)
{
    lmb_gltf_texture_info c{};
    c.index = index;
    c.texcoord = texcoord;
    c.scale[0] = c.scale[1] = 1.0;
    c.transform_texcoord = -1;
    if (t && t->IsObject()) {
        c.has_transform = 1;
        number_array(t, "offset", c.offset, 2);
        number_array(t, "scale", c.scale, 2);
        c.rotation = number_member(t, "rotation", 0.0);
        c.transform_texcoord = int_member(t, "texCoord", -1);
    }
    return c;
}

lmb_gltf_texture_info texture_info(const tinygltf::TextureInfo &t)
{
    return texture_info(t.index, t.texCoord, extension(t.extensions, "KHR_texture_transform"));
}

/* A textureInfo held as a JSON object inside an extension (spec-gloss's textures). */
lmb_gltf_texture_info texture_info(const tinygltf::Value *obj)
{
    const tinygltf::Value *ext = obj ? member(*obj, "extensions") : nullptr;
    return texture_info(int_member(obj, "index", -1), int_member(obj, "texCoord", 0),
                        ext ? member(*ext, "KHR_texture_transform") : nullptr);
}

void fill_materials(lmb_gltf_doc &d)
{
    for (const auto &m : d.model.materials) {
        lmb_gltf_material c{};
        c.name = m.name.c_str();
        const auto &pbr = m.pbrMetallicRoughness;
        c.base_color[0] = c.base_color[1] = c.base_color[2] = c.base_color[3] = 1.0;
        copy_doubles(c.base_color, pbr.baseColorFactor, 4);
        c.base_color_texture = texture_info(pbr.baseColorTexture);
        c.metallic = pbr.metallicFactor;
        c.metallic_roughness_texture = texture_info(pbr.metallicRoughnessTexture);
        copy_doubles(c.emissive, m.emissiveFactor, 3);
        c.emissive_strength = number_member(extension(m.extensions, "KHR_materials_emissive_strength"),
                                            "emissiveStrength", 1.0);
        c.emissive_texture = texture_info(m.emissiveTexture);
        c.double_sided = m.doubleSided;
        const tinygltf::Value *sg = extension(m.extensions, "KHR_materials_pbrSpecularGlossiness");
        c.spec_gloss = sg && sg->IsObject();
        c.diffuse[0] = c.diffuse[1] = c.diffuse[2] = c.diffuse[3] = 1.0;
        c.specular[0] = c.specular[1] = c.specular[2] = 1.0;
        c.glossiness = 1.0;
        c.diffuse_texture = texture_info(c.spec_gloss ? member(*sg, "diffuseTexture") : nullptr);
        c.specular_glossiness_texture = texture_info(c.spec_gloss ? member(*sg, "specularGlossinessTexture") : nullptr);
        if (c.spec_gloss) {
            number_array(sg, "diffuseFactor", c.diffuse, 4);
            number_array(sg, "specularFactor", c.specular, 3);
            c.glossiness = number_member(sg, "glossinessFactor", 1.0);
        }
        c.unlit = extension(m.extensions, "KHR_materials_unlit") != nullptr;
        c.alpha_mode = m.alphaMode.empty() || m.alphaMode == "OPAQUE" ? 0
                       : m.alphaMode == "MASK"                        ? 1
                       : m.alphaMode == "BLEND"                       ? 2
                                                                      : -1;
        c.alpha_cutoff = m.alphaCutoff;
        const tinygltf::Value *tr = extension(m.extensions, "KHR_materials_transmission");
        c.has_transmission = tr != nullptr;
        c.transmission = number_member(tr, "transmissionFactor", 0.0);
        c.transmission_texture = texture_info(tr ? member(*tr, "transmissionTexture") : nullptr);
        const tinygltf::Value *vol = extension(m.extensions, "KHR_materials_volume");
        c.has_volume = vol != nullptr;
        c.thickness = number_member(vol, "thicknessFactor", 0.0);
        c.attenuation_distance = number_member(vol, "attenuationDistance", INFINITY);
        c.attenuation_color[0] = c.attenuation_color[1] = c.attenuation_color[2] = 1.0;
        number_array(vol, "attenuationColor", c.attenuation_color, 3);
        const tinygltf::Value *dt = extension(m.extensions, "KHR_materials_diffuse_transmission");
        c.diffuse_transmission = number_member(dt, "diffuseTransmissionFactor", 0.0);
        c.diffuse_transmission_color[0] = c.diffuse_transmission_color[1] = c.diffuse_transmission_color[2] = 1.0;
        number_array(dt, "diffuseTransmissionColorFactor", c.diffuse_transmission_color, 3);
        c.diffuse_transmission_textures = (dt && member(*dt, "diffuseTransmissionTexture") ? 1 : 0) +
                                          (dt && member(*dt, "diffuseTransmissionColorTexture") ? 1 : 0);
        d.materials.push_back(c);
    }
}

void fill_textures(lmb_gltf_doc &d)
{
    for (const auto &t : d.model.textures) {
        /* EXT_texture_webp: its image where the texture has no core `source` (glTF-Transform writes none) */
        int32_t source = t.source >= 0 ? t.source : int_member(extension(t.extensions, "EXT_texture_webp"), "source", -1);
        lmb_gltf_texture c{source, t.sampler, TINYGLTF_TEXTURE_WRAP_REPEAT, TINYGLTF_TEXTURE_WRAP_REPEAT, -1};
        if (t.sampler >= 0 && (size_t)t.sampler < d.model.samplers.size()) {
            const auto &s = d.model.samplers[(size_t)t.sampler];
            c.wrap_s = s.wrapS;
            c.wrap_t = s.wrapT;
            c.mag_filter = s.magFilter;
        }
        d.textures.push_back(c);
    }
}

void fill_lights(lmb_gltf_doc &d)
{
    for (const auto &l : d.model.lights) {
        lmb_gltf_light c{};
        c.name = l.name.c_str();
        c.type = l.type.c_str();
        c.color[0] = c.color[1] = c.color[2] = 1.0;
        copy_doubles(c.color, l.color, 3);
        c.intensity = l.intensity;
        c.range = l.range;
        c.inner_cone = l.spot.innerConeAngle;
        c.outer_cone = l.spot.outerConeAngle;
        c.lightmap_mode = extras_string(l.extras, "lightmap_mode");
        c.lightmap_group = extras_string(l.extras, "lightmap_group");
        d.lights.push_back(c);
    }
}

/* The scene's EXT_lights_image_based light into d.view.ibl (present, and usable or why not). */
void fill_ibl(lmb_gltf_doc &d, const tinygltf::Scene &scene)
{
    lmb_gltf_ibl &ibl = d.view.ibl;
    const tinygltf::Value *ref = extension(scene.extensions, "EXT_lights_image_based");
    if (!ref)
        return;
    ibl.present = 1;
    ibl.index = int_member(ref, "light", -1);
    ibl.intensity = 1.0f;
    ibl.rotation[3] = 1.0f;
    std::snprintf(ibl.name, sizeof ibl.name, "light %d", ibl.index);
    const tinygltf::Value *root = extension(d.model.extensions, "EXT_lights_image_based");
    const tinygltf::Value *lights = root ? member(*root, "lights") : nullptr;
    if (!lights || !lights->IsArray() || ibl.index < 0 || (size_t)ibl.index >= lights->ArrayLen()) {
        std::snprintf(ibl.problem, sizeof ibl.problem, "the scene names light %d, which the extension's lights do not "
                      "hold", ibl.index);
        return;
    }
    const tinygltf::Value &l = lights->Get(ibl.index);
    const tinygltf::Value *name = member(l, "name");
    if (name && name->IsString())
        std::snprintf(ibl.name, sizeof ibl.name, "%s", name->Get<std::string>().c_str());
    const tinygltf::Value *intensity = member(l, "intensity");
    if (intensity && intensity->IsNumber())
        ibl.intensity = (float)intensity->GetNumberAsDouble();
    const tinygltf::Value *rot = member(l, "rotation");
    if (rot && rot->IsArray() && rot->ArrayLen() == 4)
        for (int k = 0; k < 4; k++)
            if (rot->Get(k).IsNumber())
                ibl.rotation[k] = (float)rot->Get(k).GetNumberAsDouble();
    const tinygltf::Value *sh = member(l, "irradianceCoefficients");
    int ok = sh && sh->IsArray() && sh->ArrayLen() == 9;
    for (int i = 0; ok && i < 9; i++) {
        const tinygltf::Value &row = sh->Get(i);
        ok = row.IsArray() && row.ArrayLen() == 3;
        for (int c = 0; ok && c < 3; c++) {
            ok = row.Get(c).IsNumber() && std::isfinite(row.Get(c).GetNumberAsDouble());
            if (ok)
                ibl.sh[i][c] = (float)row.Get(c).GetNumberAsDouble();
        }
    }
    if (!ok || !std::isfinite(ibl.intensity) || ibl.intensity < 0) {
        std::snprintf(ibl.problem, sizeof ibl.problem, "light %d: irradianceCoefficients must be 9 x 3 finite numbers "
                      "and intensity a number >= 0", ibl.index);
        return;
    }
    ibl.usable = 1;
}

void fill_scene(lmb_gltf_doc &d)
{
    const auto &m = d.model;
    int s = m.defaultScene >= 0 ? m.defaultScene : (m.scenes.empty() ? -1 : 0);
    d.view.has_scene = s >= 0 && s < (int)m.scenes.size();
    if (d.view.has_scene)
        fill_ibl(d, m.scenes[(size_t)s]);
    if (d.view.has_scene) {
        d.scene_roots.assign(m.scenes[(size_t)s].nodes.begin(), m.scenes[(size_t)s].nodes.end());
        return;
    }
    /* No scene: glTF allows it; lmbake bakes every parentless node. */
    std::vector<char> is_child(m.nodes.size(), 0);
    for (const auto &n : m.nodes)
        for (int c : n.children)
            if (c >= 0 && (size_t)c < m.nodes.size())
                is_child[(size_t)c] = 1;
    for (size_t i = 0; i < m.nodes.size(); i++)
        if (!is_child[i])
            d.scene_roots.push_back((int32_t)i);
}

template <typename T> void expose(const std::vector<T> &v, const T *&ptr, uint32_t &count)
{
    ptr = v.empty() ? nullptr : v.data();
    count = (uint32_t)v.size();
}

void build_view(lmb_gltf_doc &d)
{
    fill_buffers(d);
    fill_meshes(d);
    d.nodes.resize(d.model.nodes.size());
    for (size_t i = 0; i < d.model.nodes.size(); i++)
        d.nodes[i].lod_of = -1;
    /* MSFT_lod: a node's `ids` are its lower levels of detail, nearest first */
    for (size_t i = 0; i < d.model.nodes.size(); i++) {
        const tinygltf::Value *lod = extension(d.model.nodes[i].extensions, "MSFT_lod");
        const tinygltf::Value *ids = lod ? member(*lod, "ids") : nullptr;
        for (int k = 0; ids && ids->IsArray() && k < (int)ids->ArrayLen(); k++) {
            const tinygltf::Value &id = ids->Get(k);
            int64_t j = id.IsNumber() ? (int64_t)id.GetNumberAsDouble() : -1;
            if (j >= 0 && (size_t)j < d.model.nodes.size() && (size_t)j != i)
                d.nodes[(size_t)j].lod_of = (int32_t)i;
        }
    }
    for (size_t i = 0; i < d.model.nodes.size(); i++)
        fill_node(d, d.model.nodes[i], d.nodes[i]);
    fill_materials(d);
    fill_lights(d);
    fill_scene(d);
    for (const auto &e : d.model.extensionsRequired)
        d.ext_required.push_back(e.c_str());
    for (const auto &e : d.model.extensionsUsed)
        d.ext_used.push_back(e.c_str());
    for (const auto &img : d.model.images) {
        d.image_uris.push_back(img.uri.c_str());
        lmb_gltf_image g{img.uri.c_str(), img.mimeType.c_str(), nullptr, 0};
        if (!img.image.empty()) {
            g.bytes = img.image.data();
            g.size = img.image.size();
        } else if (img.bufferView >= 0 && (size_t)img.bufferView < d.model.bufferViews.size()) {
            const auto &v = d.model.bufferViews[(size_t)img.bufferView];
            if (v.buffer >= 0 && (size_t)v.buffer < d.model.buffers.size() &&
                v.byteOffset + v.byteLength <= d.model.buffers[(size_t)v.buffer].data.size()) {
                g.bytes = d.model.buffers[(size_t)v.buffer].data.data() + v.byteOffset;
                g.size = v.byteLength;
            }
        }
        d.images.push_back(g);
    }
    fill_textures(d);
    lmb_gltf_view &v = d.view;
    expose(d.buffers, v.buffers, v.buffer_count);
    expose(d.buffer_views, v.buffer_views, v.buffer_view_count);
    expose(d.accessors, v.accessors, v.accessor_count);
    expose(d.meshes, v.meshes, v.mesh_count);
    expose(d.primitives, v.primitives, v.primitive_count);
    expose(d.nodes, v.nodes, v.node_count);
    expose(d.children, v.children, v.children_total);
    expose(d.materials, v.materials, v.material_count);
    expose(d.lights, v.lights, v.light_count);
    expose(d.scene_roots, v.scene_roots, v.scene_root_count);
    expose(d.ext_required, v.extensions_required, v.extensions_required_count);
    expose(d.ext_used, v.extensions_used, v.extensions_used_count);
    expose(d.image_uris, v.image_uris, v.image_count);
    v.images = d.images.empty() ? nullptr : d.images.data();
    expose(d.textures, v.textures, v.texture_count);
}

/* tinygltf's messages end in newlines and may hold several lines: keep the first one. */
std::string first_line(const std::string &s)
{
    size_t start = s.find_first_not_of(" \n\r\t");
    if (start == std::string::npos)
        return "unknown error";
    size_t end = s.find('\n', start);
    return s.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

bool is_glb(const char *path)
{
    unsigned char magic[4] = {0, 0, 0, 0};
    FILE *f = std::fopen(path, "rb");
    if (!f)
        return false;
    size_t n = std::fread(magic, 1, 4, f);
    std::fclose(f);
    return n == 4 && std::memcmp(magic, "glTF", 4) == 0;
}

} // namespace

/* Parses path, or the .glb bytes given for it (load/decompress.h), with tinygltf. */
static lmb_status open_doc(const char *path, const uint8_t *glb, size_t size, const char *extras_key,
                           lmb_gltf_doc **out, const lmb_log *log, lmb_error *err)
{
    *out = nullptr;
    FILE *probe = std::fopen(path, "rb");
    if (!probe)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: cannot open: %s", path, std::strerror(errno));
    std::fclose(probe);
    try {
        std::unique_ptr<lmb_gltf_doc> d(new lmb_gltf_doc());
        d->extras_key = extras_key ? extras_key : "";
        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(skip_image, nullptr);
        const char *slash = std::strrchr(path, '/');
        confined_fs fs_root{slash ? std::string(path, (size_t)(slash - path)) : std::string(".")};
        if (fs_root.folder.empty())
            fs_root.folder = "/";
        loader.SetFsCallbacks(tinygltf::FsCallbacks{confined_exists, no_expansion, confined_read, no_write, &fs_root});
        std::string terr, twarn;
        bool ok = glb    ? loader.LoadBinaryFromMemory(&d->model, &terr, &twarn, glb, (unsigned int)size, fs_root.folder)
                  : is_glb(path) ? loader.LoadBinaryFromFile(&d->model, &terr, &twarn, path)
                                 : loader.LoadASCIIFromFile(&d->model, &terr, &twarn, path);
        if (!ok)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: not a loadable glTF: %s", path,
                                 first_line(terr.empty() ? twarn : terr).c_str());
        if (!twarn.empty())
            lmb_warn(log, "%s: %s", path, first_line(twarn).c_str());
        build_view(*d);
        *out = d.release();
        return LMB_OK;
    } catch (const std::bad_alloc &) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory while parsing", path);
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: glTF parser failed: %s", path, e.what());
    }
}

extern "C" lmb_status lmb_gltf_open(const char *path, const char *extras_key, lmb_gltf_doc **out,
                                    const lmb_log *log, lmb_error *err)
{
    return open_doc(path, nullptr, 0, extras_key, out, log, err);
}

extern "C" lmb_status lmb_gltf_open_glb(const char *path, const uint8_t *glb, size_t size, const char *extras_key,
                                        lmb_gltf_doc **out, const lmb_log *log, lmb_error *err)
{
    return open_doc(path, glb, size, extras_key, out, log, err);
}

extern "C" const lmb_gltf_view *lmb_gltf_get_view(const lmb_gltf_doc *doc)
{
    return &doc->view;
}

extern "C" void lmb_gltf_close(lmb_gltf_doc *doc)
{
    delete doc;
}
