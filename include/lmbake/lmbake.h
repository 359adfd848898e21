/*
 * lmbake public C API: status codes, the scene model, the bake config, progress.
 *
 * lmbake is a library the `lmbake` CLI is a thin user of; an asset pipeline or an
 * engine tool links the same functions. Conventions (after cgltf and Embree):
 *   - plain structs for data, opaque handles where a C++ library sits behind;
 *   - every fallible function returns lmb_status and fills an lmb_error with a message
 *     that names the file and the thing (mesh, key, line);
 *   - the caller owns what it creates and frees it with the matching *_free function;
 *   - no global mutable state.
 */
#ifndef LMBAKE_LMBAKE_H
#define LMBAKE_LMBAKE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LMB_VERSION_STRING "0.1.0"

/* ---- status and errors ---------------------------------------------------- */

/* Values double as the CLI's exit codes (docs/cli.md). */
typedef enum lmb_status {
    LMB_OK = 0,
    LMB_ERR_USAGE = 1,    /* bad command line */
    LMB_ERR_INPUT = 2,    /* bad scene, config or other input file */
    LMB_ERR_INTERNAL = 3, /* out of memory, I/O failure, a bug */
    LMB_NOT_KEPT = 4      /* lmb_farm_run.relight_only: the bake would light, not relight (nothing written) */
} lmb_status;

typedef struct lmb_error {
    lmb_status status;
    char message[1024];
} lmb_error;

