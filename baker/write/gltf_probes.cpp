/*
 * Light probes into the output glTF (see gltf_write.h's lmb_gltf_set_probes; docs/probes.md):
 * positions, SH, ambient cubes and tetrahedra in the new buffer, named in
 * asset.extras.lightmap.probes; each grid as a node for bevy's IrradianceVolume. Part of the
 * tinygltf adapter.
 */
#include "gltf_write.h"

#include "../load/gltf_doc.hpp"
#include "gltf_buffers.hpp"

#include <string>

using tinygltf::Value;
using namespace lmb_gltf_out;

namespace {

/* One irradiance volume as a node of the default scene (see lmb_gltf_set_probes). */
void add_volume_node(tinygltf::Model &m, const lmb_gltf_doc::volume &v, const lmb_gltf_doc &doc)
{
    int radiance = doc.probe_radiance;
    tinygltf::Node node;
    node.name = !v.node_name.empty() ? "lightmap irradiance volume of " + v.node_name
                : v.config_entry      ? "lightmap irradiance volume " + std::to_string(v.config_entry)
                                      : std::string("lightmap irradiance volume");
    if (!v.node_name.empty()) {
        node.matrix.assign(v.matrix, v.matrix + 16); /* the asking node's world transform */
    } else {
        for (int k = 0; k < 3; k++) {
            node.translation.push_back(0.5 * (v.lo[k] + v.hi[k]));
            node.scale.push_back(v.hi[k] - v.lo[k]);
        }
    }
    Value::Object volume;
    volume["uri"] = Value(v.uri);
    volume["resolution"] = Value(Value::Array{Value((int)v.res[0]), Value((int)v.res[1]), Value((int)v.res[2])});
    volume["layout"] = Value(std::string("bevy IrradianceVolume: a unit cube centred on the origin, placed by this node; "
                                         "KTX2 E5B9G9R9 of (Rx, 2Ry, 3Rz) texels, ambient cubes"));
    volume["scale"] = Value(std::string(radiance ? "radiance" : "irradiance"));
    volume["unit"] = Value(std::string(radiance ? "nits (E / pi)" : "lux (E)"));
    volume["configEntry"] = Value((int)v.config_entry);
    if (!v.group_uris.empty()) { /* each light group's own volume: a game blends them as the lightmaps */
        Value::Array groups;
        for (size_t g = 0; g < v.group_uris.size() && g < doc.probe_groups.size(); g++) {
            const auto &pg = doc.probe_groups[g];
            Value::Object o;
            o["name"] = Value(pg.name);
            o["scale"] = Value(pg.scale);
            o["intensity"] = Value(Value::Array{Value(pg.intensity[0]), Value(pg.intensity[1]), Value(pg.intensity[2])});
            o["uri"] = Value(v.group_uris[g]);
            groups.push_back(Value(o));
        }
        volume["groups"] = Value(groups);
    }
    if (!v.node_name.empty())
        volume["node"] = Value(v.node_name);
    Value::Object node_lightmap;
    node_lightmap["irradianceVolume"] = Value(volume);
    Value::Object node_extras;
    node_extras["lightmap"] = Value(node_lightmap);
    node.extras = Value(node_extras);
    m.nodes.push_back(node);
    int index = (int)m.nodes.size() - 1;
    if (m.scenes.empty()) {
        m.scenes.push_back(tinygltf::Scene());
        m.defaultScene = 0;
    }
    size_t scene = m.defaultScene >= 0 && (size_t)m.defaultScene < m.scenes.size() ? (size_t)m.defaultScene : 0;
    m.scenes[scene].nodes.push_back(index);
}

/* The probes lmb_gltf_set_probes kept: into the new buffer and asset.extras.lightmap.probes. */
}

