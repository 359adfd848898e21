/*
 * The tinygltf adapter (C header over C++): parses a .gltf/.glb with tinygltf and exposes
 * what lmbake reads as plain C structs that mirror the glTF JSON. It decodes nothing and
 * validates only what tinygltf does: accessor decoding, bounds checks, the node graph and
 * every lmbake-specific rule live in C (scene_load.c, accessor.c).
 * The same handle later takes the lightmap additions and writes the output glTF.
 */
#ifndef LMBAKE_GLTF_ADAPTER_H
#define LMBAKE_GLTF_ADAPTER_H

#include <lmbake/lmbake.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lmb_gltf_buffer {
    const uint8_t *data; /* owned by the doc */
    size_t size;
} lmb_gltf_buffer;

typedef struct lmb_gltf_buffer_view {
    int32_t buffer;
    size_t offset, length, stride; /* stride 0: tightly packed */
} lmb_gltf_buffer_view;

typedef struct lmb_gltf_accessor {
    const char *name;
    int32_t buffer_view; /* -1: all zeros (or sparse only) */
    size_t offset;
    int32_t component_type; /* 5120..5126 (GL enums) */
    int32_t components;     /* 1,2,3,4,9,16 from the type, 0 if unknown */
    size_t count;
    int normalized;
    /* sparse substitution, count 0 if not sparse */
    size_t sparse_count;
    int32_t sparse_indices_view, sparse_indices_type;
    size_t sparse_indices_offset;
    int32_t sparse_values_view;
    size_t sparse_values_offset;
} lmb_gltf_accessor;

typedef struct lmb_gltf_primitive {
    int32_t mode;     /* 0..6, glTF default 4 */
    int32_t material; /* -1: default */
    int32_t indices;  /* accessor or -1 */
    int32_t position, normal, texcoord0, texcoord1; /* accessors or -1 */
    int32_t color0;   /* COLOR_0 accessor or -1 */
    int32_t any_attribute; /* the first attribute's accessor, -1 if none (for counting) */
} lmb_gltf_primitive;

typedef struct lmb_gltf_mesh {
    const char *name; /* "" if unnamed */
    uint32_t first_primitive, primitive_count; /* into lmb_gltf_view.primitives */
} lmb_gltf_mesh;

typedef struct lmb_gltf_node {
    const char *name;
    int32_t mesh, light; /* -1 if none */
    uint32_t first_child, child_count; /* into lmb_gltf_view.children */
    int has_matrix;
    double matrix[16];   /* column-major, when has_matrix */
    double translation[3], rotation[4], scale[3]; /* TRS, defaults filled in */
    int extras_lightmap; /* -1 absent, 0/1: the bool under the requested extras key */
    int32_t gpu_translation, gpu_rotation, gpu_scale; /* EXT_mesh_gpu_instancing accessors, -1 */
    int has_gpu_instancing;
    const char *lightmap_mode; /* extras.lightmap_mode as written ("" absent, "?" not a string): the mode of its light */
    const char *lightmap_group; /* extras.lightmap_group as written ("" absent, "?" not a string): its light's group */
    int32_t lightmap_probes[3]; /* extras.lightmap_probes: a volume's resolution; 0 0 0 absent, -1 -1 -1 malformed */
    int skinned;      /* node.skin is set */
    int morphing;     /* its mesh has morph targets */
    int32_t lod_of;   /* a lower level of detail (MSFT_lod) of this node, or -1 */
} lmb_gltf_node;

/* A glTF textureInfo with its KHR_texture_transform, as written (defaults filled in). */
typedef struct lmb_gltf_texture_info {
    int32_t index;    /* texture, -1: none */
    int32_t texcoord; /* textureInfo.texCoord */
    int has_transform;
    double offset[2], rotation, scale[2]; /* KHR_texture_transform (0, 0), 0, (1, 1) by default */
    int32_t transform_texcoord;           /* its texCoord override, -1 if not given */
} lmb_gltf_texture_info;

typedef struct lmb_gltf_material {
    const char *name;
    double base_color[4];
    lmb_gltf_texture_info base_color_texture;
    double metallic;
    lmb_gltf_texture_info metallic_roughness_texture;
    double emissive[3];
    double emissive_strength; /* 1 if KHR_materials_emissive_strength is absent */
    lmb_gltf_texture_info emissive_texture;
    int double_sided;
    /* KHR_materials_pbrSpecularGlossiness (when spec_gloss): defaults 1, 1, 1 */
    int spec_gloss;
    double diffuse[4], specular[3], glossiness;
    lmb_gltf_texture_info diffuse_texture, specular_glossiness_texture;
    int unlit; /* KHR_materials_unlit */
    /* alphaMode as written: 0 OPAQUE (also when absent), 1 MASK, 2 BLEND, -1 anything else;
     * alphaCutoff 0.5 when absent (preflight checks the JSON value is a number in [0, 1]) */
    int alpha_mode;
    double alpha_cutoff;
    /* KHR_materials_transmission (has_transmission: present): factor 0 and texture (red) */
    int has_transmission;
    double transmission;
    lmb_gltf_texture_info transmission_texture;
    /* KHR_materials_volume (has_volume: present): thicknessFactor, attenuationDistance
     * (INFINITY when absent) and attenuationColor */
    int has_volume;
    double thickness, attenuation_distance, attenuation_color[3];
    /* KHR_materials_diffuse_transmission: factor 0 and colour 1 1 1 by default */
    double diffuse_transmission, diffuse_transmission_color[3];
    int diffuse_transmission_textures; /* its textures given (diffuseTransmissionTexture, ...ColorTexture) */
} lmb_gltf_material;

