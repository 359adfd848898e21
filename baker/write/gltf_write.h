/*
 * Writing the baked glTF through the tinygltf adapter (C header over C++). Each
 * lightmapped node gets its own copy of its mesh whose triangle primitives carry
 * TEXCOORD_1 (vertices split where charts meet) and materials that reference the atlas
 * through MOZ_lightmap {index, texCoord: 1, intensity}; the texture's source is a PNG and
 * its MOZ_texture_rgbe source the Radiance .hdr (the convention three.js-based viewers
 * such as Mozilla Hubs read). intensity is pi when the files hold E / pi (output.scale
 * radiance), so texel x intensity is irradiance either way. Every file of an atlas is named
 * in its texture's extras.lightmap and every lightmapped node's (docs/output.md). Everything
 * else in the file is kept as it was.
 */
#ifndef LMBAKE_GLTF_WRITE_H
#define LMBAKE_GLTF_WRITE_H

#include <lmbake/lmbake.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lmb_gltf_prim_out {
    uint32_t gltf_primitive; /* index among the glTF mesh's primitives */
    uint32_t vertex_count;   /* new vertices */
    const uint32_t *source;  /* per new vertex: its vertex in the original primitive */
    const float *positions;  /* 3 per new vertex */
    const float *normals;    /* 3 per new vertex, or NULL */
    const float *uv0;        /* 2 per new vertex, or NULL */
    const float *uv1;        /* 2 per new vertex, normalized to the atlas ([0,1], glTF's top-left origin) */
    uint32_t triangle_count;
    const uint32_t *indices; /* 3 per triangle, into the new vertices */
} lmb_gltf_prim_out;

/* One atlas's lightmap files (URIs relative to the glTF; NULL: not written) and what they hold. */
typedef struct lmb_gltf_lightmap_files {
    uint32_t atlas, width, height;
    int radiance;             /* output.scale radiance: texels hold E / pi (else E, lux) */
    const char *png, *hdr;    /* always: the texture's source and its MOZ_texture_rgbe source */
    const char *exr, *ktx2, *rgbm;
    double rgbm_range;        /* rgbm: its range (write/rgbm.h) */
    uint32_t ktx2_vkformat;   /* ktx2: its vkFormat */
    const char *direction_png, *direction_exr, *direction_ktx2; /* output.directional */
    const char *shadowmask;   /* output.shadowmask: the RGBA8 PNG */
    uint32_t groups;          /* output.light_groups: each group's name, scale, intensity and files */
    const char *group_name[LMB_MAX_LIGHT_GROUPS], *group_exr[LMB_MAX_LIGHT_GROUPS], *group_hdr[LMB_MAX_LIGHT_GROUPS],
        *group_ktx2[LMB_MAX_LIGHT_GROUPS]; /* group_ktx2[g] NULL: no KTX2 (output.formats) */
    double group_scale[LMB_MAX_LIGHT_GROUPS];
    double group_intensity[LMB_MAX_LIGHT_GROUPS][3]; /* RGB: a group of one source's intensity x colour (its
                                                        files hold it at 1), else 1 1 1 */
} lmb_gltf_lightmap_files;

/* Adds the texture of one atlas: source files->png, MOZ_texture_rgbe files->hdr, and
 * extras.lightmap {atlas, width, height, scale, files {format: uri}, rgbm {range, decode},
 * ktx2 {vkFormat}, groups [{name, scale, intensity [r, g, b], files {exr, hdr}}] (light groups:
 * the texture's files hold sum_g scale_g x intensity_g x group g's)}, so an engine script finds every file without guessing names. Returns its
 * index, or -1 on failure. */
int32_t lmb_gltf_add_lightmap_texture(lmb_gltf_doc *doc, const lmb_gltf_lightmap_files *files, lmb_error *err);

/* Adds a texture for one atlas's directions (png_uri: the -dir.png). Returns its index, or -1. */
int32_t lmb_gltf_add_direction_texture(lmb_gltf_doc *doc, const char *png_uri, lmb_error *err);

/* Gives node `node` a copy of its mesh with the primitives in prims replaced (others kept)
 * and lightmapped materials using `texture`; with direction_texture >= 0 the materials name
 * it in extras.lightmap_directional {index, texCoord: 1, encoding, decode} (docs/artists.md;
 * the material's other extras are kept). scale_offset (sx, sy, ox, oy) places the node's
 * TEXCOORD_1 in the atlas: uv_atlas = uv * (sx, sy) + (ox, oy); not (1, 1, 0, 0) (a mesh that
 * kept its own TEXCOORD_1 as a rectangle of a shared atlas) its materials' MOZ_lightmap carry
 * it as KHR_texture_transform. The node gets extras.lightmap {atlas, texCoord, scaleOffset,
 * scale, files} (its other extras are kept; a boolean extras.lightmap flag is replaced). */
lmb_status lmb_gltf_lightmap_node(lmb_gltf_doc *doc, uint32_t node, const lmb_gltf_prim_out *prims, uint32_t count,
                                  int32_t texture, int32_t direction_texture, const double scale_offset[4],
                                  lmb_error *err);

/* atlas.share_meshes: the first node of a mesh that several nodes share gets the lightmapped copy
 * of the mesh (its TEXCOORD_1 the layout they share; no KHR_texture_transform in its materials,
 * which every node shares), and its rectangle in its extras.lightmap.scaleOffset; the other
 * nodes then point at that mesh with lmb_gltf_share_lightmapped_mesh, each with its rectangle. */
lmb_status lmb_gltf_lightmap_shared_mesh(lmb_gltf_doc *doc, uint32_t node, const lmb_gltf_prim_out *prims,
                                         uint32_t count, int32_t texture, int32_t direction_texture,
                                         const double scale_offset[4], lmb_error *err);