void lmb_gltf_add_probes(lmb_gltf_doc *doc)
{
    uint32_t count = (uint32_t)(doc->probe_positions.size() / 3);
    if (!count)
        return;
    const float *xyz = doc->probe_positions.data(), *sh_values = doc->probe_sh.data(),
                *cube_values = doc->probe_cube.data();
    tinygltf::Model &m = doc->model;
    writer w{m, new_buffer(m)};
    Value::Object probes;
    probes["count"] = Value((int)count);
    int positions = add_float_accessor(w, xyz, count, 3, true);
    m.bufferViews[(size_t)m.accessors[(size_t)positions].bufferView].target = 0; /* points, not a vertex buffer */
    probes["positions"] = Value(positions);
    int sh = add_view(w, sh_values, sizeof(float) * 27 * (size_t)count, 0);
    int cube = add_view(w, cube_values, sizeof(float) * 18 * (size_t)count, 0);
    m.bufferViews[(size_t)sh].name = "lightmap probes SH L2";
    m.bufferViews[(size_t)cube].name = "lightmap probes ambient cube";
    probes["sh"] = Value(sh);
    probes["ambientCube"] = Value(cube);
    if (!doc->probe_groups.empty()) { /* light groups: sh and ambientCube hold sum_g scale_g x intensity_g x group g's */
        Value::Array groups;
        for (const auto &g : doc->probe_groups) {
            Value::Object one;
            int gsh = add_view(w, g.sh.data(), sizeof(float) * 27 * (size_t)count, 0);
            int gcube = add_view(w, g.cube.data(), sizeof(float) * 18 * (size_t)count, 0);
            m.bufferViews[(size_t)gsh].name = "lightmap probes SH L2, light group " + g.name;
            m.bufferViews[(size_t)gcube].name = "lightmap probes ambient cube, light group " + g.name;
            one["name"] = Value(g.name);
            one["scale"] = Value(g.scale);
            one["intensity"] = Value(Value::Array{Value(g.intensity[0]), Value(g.intensity[1]), Value(g.intensity[2])});
            one["sh"] = Value(gsh);
            one["ambientCube"] = Value(gcube);
            groups.push_back(Value(one));
        }
        probes["groups"] = Value(groups);
    }
    if (!doc->probe_tetrahedra.empty()) {
        tinygltf::Accessor a;
        a.bufferView = add_view(w, doc->probe_tetrahedra.data(), sizeof(uint32_t) * doc->probe_tetrahedra.size(), 0);
        m.bufferViews[(size_t)a.bufferView].name = "lightmap probes tetrahedra";
        a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        a.count = doc->probe_tetrahedra.size();
        a.type = TINYGLTF_TYPE_SCALAR;
        m.accessors.push_back(a);
        probes["tetrahedra"] = Value((int)m.accessors.size() - 1);
        probes["tetrahedraLayout"] = Value(std::string(
            "uint32 x 4 per tetrahedron: probe indices, the Delaunay tetrahedralization of the positions (qhull), "
            "each of positive volume ((p1 - p0) x (p2 - p0) . (p3 - p0) > 0); a point inside one takes its probes' "
            "values with its barycentric weights"));
    }
    probes["shBasis"] = Value(std::string(
        "float32 x 27 per probe, coefficient-major RGB: (l,m) = (0,0) (1,-1) (1,0) (1,1) (2,-2) (2,-1) (2,0) "
        "(2,1) (2,2), real SH Y00 = 0.282095, Y1m = 0.488603 (y, z, x), Y2-2 = 1.092548 xy, Y2-1 = 1.092548 yz, "
        "Y20 = 0.315392 (3z^2 - 1), Y21 = 1.092548 xz, Y22 = 0.546274 (x^2 - y^2), glTF axes; irradiance "
        "E(n) = sum_k sh[k] Y_k(n) (the radiance's coefficients times pi, 2pi/3, pi/4)"));
    probes["ambientCubeLayout"] = Value(std::string("float32 x 18 per probe: irradiance for normals +X, -X, +Y, -Y, "
                                                    "+Z, -Z, RGB each"));
    probes["scale"] = Value(std::string(doc->probe_radiance ? "radiance" : "irradiance"));
    probes["unit"] = Value(std::string(doc->probe_radiance ? "nits (E / pi)" : "lux (E)"));
    probes["spacing"] = Value(doc->probe_spacing);
    tinygltf::Asset &asset = m.asset;
    Value::Object extras = asset.extras.IsObject() ? asset.extras.Get<Value::Object>() : Value::Object();
    Value::Object lightmap = extras.count("lightmap") && extras["lightmap"].IsObject()
                                 ? extras["lightmap"].Get<Value::Object>() : Value::Object();
    lightmap["probes"] = Value(probes);
    extras["lightmap"] = Value(lightmap);
    asset.extras = Value(extras);
    for (const auto &v : doc->volumes)
        add_volume_node(m, v, *doc);
}



extern "C" lmb_status lmb_gltf_set_probes(lmb_gltf_doc *doc, const lmb_gltf_probes *p, lmb_error *err)
{
    try {
        doc->probe_positions.assign(p->positions, p->positions + 3 * (size_t)p->count);
        doc->probe_sh.assign(p->sh, p->sh + 27 * (size_t)p->count);
        doc->probe_cube.assign(p->cube, p->cube + 18 * (size_t)p->count);
        doc->probe_groups.clear();
        for (uint32_t g = 0; g < p->groups; g++)
            doc->probe_groups.push_back({p->group_name[g], p->group_scale[g],
                                         {p->group_intensity[g][0], p->group_intensity[g][1], p->group_intensity[g][2]},
                                         std::vector<float>(p->group_sh[g], p->group_sh[g] + 27 * (size_t)p->count),
                                         std::vector<float>(p->group_cube[g], p->group_cube[g] + 18 * (size_t)p->count)});
        doc->probe_tetrahedra.assign(p->tetrahedra, p->tetrahedra + 4 * (size_t)p->tetrahedron_count);
        doc->probe_spacing = p->spacing;
        doc->probe_radiance = p->radiance;
        doc->volumes.clear();
        for (uint32_t i = 0; i < p->volume_count; i++) {
            const lmb_gltf_volume &v = p->volumes[i];
            lmb_gltf_doc::volume d{v.uri, {v.lo[0], v.lo[1], v.lo[2]}, {v.hi[0], v.hi[1], v.hi[2]},
                                   {v.res[0], v.res[1], v.res[2]}, v.config_entry, v.node_name ? v.node_name : "", {0}, {}};
            std::copy(v.matrix, v.matrix + 16, d.matrix);
            for (uint32_t g = 0; g < p->groups && v.group_uri[g]; g++)
                d.group_uris.push_back(v.group_uri[g]);
            doc->volumes.push_back(d);
        }
        return LMB_OK;
    } catch (const std::exception &e) {
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: cannot keep the light probes: %s", e.what());
    }
}