/* Sets err (if not NULL) and returns status; printf-style message. */
lmb_status lmb_error_set(lmb_error *err, lmb_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* ---- diagnostics: warnings go through a sink the caller chooses ----------- */

typedef void (*lmb_warn_fn)(void *user, const char *message);

typedef struct lmb_log {
    lmb_warn_fn warn; /* NULL: warnings are dropped */
    void *user;
    lmb_warn_fn info; /* plain report lines (what a stage did); NULL: dropped. Same user. */
} lmb_log;

void lmb_warn(const lmb_log *log, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* A report line (lmb_log.info). */
void lmb_info(const lmb_log *log, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* ---- progress (after xatlas's progress callback) -------------------------- */

/* Called from the thread that drives a stage, never concurrently. done <= total. */
typedef void (*lmb_progress_fn)(void *user, const char *stage, uint64_t done, uint64_t total);

/* ---- scene model ---------------------------------------------------------- */

typedef enum lmb_light_type {
    LMB_LIGHT_POINT = 0,
    LMB_LIGHT_SPOT = 1,
    LMB_LIGHT_DIRECTIONAL = 2
} lmb_light_type;

/* A triangle list built from one glTF primitive (strips and fans are converted). */
typedef struct lmb_primitive {
    uint32_t gltf_mesh;      /* index into the glTF's meshes */
    uint32_t gltf_primitive; /* index into that mesh's primitives */
    int32_t material;        /* index into lmb_scene.materials, -1: glTF default material */
    uint32_t vertex_count;
    float *positions; /* 3 * vertex_count, object space */
    float *normals;   /* 3 * vertex_count, or NULL (flat normals are used) */
    float *uv0;       /* 2 * vertex_count, or NULL */
    float *uv1;       /* 2 * vertex_count, or NULL (the glTF had no TEXCOORD_1) */
    float *colors;    /* 4 * vertex_count, COLOR_0 as linear RGBA (alpha 1 for RGB), or NULL */
    uint32_t triangle_count;
    uint32_t *indices;        /* 3 * triangle_count, counter-clockwise front faces */
    uint32_t degenerate_count; /* zero-area triangles (kept in indices, flagged below) */
    uint8_t *degenerate;       /* triangle_count flags: 1 = zero area, left out of lightmapping */
} lmb_primitive;

typedef struct lmb_mesh {
    char *name; /* glTF name or "mesh N" */
    uint32_t first_primitive; /* into lmb_scene.primitives */
    uint32_t primitive_count;
    uint32_t triangle_count;  /* over its primitives */
    uint32_t degenerate_count;
    uint32_t skipped_primitives; /* points/lines or no-POSITION primitives, left out with a warning */
    uint32_t skipped_triangles;  /* triangles the no-POSITION ones would have had (not in triangle_count) */
} lmb_mesh;

/* Why a placement is not static scenery (docs/input.md#what-moves-and-levels-of-detail): it is
 * neither lightmapped nor an occluder of baked light, and the light probes light it, unless its
 * node's extras flag (lightmap: true) makes it static. */
typedef enum lmb_motion {
    LMB_STATIC = 0,
    LMB_SKINNED = 1,   /* node.skin: drawn at poses the bake does not know */
    LMB_MORPHING = 2,  /* morph targets */
    LMB_LOWER_LOD = 3  /* a lower level of detail: MSFT_lod ids, or a NAME_LOD<n> (n >= 1) beside NAME_LOD0 */
} lmb_motion;

/* One placement of a mesh in the world: a node, or one EXT_mesh_gpu_instancing copy. */
typedef struct lmb_instance {
    char *name;            /* node name or "node N"; GPU copies get "#k" appended */
    uint32_t node;         /* glTF node index */
    int32_t gpu_instance;  /* -1, or the index within EXT_mesh_gpu_instancing */
    uint32_t mesh;         /* into lmb_scene.meshes */
    double world[16];      /* column-major object-to-world */
    int flips_winding;     /* det(world) < 0: triangles' winding is reversed in world space */
    int lightmapped;       /* decided by lmb_scene_select_lightmapped */
    char skip_reason[96];  /* why not lightmapped, "" if it is */
    int extras_lightmap;   /* node extras flag: -1 absent, 0 false, 1 true */
    lmb_motion motion;     /* what makes it not scenery (a skin, morph targets, a lower LOD), or LMB_STATIC */
    int occludes;          /* in the bake's ray-tracing scene (decided by lmb_scene_select_lightmapped) */
} lmb_instance;

/* A material's texture slot: which glTF texture, read through which TEXCOORD_n set, and the
 * KHR_texture_transform affine map applied to that set's UVs before the lookup. */
typedef struct lmb_texture_ref {
    int32_t texture;  /* glTF texture index, -1: none */
    int32_t texcoord; /* TEXCOORD_n (KHR_texture_transform's texCoord when it gives one) */
    double uv[6];     /* u' = uv[0] u + uv[1] v + uv[2], v' = uv[3] u + uv[4] v + uv[5]; identity without a transform */
} lmb_texture_ref;

/* What the baker reads of a glTF material. A KHR_materials_pbrSpecularGlossiness material is
 * mapped onto the same fields: base_color = diffuseFactor, base_color_texture = diffuseTexture,
 * metallic = 0, and its specular part in spec_gloss / specular / specular_texture. */
/* How a material's alpha covers its surface (glTF alphaMode). */
typedef enum lmb_alpha_mode {
    LMB_ALPHA_OPAQUE = 0, /* alpha ignored */
    LMB_ALPHA_MASK = 1,   /* absent where alpha < alpha_cutoff, opaque elsewhere */
    LMB_ALPHA_BLEND = 2   /* coverage: 1 - alpha of the light passes */
} lmb_alpha_mode;

typedef struct lmb_material {
    char *name;
    float base_color[4];                /* linear RGBA factor (spec-gloss: diffuseFactor) */
    lmb_texture_ref base_color_texture; /* sRGB (spec-gloss: diffuseTexture) */
    float metallic;                     /* metallicFactor (spec-gloss: 0) */
    lmb_texture_ref metallic_texture;   /* metallicRoughnessTexture: metalness in blue, linear */
    int spec_gloss;                     /* KHR_materials_pbrSpecularGlossiness */
    float specular[3];                  /* its specularFactor */
    lmb_texture_ref specular_texture;   /* its specularGlossinessTexture: specular in RGB, sRGB */
    int unlit;                          /* KHR_materials_unlit: reflects no light in the bake */
    float emissive[3];                  /* emissiveFactor x KHR_materials_emissive_strength */
    float emissive_strength;            /* the strength alone (1 if absent) */
    lmb_texture_ref emissive_texture;   /* sRGB */
    int double_sided;
    lmb_alpha_mode alpha_mode;
    float alpha_cutoff;                 /* MASK: alphaCutoff (0.5 by default) */
    float transmission;                 /* KHR_materials_transmission factor (0: none) */
    lmb_texture_ref transmission_texture; /* its texture: transmission in red, linear */
    int volume;                         /* KHR_materials_volume: a closed mesh, tinted once on entering */
    float volume_tint[3];               /* volume: attenuationColor^(thicknessFactor / attenuationDistance) */
    float diffuse_transmission;         /* KHR_materials_diffuse_transmission factor (0: none) */
    float diffuse_transmission_color[3]; /* its colour factor (textures not read) */
} lmb_material;

/* How a light is baked (lights.modes, or the light's extras.lightmap_mode): as engines light
 * levels with some lights real-time (Unity's Baked Indirect and Shadowmask, Godot's per-light
 * bake mode, bevy's MixedLighting). */
typedef enum lmb_light_mode {
    LMB_LIGHT_BAKED = 0,    /* direct and bounced light in the lightmap */
    LMB_LIGHT_INDIRECT = 1, /* only its bounced light in the lightmap: the engine draws its direct light */
    LMB_LIGHT_REALTIME = 2  /* not in the bake at all */
} lmb_light_mode;

#define LMB_SHADOWMASK_CHANNELS 4

typedef struct lmb_light {
    char *name;
    char *node_name;     /* the node that places it: its name or "node N" */
    lmb_light_mode mode;
    int shadowmask_channel; /* output.shadowmask: its visibility's channel (0..3) in the shadowmask, or -1 */
    char *group;         /* extras.lightmap_group of the light, else of its node ("": none) */
    lmb_light_type type;
    uint32_t gltf_light; /* index into KHR_lights_punctual.lights */
    uint32_t node;       /* node that places it */
    float color[3];      /* linear */
    float intensity;     /* candela (point, spot) or lux (directional) */
    float range;         /* 0: infinite */
    float inner_cone, outer_cone; /* radians, spot only */
    double position[3];  /* world */
    double direction[3]; /* world, unit: the way light travels (node's -Z) */
} lmb_light;

typedef struct lmb_gltf_doc lmb_gltf_doc; /* opaque: the parsed glTF, kept for writing */

/* A node whose extras.lightmap_probes = [x, y, z] asks for an irradiance volume: a grid of
 * x x y x z probes over the unit cube centred on its origin, placed by its world transform
 * (bevy's IrradianceVolume). */
typedef struct lmb_node_probe_volume {
    uint32_t node;
    char *name;         /* the node's name or "node N" */
    double world[16];   /* column-major */
    uint32_t resolution[3];
} lmb_node_probe_volume;

typedef struct lmb_scene {
    char *path; /* the file it was loaded from */
    lmb_mesh *meshes;
    uint32_t mesh_count;
    lmb_primitive *primitives;
    uint32_t primitive_count;
    lmb_instance *instances;
    uint32_t instance_count;
    lmb_material *materials;
    uint32_t material_count;
    lmb_light *lights;
    uint32_t light_count;
    lmb_node_probe_volume *probe_volumes; /* nodes whose extras.lightmap_probes asks for a volume */
    uint32_t probe_volume_count;
    uint32_t node_count;
    uint32_t gpu_instanced_nodes; /* nodes expanded from EXT_mesh_gpu_instancing */
    double default_albedo[3];     /* diffuse albedo of primitives with no material (materials.default.albedo; glTF's
                                     default material is fully metallic: 0) */
    int default_albedo_given;     /* materials.default.albedo was set: the output's material for them says so */
    lmb_gltf_doc *doc;            /* owned */
} lmb_scene;

/* ---- bake config ---------------------------------------------------------- */

typedef enum lmb_gather_method {
    LMB_GATHER_COSINE = 0,         /* classic final gathering */
    LMB_GATHER_AMIS = 1,           /* the paper exactly */
    LMB_GATHER_AMIS_DEFENSIVE = 2  /* AMIS with a share of cosine samples in every pdf */
} lmb_gather_method;

typedef enum lmb_amis_weights {
    LMB_AMIS_UNBIASED = 0, /* each iteration's samples by their own pdf, fixed shares: unbiased */
    LMB_AMIS_BALANCE = 1   /* the paper: every sample by the balance heuristic over all lobes (biased, consistent) */
} lmb_amis_weights;

typedef enum lmb_ic_records_mode {
    LMB_IC_RECORDS_PER_PASS = 0, /* every pass places its own records */
    LMB_IC_RECORDS_SHARED = 1    /* the first pass places them, later passes gather again at them */
} lmb_ic_records_mode;

/* Which sides of an emissive face emit (docs/artists.md). */
typedef enum lmb_emission_sides {
    LMB_EMIT_FRONT = 0,    /* the front only, whatever the material says (as Unity's default GI) */
    LMB_EMIT_MATERIAL = 1  /* both sides where the material is doubleSided (as Cycles renders glTF) */
} lmb_emission_sides;

/* MASK: <stem>-lightmap-N-mask.png, per texel 255 = lit (valid), 128 = inside geometry, 0 = padding */
/* KTX2: <stem>-lightmap-N.ktx2 (write/ktx2.h); RGBM: <stem>-lightmap-N-rgbm.png (write/rgbm.h) */
enum {
    LMB_OUTPUT_EXR = 1,
    LMB_OUTPUT_HDR = 2,
    LMB_OUTPUT_PNG = 4,
    LMB_OUTPUT_MASK = 8,
    LMB_OUTPUT_KTX2 = 16,
    LMB_OUTPUT_RGBM = 32
};

/* output.scale: what a lightmap texel holds. three.js multiplies a lightmap by albedo / pi
 * (it wants E); bevy's and Unity's shaders multiply by albedo alone (they want E / pi). */
typedef enum lmb_output_scale {
    LMB_SCALE_IRRADIANCE = 0, /* E, lux */
    LMB_SCALE_RADIANCE = 1    /* E / pi: the exitant radiance of a white diffuse surface, nits */
} lmb_output_scale;

/* output.ktx2_format: the KTX2 lightmap's texel format (write/ktx2.h writes them). */
typedef enum lmb_ktx2_format {
    LMB_KTX2_E5B9G9R9 = 0,  /* vkFormat 123 E5B9G9R9_UFLOAT_PACK32: shared exponent, 2^-9 relative */
    LMB_KTX2_B10G11R11 = 1, /* vkFormat 122 B10G11R11_UFLOAT_PACK32: what bevy's Cornell box ships */
    LMB_KTX2_RGBA16F = 2,   /* vkFormat 97 R16G16B16A16_SFLOAT: half floats, alpha 1 */
    LMB_KTX2_BC6H = 3,      /* vkFormat 143 BC6H_UFLOAT_BLOCK: 4 x 4 blocks of 16 bytes (write/bc6h.h) */
    LMB_KTX2_ASTC_HDR = 4   /* vkFormat 1000066000 ASTC_4x4_SFLOAT_BLOCK (write/astc_adapter.h) */
} lmb_ktx2_format;

/* A u32 key set to "auto" (bounces). */
#define LMB_AUTO UINT32_MAX

#define LMB_MAX_PATTERNS 64
#define LMB_MAX_DIRECT_OF 16 /* lights named by --direct-of */
#define LMB_PATTERN_LEN 128

typedef struct lmb_density_override {
    char pattern[LMB_PATTERN_LEN]; /* glob over node and mesh names */
    double texel_density;
} lmb_density_override;

/* materials.override entry: the materials whose name matches get this diffuse albedo and/or
 * emission (a component < 0: keep the file's) */
typedef struct lmb_material_override {
    char pattern[LMB_PATTERN_LEN]; /* glob over material names */
    double albedo[3];              /* linear RGB, [0] < 0: keep */
    double emissive[3];            /* nits, linear RGB, [0] < 0: keep */
} lmb_material_override;

/* lights.modes entry: the lights whose name or node name matches get this mode */
typedef struct lmb_light_mode_rule {
    char pattern[LMB_PATTERN_LEN];
    int mode; /* lmb_light_mode; -1 before it is read */
} lmb_light_mode_rule;

/* output.light_groups entry (docs/light-groups.md): a set of the level's light sources baked into
 * a lightmap of its own, which a game scales and tints at run time; the bake's own lightmap is
 * the sum of the groups' at their scales. */
#define LMB_MAX_LIGHT_GROUPS 8
typedef struct lmb_light_group_spec {
    char name[LMB_PATTERN_LEN];    /* letters, digits, '_' and '-': it names the group's files */
    char pattern[LMB_PATTERN_LEN]; /* match: the lights whose name or node name matches ("" none) */
    int sky, emissive;             /* the sky's light, every emissive surface's light */
    int one_per_light;             /* every light it matches in a group of its own, named after the light (no
                                      name, sky or emissive then; without match the sky and the emissive
                                      surfaces too); beyond the limit the dimmest share `rest` */
    double scale;                  /* its weight in the lightmap the bake writes (1) */
    uint32_t line;                 /* the config's line that starts it (for messages; not part of its text) */
} lmb_light_group_spec;

/* probes.volumes entry: a box of probes at the centres of a resolution[0] x [1] x [2] grid of
 * cells (an irradiance volume an artist places) */
#define LMB_MAX_PROBE_VOLUMES 16
typedef struct lmb_probe_volume_spec {
    double min[3], max[3]; /* world corners, min < max on every axis */
    uint32_t resolution[3]; /* cells per axis, 1..256 */
} lmb_probe_volume_spec;

typedef struct lmb_config {
    /* unwrap / pack */
    double texel_density;          /* texels per world unit; 0 = auto: the lightmapped surface fills atlas_texels */
    lmb_density_override density_overrides[LMB_MAX_PATTERNS];
    uint32_t density_override_count;
    uint64_t atlas_texels;         /* auto density's budget of lightmapped texels; 0 = auto (lmb_config_atlas_texels) */
    uint32_t max_atlas_size;       /* texels per side */
    uint32_t padding;              /* texels between charts */
    int keep_uv1;                  /* keep a mesh's own TEXCOORD_1 */
    int share_meshes;              /* atlas.share_meshes: nodes that share a mesh keep sharing it, a rectangle each */
    int skip_hidden;               /* atlas.skip_hidden: faces back to back inside a solid get no texels */
    uint32_t min_chart_texels;     /* atlas.min_chart_texels: an instance's density is raised so its typical chart
                                      spans at least this many texels each way (0 = off; docs/defaults.md) */
    /* samples */
    uint32_t texel_samples;        /* gather points per texel (stratified) */
    uint32_t direct_samples;       /* shadow rays per area-light evaluation */
    int adaptive;                  /* samples.adaptive: more samples where an estimate's own variance says so */
    double noise_target;           /* samples.noise: relative standard error per texel aimed at */
    uint32_t max_rays;             /* samples.max_rays: adaptive sampling stops at this many samples per estimate */
    uint32_t gather_rays;          /* final gather rays per texel (reference: paths per texel) */
    uint32_t bounce_rays;          /* rays per texel of each bounce pass before the final gather */
    uint32_t bounce_rays_high;     /* rays per texel of bounce passes 3 and later; 0 = bounce_rays */
    uint32_t amis_iterations;
    uint32_t bounces;              /* indirect bounces, or LMB_AUTO: bounce passes until the tail is small, tail added */
    uint32_t bounces_max;          /* auto: at most this many bounces */
    double bounces_tail;           /* auto: stop when the estimated tail beyond the last pass is below this share */
    lmb_gather_method gather_method;
    double defensive_fraction;     /* share of cosine samples, AMIS defensive */
    lmb_amis_weights amis_weights; /* how AMIS weights its samples in the estimate */
    uint32_t guide_stride;         /* guided gathering: pilot texels every N texels (0: off) */
    uint32_t guide_lobes;          /* lobes a pilot learns (1..3) */
    int direct_at_hits;            /* final gather: direct light at each hit by shadow rays, the cache only for indirect */
    int denoise_indirect;          /* denoise.indirect: the final gather's light through the edge-aware filter */
    uint32_t denoise_levels;       /* denoise.levels: its a-trous passes */
    int denoise_direct;            /* denoise.direct: the lightmap's light through it again at the direct light's noise */
    double denoise_strength;       /* denoise.strength: luminance differences up to this many times the noise average */
    int reference;                 /* path-trace indirect light with no cache (ground truth) */
    /* irradiance cache (Ward): gathers at records, interpolation elsewhere */
    double ic_error;               /* Ward's a; 0 = a gather at every texel */
    double ic_min_spacing;         /* texels: the smallest record reach */
    double ic_max_spacing;         /* texels: the largest record reach */
    uint32_t ic_ray_scale;         /* a record gathers with this many times the per-texel rays */
    lmb_ic_records_mode ic_records; /* records per pass, or one set refined pass by pass */
    uint64_t farm_min_step_rays;   /* farm: a step estimated under this many rays runs in every process
                                      instead of as shards (it costs less than a shard's start) */
    uint64_t seed;
    uint32_t threads;              /* 0: all cores */
    unsigned output_formats;       /* LMB_OUTPUT_* bits */
    /* what is lightmapped */
    char include[LMB_MAX_PATTERNS][LMB_PATTERN_LEN];
    uint32_t include_count;
    char exclude[LMB_MAX_PATTERNS][LMB_PATTERN_LEN];
    uint32_t exclude_count;
    char extras_key[LMB_PATTERN_LEN]; /* node extras flag name, e.g. "lightmap" */
    /* lights */
    double light_intensity_scale;  /* multiplies punctual lights */
    double emissive_scale;         /* multiplies emissive materials */
    lmb_emission_sides emission_sides; /* front only, or as the material's doubleSided */
    lmb_emission_sides reflect_sides;  /* materials.reflect_sides: which sides reflect light to the bake's rays */
    uint32_t directional_rays;     /* samples.directional: cosine rays per texel for the indirect light's direction */
    int directional;               /* output.directional: directional lightmaps (lmb_direction.h) */
    int ktx2_format;               /* output.ktx2_format: lmb_ktx2_format */
    int ktx2_zstd;                 /* output.ktx2_supercompression: 1 zstd, 0 none */
    int ktx2_mipmaps;              /* output.ktx2_mipmaps: 1 a full mip chain in the lightmap's .ktx2 */
    lmb_output_scale output_scale; /* output.scale: E or E / pi in every lightmap file */
    double rgbm_range;             /* output.rgbm_range: the largest value RGBM holds; 0 = auto (each atlas's
                                      largest valid texel, rounded up to a power of two) */
    int firefly_spread;            /* fireflies.spread: outlier texels' excess moved to their neighbours */
    /* seams */
    int seam_stitch;               /* least-squares seam stitching after the gather */
    /* sky (lights/sky.h): light from every direction a ray leaves the level by */
    double sky_intensity;          /* radiance multiplier, nits; 0 = no sky (a config that gives sky.image and
                                      no sky.intensity reads as 1: the map's own radiance) */
    double sky_color[3];           /* linear RGB, times sky_intensity (and the image) */
    double sky_ground[3];          /* radiance below the horizon, times sky_intensity; [0] < 0: none (the sky or image's own) */
    char sky_image[LMB_PATTERN_LEN]; /* equirectangular HDR/EXR, relative to the config's folder; "" = none */
    double sky_rotation;           /* degrees about sky_up */
    double sky_up[3];              /* the sky's up axis (unit; +Y, glTF's up) */
    uint32_t sky_samples;          /* sky rays per gather point, split between the map's and the cosine distribution */
    int sky_cosine_only;           /* sky.sampling: cosine: no map samples (the benchmark's comparison) */
    double sun_angle;              /* degrees: a directional light is a disc of this angular diameter; 0 = a point */
    lmb_light_mode_rule light_modes[LMB_MAX_PATTERNS]; /* lights.modes: first match wins, over the file's extras */
    uint32_t light_mode_count;
    /* not a config key: `lmbake bake --direct-of GLOB` (lmb_config_direct_of): the lights whose
     * name or node name matches one of these are the only ones the bake holds (others realtime) */
    char direct_of[LMB_MAX_DIRECT_OF][LMB_PATTERN_LEN];
    uint32_t direct_of_count;
    /* not a config key: `lmbake bake --stages-out DIR`: the folder the light of each stage (the
     * direct light, the bounce passes') is written to as soon as it is known (watch/stages_out.h);
     * "" = none */
    char stages_out[4096];
    int shadowmask;                /* output.shadowmask: the visibility of up to 4 `indirect` lights per texel */
    lmb_light_group_spec light_groups[LMB_MAX_LIGHT_GROUPS]; /* output.light_groups */
    uint32_t light_group_count;
    /* materials the file did not set, or set wrongly for a bake */
    double default_albedo[3];      /* materials.default.albedo: primitives with no material; [0] < 0: none (glTF's metal) */
    lmb_material_override material_overrides[LMB_MAX_PATTERNS];
    uint32_t material_override_count;
    /* light probes (baker/probes): irradiance for what moves through the level */
    int probes_auto;               /* probes.auto: a grid over the level, refined near surfaces */
    double probe_spacing;          /* probes.spacing: the grid's cell, world units; 0 = auto (from the surface area) */
    uint32_t probe_rays;           /* probes.rays: directions each probe looks in */
    lmb_probe_volume_spec probe_volumes[LMB_MAX_PROBE_VOLUMES]; /* probes.volumes */
    uint32_t probe_volume_count;
    char config_path[4096];        /* the config file it was loaded from (lmb_config_load), "" for none: sky.image is
                                      read from its folder; not a key */
} lmb_config;

/* Fills cfg with the documented defaults (docs/config.md). */
void lmb_config_default(lmb_config *cfg);

/* The auto density's texel budget: cfg->atlas_texels, or when 0 the texels of one 1024^2
 * atlas (max_size^2 if smaller) at the coverage the packer typically reaches on real levels. */
uint64_t lmb_config_atlas_texels(const lmb_config *cfg);

/* Reads a YAML bake config over the defaults already in cfg. Unknown keys, wrong
 * types and out-of-range values are LMB_ERR_INPUT naming file, line and key. */
lmb_status lmb_config_load(const char *path, lmb_config *cfg, lmb_error *err);

/* Same, from a string; `name` is used in messages in place of a file name. */
lmb_status lmb_config_parse(const char *name, const char *text, size_t length, lmb_config *cfg,
                            lmb_error *err);

/* Warns, naming the config and both keys, of every key set (to other than its default) whose
 * effect another key switches off (sky.color with no sky, output.ktx2_format with no ktx2
 * output, ...); checks paths whether or not they are used (sky.image: LMB_ERR_INPUT). */
lmb_status lmb_config_lint(const lmb_config *cfg, const lmb_log *log, lmb_error *err);

/* The effective config as YAML (every key, grouped by section) that lmb_config_parse reads back
 * to the same lmb_config; like snprintf, writes at most size bytes (NUL included) and returns the
 * length the whole text needs. Two configs that bake the same give the same text. */
size_t lmb_config_write(const lmb_config *cfg, char *buf, size_t size);

/* Turns cfg into its quick look (`bake --quick`, the watch's first picture; docs/watch.md): the
 * same layout, lit with a fraction of the rays, no seam stitching or probes. */
void lmb_config_quick(lmb_config *cfg);

/* Turns cfg into the direct light of the lights whose name or node name matches one of the
 * `count` globs in names (`bake --direct-of`, one light's share of a bake; docs/cli.md): the
 * same layout and the same direct light as cfg's bake holds of those lights, and
 * nothing else: no bounces, sky, emissive surfaces, seam stitching or probes; only the .hdr and
 * .png. LMB_ERR_USAGE for more than LMB_MAX_DIRECT_OF names or one too long. */
lmb_status lmb_config_direct_of(lmb_config *cfg, const char *const *names, uint32_t count, lmb_error *err);

/* glob match with '*' and '?', used for node/mesh name patterns. */
int lmb_glob_match(const char *pattern, const char *name);

/* ---- loading -------------------------------------------------------------- */

/* Loads a .gltf or .glb into *out (caller frees with lmb_scene_free). On error nothing
 * needs freeing. Unsupported required extensions, broken accessors, cycles... are
 * LMB_ERR_INPUT with a message naming the file and the object. cfg may be NULL (defaults);
 * the loader reads only cfg->extras_key from it. */
lmb_status lmb_scene_load(const char *path, const lmb_config *cfg, lmb_scene **out,
                          const lmb_log *log, lmb_error *err);

void lmb_scene_free(lmb_scene *scene);

/* Marks each instance lightmapped or not (with a reason) from the config's include /
 * exclude globs, the node extras flag and the geometry itself. */
/* "baked", "indirect" or "realtime" -> *mode; -1 for anything else. */
int lmb_light_mode_parse(const char *name, lmb_light_mode *mode);

/* The name of a mode ("baked", "indirect", "realtime"). */
const char *lmb_light_mode_name(lmb_light_mode mode);

/* Applies cfg's lights.modes (first matching glob over the light's name and its node's name
 * wins over the file's extras.lightmap_mode) and, with output.shadowmask, gives the first 4
 * `indirect` lights their channels (more are listed in a warning and baked instead). Logs
 * each light's mode when any is not `baked`. */
void lmb_scene_set_light_modes(lmb_scene *scene, const lmb_config *cfg, const lmb_log *log);

void lmb_scene_select_lightmapped(lmb_scene *scene, const lmb_config *cfg);

/* Counts for reports. Triangle counts include zero-area ones; "in_nodes" counts each node
 * once (as the glTF's JSON reads), "instanced" expands EXT_mesh_gpu_instancing copies. */
typedef struct lmb_scene_stats {
    uint64_t triangles_unique;     /* over all meshes */
    uint64_t triangles_skipped;    /* in primitives without POSITION, not baked */
    uint64_t degenerate_unique;    /* zero-area, over all meshes */
    uint64_t triangles_in_nodes;   /* over nodes that place a mesh */
    uint64_t triangles_instanced;  /* over all instances */
    uint32_t lightmapped_instances;
    uint64_t lightmapped_triangles; /* non-degenerate, over lightmapped instances */
    uint32_t emissive_materials;    /* emissive factor x strength > 0 */
    uint64_t emissive_triangles;    /* over instances, non-degenerate: the area lights */
} lmb_scene_stats;

void lmb_scene_stats_compute(const lmb_scene *scene, lmb_scene_stats *out);

/* ---- baking -------------------------------------------------------------- */

#define LMB_MAX_REPORTED_BOUNCES 65

/* Why bounces: auto stopped. */
enum { LMB_BOUNCES_TAIL = 1, LMB_BOUNCES_SMALL_PASS = 2, LMB_BOUNCES_MAX = 3, LMB_BOUNCES_TAIL_BOUNDED = 4 };

typedef struct lmb_bake_stats {
    uint32_t atlases;
    uint64_t texels;        /* texels holding gather points */
    uint64_t valid_texels;  /* of those, not inside geometry */
    uint64_t rays;          /* shadow and validity rays traced */
    double seconds;         /* wall time of the bake (layout to last file) */
    double light_seconds;   /* wall time of the lighting stages */
    double gather_seconds;  /* wall time of the final gather (or the reference) */
    uint64_t gather_rays;   /* rays of the final gather (or the reference) */
    uint64_t amis_adapted;  /* AMIS lobe updates that changed a lobe */
    uint64_t gather_records; /* irradiance cache: records of the final gather (0: a gather per texel) */
    uint32_t bounces;       /* bounces of indirect light computed (passes + the final gather) */
    double bounce_energy[LMB_MAX_REPORTED_BOUNCES]; /* mean luminance: [0] direct, [b] what pass b added */
    double bounce_ratio;    /* bounces: auto: the last ratio of what two passes added */
    double tail_share;      /* bounces: auto: the estimated tail's share of the total */
    int tail_added;         /* bounces: auto: the geometric tail was added to the cache */
    int bounce_stop;        /* bounces: auto: LMB_BOUNCES_* (0: no pass ran) */
    int no_light;           /* nothing in the scene emits: the lightmaps are 0, no gather ran */
    double texel_density;   /* the scene's density (auto: what the budget gave) */
    int density_auto;       /* texel_density: auto */
    uint32_t density_capped; /* auto: instances lowered to fit one atlas */
    uint32_t density_raised; /* instances raised by atlas.min_chart_texels */
    double direct_noise_median, direct_noise_p95; /* estimated relative standard error of texels' direct light,
                                                     of the light shown */
    uint64_t direct_refined; /* texels whose direct light took more samples (samples.noise) */
    uint64_t direct_capped; /* of those, stopped by samples.max_rays short of samples.noise */
    uint64_t records_extended; /* final gather: records that gathered more rays for samples.noise */
    uint64_t records_capped;   /* of those, stopped by samples.max_rays */
    double indirect_noise;     /* final gather with the cache: its records' median relative standard error */
    uint64_t denoised_texels;  /* texels the denoiser filtered, summed over its filters (indirect, then all) */
    uint64_t rim_limited;   /* partly covered texels limited to their neighbours (post/rim.c) */
    double rim_energy;      /* the direct light that removed, as a share of all direct light */
    uint64_t firefly_texels; /* fireflies spread to their neighbours (post/fireflies.c) */
    double firefly_moved;   /* the light that moved, as a share of all light */
    uint64_t seam_edges;    /* seam edges stitched */
    double seam_jump_before, seam_jump_after; /* largest relative luminance jump across them */
    uint64_t rgbm_clamped;  /* output rgbm: valid texels above the range, clamped */
    char gltf_path[8600];   /* the output glTF */
} lmb_bake_stats;

/* Bakes the lightmapped instances of scene (after lmb_scene_select_lightmapped) into
 * outdir: per atlas <stem>-lightmap-N.exr / .hdr / .png (as cfg->output_formats says; EXR
 * and HDR are linear irradiance in lux, PNG a tonemapped preview) and <stem>.gltf with
 * TEXCOORD_1 and MOZ_lightmap. Files appear only when everything succeeded; outdir must
 * not be the input's folder. The scene's glTF document is modified (it becomes the output). */
lmb_status lmb_bake(lmb_scene *scene, const lmb_config *cfg, const char *outdir, lmb_progress_fn progress,
                    void *progress_user, lmb_bake_stats *stats, const lmb_log *log, lmb_error *err);

/* The staged bake's plan stage (docs/farm.md): lays out scene (unwrap, pack) as lmb_bake
 * would and writes the layout to plan_path with the identity of the input and the config
 * (baker/farm/part_file.h), all-or-nothing. */
lmb_status lmb_plan_write(const lmb_scene *scene, const lmb_config *cfg, const char *plan_path,
                          lmb_progress_fn progress, void *progress_user, const lmb_log *log, lmb_error *err);

/* lmb_bake with the layout read from a plan file instead of built: the same files, byte for
 * byte. A plan made from another input, config or lmbake version is refused (LMB_ERR_INPUT),
 * naming what differs. plan_path NULL: lmb_bake. */
lmb_status lmb_bake_planned(lmb_scene *scene, const lmb_config *cfg, const char *plan_path, const char *outdir,
                            lmb_progress_fn progress, void *progress_user, lmb_bake_stats *stats, const lmb_log *log,
                            lmb_error *err);

/* The staged bake on a farm (docs/farm.md, baker/farm/steps.h). The bake is a sequence of
 * steps; each step's items can be split into shards that run anywhere, and merged. */
typedef enum lmb_farm_mode {
    LMB_FARM_LOCAL = 0,  /* every step in this process: lmb_bake */
    LMB_FARM_STEP = 1,   /* one shard of one step: reads earlier steps' states from farm_dir, writes its part */
    LMB_FARM_FINISH = 2, /* every step from farm_dir's states, then post-processing and the outputs */
    LMB_FARM_WORKER = 3  /* a worker for the whole bake: shards worker, worker + workers, ... of every
                            step, waiting for the other workers' parts and merging each step itself;
                            worker 0 with an outdir writes the outputs as LMB_FARM_FINISH does */
} lmb_farm_mode;

typedef struct lmb_farm_run {
    lmb_farm_mode mode;
    const char *farm_dir;     /* the shared folder (lmbake plan --farm) */
    uint32_t step;            /* LMB_FARM_STEP: the step to run */
    uint32_t shard, shards;   /* LMB_FARM_STEP: shard (0-based) of shards */
    int ended;                /* out, LMB_FARM_STEP: the bake has fewer steps (an "end" part was written) */
    uint32_t steps;           /* out: steps met */
    uint32_t worker, workers; /* LMB_FARM_WORKER: 0-based worker of workers (workers <= shards) */
    double wait_timeout;      /* LMB_FARM_WORKER: seconds to wait for another worker's part (0: for ever) */
    const char *layout_cache; /* LMB_FARM_LOCAL with no plan: a folder of layouts kept between bakes
                                 (lmbake bake --layout-cache, docs/watch.md); NULL: none */
    int layout_reused;        /* out: the layout was read back from layout_cache, not built */
    uint32_t tail_threads;    /* LMB_FARM_WORKER, the worker that writes the output: threads for what
                                 runs after the last step, when the other workers have stopped
                                 (post-processing, images, glTF); 0: every core of its machine */
    int relight_only;         /* with layout_cache: bake only when the layout and every light group
                                 are kept there (a relight: the sum and the files); else stop before
                                 any work with LMB_NOT_KEPT, nothing written (preview --watch) */
} lmb_farm_run;

/* lmb_bake_planned through the farm: plan_path is required unless mode is LMB_FARM_LOCAL.
 * LMB_FARM_STEP writes no outputs (outdir, stats unused; stats may be NULL). LMB_FARM_FINISH
 * writes outdir exactly as lmb_bake would, all-or-nothing, once every step is merged. */
lmb_status lmb_bake_farm(lmb_scene *scene, const lmb_config *cfg, const char *plan_path, lmb_farm_run *run,
                         const char *outdir, lmb_progress_fn progress, void *progress_user, lmb_bake_stats *stats,
                         const lmb_log *log, lmb_error *err);

/* What lmb_farm_merge did. */
typedef struct lmb_farm_merge_report {
    int end;                  /* the bake has `step` steps: no later step exists (farm_dir/end written) */
    int noop;                 /* the step lies past the end: nothing to merge */
    uint64_t items;
    char name[96];            /* what the step computes */
} lmb_farm_merge_report;

/* Merges the `shards` parts of step `step` in farm_dir into its state, refusing any part not
 * made from this plan (plan_path), input, config and lmbake version, and naming the part and
 * the difference. */
lmb_status lmb_farm_merge(const lmb_scene *scene, const lmb_config *cfg, const char *plan_path, const char *farm_dir,
                          uint32_t step, uint32_t shards, lmb_farm_merge_report *report, lmb_error *err);

/* The step the farm's bake ended at (farm_dir/end, written by the merge of the first step
 * that does not exist), or UINT32_MAX while not known. */
uint32_t lmb_farm_end_step(const char *farm_dir);

/* Creates farm_dir and its parts/ and steps/ folders (existing ones are fine). */
lmb_status lmb_farm_make_dirs(const char *farm_dir, lmb_error *err);

/* 1 if the material emits (emissive factor x strength > 0 in any channel). */
int lmb_material_is_emissive(const lmb_material *m);

#ifdef __cplusplus
}
#endif

#endif