lmb_status lmb_gltf_share_lightmapped_mesh(lmb_gltf_doc *doc, uint32_t node, uint32_t from_node, int32_t texture,
                                           const double scale_offset[4], lmb_error *err);

/* An EXT_mesh_gpu_instancing node: as lmb_gltf_lightmap_node (its mesh's TEXCOORD_1 is the layout
 * every copy shares; no KHR_texture_transform), and each copy's rectangle as per-instance
 * attributes _LIGHTMAP_SCALE (VEC2 sx, sy) and _LIGHTMAP_OFFSET (VEC2 ox, oy) of the extension,
 * the convention of Third Room's MX_lightmap (the extension allows custom attributes that start
 * with '_'): uv_atlas = uv * scale + offset. scale_offsets: 4 per copy, in the extension's order
 * (a copy without a lightmap: 0, 0, 0, 0). The node's extras.lightmap names the attributes. */
lmb_status lmb_gltf_lightmap_instanced_node(lmb_gltf_doc *doc, uint32_t node, const lmb_gltf_prim_out *prims,
                                            uint32_t count, int32_t texture, int32_t direction_texture,
                                            const float *scale_offsets, uint32_t copies, lmb_error *err);

/* Mixed lighting: each KHR_lights_punctual light that lights (its first node's) gets
 * extras.lightmap {mode, shadowmaskChannel ("R".."A", when it has one)}, so an engine knows
 * which lights to draw in real time; and with a shadowmask, every lightmap texture's
 * extras.lightmap.shadowmask names {channel: light name}. Nothing is written when every
 * light is `baked`. */
lmb_status lmb_gltf_set_light_modes(lmb_gltf_doc *doc, const lmb_light *lights, uint32_t count, lmb_error *err);

/* Names the irradiance cache's records file in asset.extras.lmbake.irradianceCacheRecords:
 * {"uri": uri, "count": count, "layout": "float32le x y z reach"} (write/records_file.h);
 * the asset's other extras are kept. */
lmb_status lmb_gltf_set_records(lmb_gltf_doc *doc, const char *uri, uint32_t count, lmb_error *err);

/* Light probes (probes/probes.h) as the output holds them: values already in the lightmaps'
 * scale (E, or E / pi with radiance). */
typedef struct lmb_gltf_probes {
    uint32_t count;
    const float *positions; /* 3 per probe, world */
    const float *sh;        /* 27 per probe: SH L2 irradiance, coefficient-major RGB */
    const float *cube;      /* 18 per probe: irradiance for +X, -X, +Y, -Y, +Z, -Z, RGB */
    const uint32_t *tetrahedra; /* 4 probe indices per tetrahedron (Delaunay), positive volume */
    uint32_t tetrahedron_count;
    double spacing;         /* the grid's cell */
    int radiance;           /* output.scale radiance */
    uint32_t volume_count;  /* the grids as bevy's irradiance volumes (KTX2) */
    const struct lmb_gltf_volume *volumes;
    uint32_t groups;        /* light groups: each group's own SH and ambient cubes (sh and cube: their sum) */
    const char *group_name[LMB_MAX_LIGHT_GROUPS];
    double group_scale[LMB_MAX_LIGHT_GROUPS], group_intensity[LMB_MAX_LIGHT_GROUPS][3];
    const float *group_sh[LMB_MAX_LIGHT_GROUPS], *group_cube[LMB_MAX_LIGHT_GROUPS];
} lmb_gltf_probes;

typedef struct lmb_gltf_volume {
    const char *uri;
    double lo[3], hi[3];
    uint32_t res[3];
    uint32_t config_entry; /* 0: the auto grid; k: probes.volumes entry k */
    const char *node_name; /* a node's extras.lightmap_probes: its name (NULL otherwise); matrix places
                              the unit cube (lo, hi unused) */
    double matrix[16];
    const char *group_uri[LMB_MAX_LIGHT_GROUPS]; /* light groups: group g's own volume (lmb_gltf_probes.groups) */
} lmb_gltf_volume;

/* Adds the probes to the new buffer (positions as a VEC3 accessor, the SH and the ambient cubes
 * as buffer views of float32, the tetrahedra as a SCALAR uint32 accessor) and names them in
 * asset.extras.lightmap.probes {count, positions, sh, ambientCube, tetrahedra, shBasis, scale,
 * unit, spacing, groups [{name, scale, intensity, sh, ambientCube}] (light groups)} (docs/probes.md); the asset's other extras
 * are kept. Per volume a node "lightmap irradiance volume" (or "... K" for probes.volumes entry
 * K) in the default scene whose transform takes a unit cube centred on the origin to the
 * volume's box (bevy's IrradianceVolume), with extras.lightmap.irradianceVolume {uri,
 * resolution, layout, scale, unit, configEntry, groups [{name, scale, intensity, uri}] (light
 * groups: each group's own volume)}. Nothing when count is 0. Added when the
 * document is saved. */
lmb_status lmb_gltf_set_probes(lmb_gltf_doc *doc, const lmb_gltf_probes *p, lmb_error *err);

/* Lightmapped primitives with no material get a material of this diffuse albedo (metallic 0:
 * materials.default.albedo, so the level looks as it was baked) instead of glTF's default. */
void lmb_gltf_set_default_albedo(lmb_gltf_doc *doc, const double albedo[3]);

/* Writes the document as path (.gltf) with its new data in `bin_name` beside it. Buffers of
 * the input are written beside it too; images keep their URIs (the caller copies files). */
lmb_status lmb_gltf_save(lmb_gltf_doc *doc, const char *path, const char *bin_name, lmb_error *err);

#ifdef __cplusplus
}
#endif

#endif