/* A glTF texture and its sampler (glTF defaults when it has none). */
typedef struct lmb_gltf_texture {
    int32_t source;           /* image, -1: none */
    int32_t sampler;          /* -1: none */
    int32_t wrap_s, wrap_t;   /* 10497 REPEAT, 33648 MIRRORED_REPEAT, 33071 CLAMP_TO_EDGE (or anything written) */
    int32_t mag_filter;       /* 9728 NEAREST, 9729 LINEAR, -1 not given */
} lmb_gltf_texture;

typedef struct lmb_gltf_light {
    const char *name;
    const char *type; /* as written: "point", "spot", "directional" or anything else */
    double color[3];
    double intensity, range;
    double inner_cone, outer_cone;
    const char *lightmap_mode; /* extras.lightmap_mode as written ("" absent, "?" not a string) */
    const char *lightmap_group; /* extras.lightmap_group as written ("" absent, "?" not a string) */
} lmb_gltf_light;

typedef struct lmb_gltf_image {
    const char *uri;      /* external file relative to the glTF, or "" */
    const char *mime;     /* "" if not given */
    const uint8_t *bytes; /* encoded bytes when embedded (buffer view or data URI), else NULL */
    size_t size;
} lmb_gltf_image;

/* Everything lmbake reads, as plain arrays. All pointers are owned by the doc. */
/* The scene's EXT_lights_image_based light, if it names one (its irradiance as spherical
 * harmonics; the specular cube maps are not read). */
typedef struct lmb_gltf_ibl {
    int present;          /* the baked scene names a light of the extension */
    int32_t index;        /* which one */
    char name[128];       /* its name, or "light N" */
    float intensity;      /* default 1 */
    float rotation[4];    /* quaternion x, y, z, w; default identity */
    float sh[9][3];       /* irradianceCoefficients, bands l = 0..2 in the order (0,0) (1,-1) (1,0) (1,1) (2,-2) .. (2,2) */
    int usable;           /* 0: the index or irradianceCoefficients is malformed (problem says why) */
    char problem[160];
} lmb_gltf_ibl;

typedef struct lmb_gltf_view {
    const lmb_gltf_buffer *buffers;             uint32_t buffer_count;
    const lmb_gltf_buffer_view *buffer_views;   uint32_t buffer_view_count;
    const lmb_gltf_accessor *accessors;         uint32_t accessor_count;
    const lmb_gltf_mesh *meshes;                uint32_t mesh_count;
    const lmb_gltf_primitive *primitives;       uint32_t primitive_count;
    const lmb_gltf_node *nodes;                 uint32_t node_count;
    const int32_t *children;                    uint32_t children_total;
    const lmb_gltf_material *materials;         uint32_t material_count;
    const lmb_gltf_light *lights;               uint32_t light_count;
    const int32_t *scene_roots;                 uint32_t scene_root_count; /* the scene to bake */
    int has_scene; /* 0: the file has no scene; roots are the parentless nodes */
    const char *const *extensions_required;     uint32_t extensions_required_count;
    const char *const *extensions_used;         uint32_t extensions_used_count;
    const char *const *image_uris;              uint32_t image_count; /* "" when in a buffer view */
    const lmb_gltf_image *images;               /* image_count of them */
    const lmb_gltf_texture *textures;           uint32_t texture_count;
    lmb_gltf_ibl ibl;
} lmb_gltf_view;

/* Parses path (.gltf or .glb by content). `extras_key` names the node extras bool read
 * into lmb_gltf_node.extras_lightmap (NULL: none). Images are not decoded. */
lmb_status lmb_gltf_open(const char *path, const char *extras_key, lmb_gltf_doc **out,
                         const lmb_log *log, lmb_error *err);

/* The same from .glb bytes that stand for path (its decompressed form: load/decompress.h);
 * external files resolve against path's folder. */
lmb_status lmb_gltf_open_glb(const char *path, const uint8_t *glb, size_t size, const char *extras_key,
                             lmb_gltf_doc **out, const lmb_log *log, lmb_error *err);

const lmb_gltf_view *lmb_gltf_get_view(const lmb_gltf_doc *doc);

void lmb_gltf_close(lmb_gltf_doc *doc);

#ifdef __cplusplus
}
#endif

#endif
