/*
 * The tinygltf adapter's document (C++ only): the parsed tinygltf model, kept alive for the
 * writer, and the plain C view of it. Shared by gltf_adapter.cpp (read) and
 * ../write/gltf_write.cpp (write); never included from C.
 */
#ifndef LMBAKE_GLTF_DOC_HPP
#define LMBAKE_GLTF_DOC_HPP

#include "gltf_adapter.h"

#include <tiny_gltf.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

struct lmb_gltf_doc {
    tinygltf::Model model;
    std::string extras_key;
    std::vector<lmb_gltf_buffer> buffers;
    std::vector<lmb_gltf_buffer_view> buffer_views;
    std::vector<lmb_gltf_accessor> accessors;
    std::vector<lmb_gltf_mesh> meshes;
    std::vector<lmb_gltf_primitive> primitives;
    std::vector<lmb_gltf_node> nodes;
    std::vector<int32_t> children;
    std::vector<lmb_gltf_material> materials;
    std::vector<lmb_gltf_light> lights;
    std::vector<int32_t> scene_roots;
    std::vector<const char *> ext_required, ext_used, image_uris;
    std::vector<lmb_gltf_image> images;
    std::vector<lmb_gltf_texture> textures;
    lmb_gltf_view view;
    /* writer: (original material, lightmap texture) -> lightmapped material copy */
    std::map<std::string, int> lightmap_materials; /* (material, texture, rectangle) -> lightmapped copy */
    /* writer: meshes a node used before it got its lightmapped copy (gltf_prune.cpp drops the
     * ones no node uses any more) */
    std::vector<int> replaced_meshes;
    /* light probes to add at saving, after the pruning that renumbers accessors and views
       (lmb_gltf_set_probes) */
    std::vector<float> probe_positions, probe_sh, probe_cube;
    struct probe_group {
        std::string name;
        double scale, intensity[3]; /* what the group's own probes are multiplied by, with scale */
        std::vector<float> sh, cube;
    };
    std::vector<probe_group> probe_groups; /* light groups: each group's own probes' light */
    std::vector<uint32_t> probe_tetrahedra; /* 4 per tetrahedron */
    double probe_spacing = 0;
    int probe_radiance = 0;
    struct volume {
        std::string uri;
        double lo[3], hi[3];
        uint32_t res[3], config_entry;
        std::string node_name; /* "" unless from a node's extras.lightmap_probes (then matrix places it) */
        double matrix[16];
        std::vector<std::string> group_uris; /* light groups: each group's own volume, in probe_groups' order */
    };
    std::vector<volume> volumes;
    /* writer: materials.default.albedo for primitives with no material, if given */
    bool has_default_albedo = false;
    double default_albedo[3] = {0, 0, 0};
};

#endif
