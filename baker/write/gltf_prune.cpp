/*
 * Drops the meshes a bake replaced and left unused, and the accessors and buffer views only
 * they used (see gltf_prune.hpp). Walks every reference glTF 2.0 defines to meshes, accessors
 * and buffer views (nodes, primitives and morph targets, skins, animations, sparse accessors,
 * images) and EXT_mesh_gpu_instancing's accessors.
 */
#include "gltf_prune.hpp"

#include <set>
#include <string>
#include <vector>

namespace {

/* Extensions whose references to meshes, accessors and buffer views are known here, or that
 * make none. */
bool extension_known(const std::string &name)
{
    static const char *known[] = {"KHR_lights_punctual", "KHR_texture_transform", "KHR_materials_emissive_strength",
                                  "KHR_materials_pbrSpecularGlossiness", "KHR_materials_unlit", "KHR_materials_ior",
                                  "KHR_materials_specular", "KHR_materials_transmission", "KHR_materials_volume",
                                  "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_iridescence",
                                  "KHR_materials_anisotropy", "KHR_mesh_quantization", "KHR_texture_basisu",
                                  "EXT_texture_webp", "EXT_mesh_gpu_instancing", "MOZ_lightmap", "MOZ_texture_rgbe"};
    for (const char *k : known)
        if (name == k)
            return true;
    return false;
}

/* old index -> new index (-1: removed) for `count` objects of which `keep` are kept. */
std::vector<int> renumber(size_t count, const std::vector<bool> &keep)
{
    std::vector<int> map(count, -1);
    int next = 0;
    for (size_t i = 0; i < count; i++)
        if (keep[i])
            map[i] = next++;
    return map;
}

int remap(int index, const std::vector<int> &map)
{
    return index >= 0 && (size_t)index < map.size() ? map[(size_t)index] : index;
}

/* The accessors named by a node's EXT_mesh_gpu_instancing, or NULL. */
tinygltf::Value *instancing_attributes(tinygltf::Node &n)
{
    auto ext = n.extensions.find("EXT_mesh_gpu_instancing");
    if (ext == n.extensions.end() || !ext->second.IsObject())
        return nullptr;
    auto &obj = ext->second.Get<tinygltf::Value::Object>();
    auto attrs = obj.find("attributes");
    return attrs != obj.end() && attrs->second.IsObject() ? &attrs->second : nullptr;
}

/* Calls f(accessor index reference) for every accessor reference outside meshes. */
template <typename F> void other_accessor_refs(tinygltf::Model &m, F f)
{
    for (auto &skin : m.skins)
        f(skin.inverseBindMatrices);
    for (auto &anim : m.animations)
        for (auto &s : anim.samplers) {
            f(s.input);
            f(s.output);
        }
    for (auto &n : m.nodes) {
        tinygltf::Value *attrs = instancing_attributes(n);
        if (!attrs)
            continue;
        tinygltf::Value::Object obj = attrs->Get<tinygltf::Value::Object>();
        for (auto &kv : obj)
            if (kv.second.IsInt()) {
                int a = kv.second.Get<int>();
                f(a);
                kv.second = tinygltf::Value(a);
            }
        *attrs = tinygltf::Value(obj);
    }
}

template <typename F> void mesh_accessor_refs(tinygltf::Mesh &mesh, F f)
{
    for (auto &p : mesh.primitives) {
        for (auto &kv : p.attributes)
            f(kv.second);
        f(p.indices);
        for (auto &target : p.targets)
            for (auto &kv : target)
                f(kv.second);
    }
}

} // namespace

int lmb_gltf_prune_replaced(lmb_gltf_doc *doc)
{
    tinygltf::Model &m = doc->model;
    for (const auto &e : m.extensionsUsed)
        if (!extension_known(e))
            return 0;
    std::vector<bool> mesh_used(m.meshes.size(), false);
    for (const auto &n : m.nodes)
        if (n.mesh >= 0 && (size_t)n.mesh < m.meshes.size())
            mesh_used[(size_t)n.mesh] = true;
    std::vector<bool> keep_mesh(m.meshes.size(), true);
    int removed = 0;
    for (int r : doc->replaced_meshes)
        if (r >= 0 && (size_t)r < m.meshes.size() && !mesh_used[(size_t)r] && keep_mesh[(size_t)r]) {
            keep_mesh[(size_t)r] = false;
            removed++;
        }
    if (!removed)
        return 0;

    /* accessors: used by a kept mesh or anything else stays; used only by removed meshes goes */
    std::vector<bool> acc_used(m.accessors.size(), false), acc_dropped(m.accessors.size(), false);
    auto mark = [&](std::vector<bool> &v) {
        return [&v](int &a) {
            if (a >= 0 && (size_t)a < v.size())
                v[(size_t)a] = true;
        };
    };
    for (size_t i = 0; i < m.meshes.size(); i++)
        mesh_accessor_refs(m.meshes[i], mark(keep_mesh[i] ? acc_used : acc_dropped));
    other_accessor_refs(m, mark(acc_used));
    std::vector<bool> keep_acc(m.accessors.size());
    for (size_t i = 0; i < m.accessors.size(); i++)
        keep_acc[i] = acc_used[i] || !acc_dropped[i];

    /* buffer views: the same rule over accessors (dense and sparse) and images */
    std::vector<bool> view_used(m.bufferViews.size(), false), view_dropped(m.bufferViews.size(), false);
    auto view_mark = [&](std::vector<bool> &v, int b) {
        if (b >= 0 && (size_t)b < v.size())
            v[(size_t)b] = true;
    };
    for (size_t i = 0; i < m.accessors.size(); i++) {
        auto &v = keep_acc[i] ? view_used : view_dropped;
        view_mark(v, m.accessors[i].bufferView);
        if (m.accessors[i].sparse.isSparse) {
            view_mark(v, m.accessors[i].sparse.indices.bufferView);
            view_mark(v, m.accessors[i].sparse.values.bufferView);
        }
    }
    for (const auto &img : m.images)
        view_mark(view_used, img.bufferView);
    std::vector<bool> keep_view(m.bufferViews.size());
    for (size_t i = 0; i < m.bufferViews.size(); i++)
        keep_view[i] = view_used[i] || !view_dropped[i];

    std::vector<int> mesh_map = renumber(m.meshes.size(), keep_mesh);
    std::vector<int> acc_map = renumber(m.accessors.size(), keep_acc);
    std::vector<int> view_map = renumber(m.bufferViews.size(), keep_view);
    auto fix_acc = [&](int &a) { a = remap(a, acc_map); };
    for (auto &n : m.nodes)
        n.mesh = remap(n.mesh, mesh_map);
    for (auto &mesh : m.meshes)
        mesh_accessor_refs(mesh, fix_acc);
    other_accessor_refs(m, fix_acc);
    for (auto &a : m.accessors) {
        a.bufferView = remap(a.bufferView, view_map);
        if (a.sparse.isSparse) {
            a.sparse.indices.bufferView = remap(a.sparse.indices.bufferView, view_map);
            a.sparse.values.bufferView = remap(a.sparse.values.bufferView, view_map);
        }
    }
    for (auto &img : m.images)
        img.bufferView = remap(img.bufferView, view_map);

    std::vector<tinygltf::Mesh> meshes;
    std::vector<tinygltf::Accessor> accessors;
    std::vector<tinygltf::BufferView> views;
    for (size_t i = 0; i < m.meshes.size(); i++)
        if (keep_mesh[i])
            meshes.push_back(std::move(m.meshes[i]));
    for (size_t i = 0; i < m.accessors.size(); i++)
        if (keep_acc[i])
            accessors.push_back(std::move(m.accessors[i]));
    for (size_t i = 0; i < m.bufferViews.size(); i++)
        if (keep_view[i])
            views.push_back(std::move(m.bufferViews[i]));
    m.meshes = std::move(meshes);
    m.accessors = std::move(accessors);
    m.bufferViews = std::move(views);
    doc->replaced_meshes.clear();
    return removed;
}
