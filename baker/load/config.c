/*
 * The per-level bake config: YAML read with libyaml's document API (it keeps every lmb_cfg_node's
 * line, so messages can name it) and checked against one schema table below: each key's
 * dotted path, its setter (the type), its range and where it lands in lmb_config. Sections
 * ("atlas", "samples", ...) are implied by the dotted paths. Every key is optional; the
 * defaults are set by lmb_config_default and documented in docs/config.md and
 * assets/example-config.yaml.
 *
 * Every problem is LMB_ERR_INPUT "FILE:LINE: key 'a.b': expected ..., got '...'" (or
 * "unknown key", "given twice", "YAML syntax error"); out of memory is LMB_ERR_INTERNAL.
 * On error cfg may be partly updated (keys before the bad one are applied): callers
 * discard it. Plain YAML nulls (nothing, ~, null) stand for an empty section or list.
 */
#include <lmbake/lmbake.h>

#include "config_internal.h"
#include "../util/file.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

static lmb_status set_overrides(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_probe_volumes(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static const schema probe_volume_schema;
static lmb_status set_material_overrides(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static const schema material_override_schema;
static lmb_status set_light_modes(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static const schema light_mode_schema;
static lmb_status set_light_groups(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static const schema light_group_schema;

#define OFF(f) offsetof(lmb_config, f)
#define FLOAT(p, off, lo, hi, op) {.path = p, .set = lmb_cfg_set_float, .offset = off, .flo = lo, .fhi = hi, .open = op}
#define U32(p, off, lo, hi) {.path = p, .set = lmb_cfg_set_u32, .offset = off, .ilo = lo, .ihi = hi}
#define FLOAT_AUTO(p, off, lo, hi, op) {.path = p, .set = lmb_cfg_set_float_or_auto, .offset = off, .flo = lo, .fhi = hi, .open = op}
#define U32_AUTO(p, off, lo, hi) {.path = p, .set = lmb_cfg_set_u32_or_auto, .offset = off, .ilo = lo, .ihi = hi}
#define U64_AUTO(p, off, lo, hi) {.path = p, .set = lmb_cfg_set_u64_or_auto, .offset = off, .ilo = lo, .ihi = hi}
#define U64(p, off, lo, hi) {.path = p, .set = lmb_cfg_set_u64, .offset = off, .ilo = lo, .ihi = hi}
#define BOOL(p, off) {.path = p, .set = lmb_cfg_set_bool, .offset = off}
#define ENUM(p, off, nm) {.path = p, .set = lmb_cfg_set_enum, .offset = off, .names = nm}
#define FLAGS(p, off, nm) {.path = p, .set = lmb_cfg_set_flags, .offset = off, .names = nm, .max_items = LMB_MAX_PATTERNS}
#define STRING(p, off) {.path = p, .set = lmb_cfg_set_string, .offset = off}
#define RGB(p, off, lo, hi, op) {.path = p, .set = lmb_cfg_set_rgb, .offset = off, .flo = lo, .fhi = hi, .open = op}
#define DIRECTION(p, off) {.path = p, .set = lmb_cfg_set_direction, .offset = off}
#define PATH(p, off) {.path = p, .set = lmb_cfg_set_path, .offset = off}
#define LIST(p, fn, off, cnt) {.path = p, .set = fn, .offset = off, .count_offset = cnt, .max_items = LMB_MAX_PATTERNS}

/* Index = lmb_gather_method value; bit i = 1 << i = LMB_OUTPUT_* */
static const char *const gather_methods[] = {"cosine", "amis", "amis_defensive", NULL};
static const char *const amis_weights[] = {"unbiased", "balance", NULL};
static const char *const ic_records_modes[] = {"per_pass", "shared", NULL};
static const char *const emission_sides[] = {"front", "material", NULL};
static const char *const sky_samplings[] = {"mis", "cosine", NULL};
static const char *const output_formats[] = {"exr", "hdr", "png", "mask", "ktx2", "rgbm", NULL};
static const char *const output_scales[] = {"irradiance", "radiance", NULL};
static const char *const ktx2_formats[] = {"e5b9g9r9", "b10g11r11", "rgba16f", "bc6h", "astc_hdr", NULL};
static const char *const ktx2_supercompressions[] = {"none", "zstd", NULL};
static const char *const light_mode_names[] = {"baked", "indirect", "realtime", NULL};
_Static_assert(LMB_LIGHT_BAKED == 0 && LMB_LIGHT_INDIRECT == 1 && LMB_LIGHT_REALTIME == 2, "light_mode_names");
_Static_assert(LMB_GATHER_COSINE == 0 && LMB_GATHER_AMIS == 1 && LMB_GATHER_AMIS_DEFENSIVE == 2, "gather_methods");
_Static_assert(LMB_SCALE_IRRADIANCE == 0 && LMB_SCALE_RADIANCE == 1, "output_scales");
_Static_assert(LMB_EMIT_FRONT == 0 && LMB_EMIT_MATERIAL == 1, "emission_sides");
_Static_assert(LMB_OUTPUT_EXR == 1 && LMB_OUTPUT_HDR == 2 && LMB_OUTPUT_PNG == 4 && LMB_OUTPUT_MASK == 8 &&
                   LMB_OUTPUT_KTX2 == 16 && LMB_OUTPUT_RGBM == 32,
               "output_formats");

static const key_spec config_keys[] = {
    FLOAT_AUTO("texel_density", OFF(texel_density), 0, 100000, OPEN_LO),
    LIST("density_overrides", set_overrides, OFF(density_overrides), OFF(density_override_count)),
    U64_AUTO("atlas.texels", OFF(atlas_texels), 256, 4294967296LL),
    U32("atlas.max_size", OFF(max_atlas_size), 16, 16384),
    U32("atlas.padding", OFF(padding), 0, 64),
    BOOL("atlas.keep_uv1", OFF(keep_uv1)),
    BOOL("atlas.share_meshes", OFF(share_meshes)),
    BOOL("atlas.skip_hidden", OFF(skip_hidden)),
    U32("atlas.min_chart_texels", OFF(min_chart_texels), 0, 64),
    U32("samples.texel", OFF(texel_samples), 1, 256),
    U32("samples.direct", OFF(direct_samples), 1, 65536),
    BOOL("samples.adaptive", OFF(adaptive)),
    FLOAT("samples.noise", OFF(noise_target), 0, 1, OPEN_LO | OPEN_HI),
    U32("samples.max_rays", OFF(max_rays), 64, 16777216),
    U32("samples.gather", OFF(gather_rays), 1, 1048576),
    U32("samples.bounce", OFF(bounce_rays), 1, 1048576),
    U32("samples.bounce_high", OFF(bounce_rays_high), 0, 1048576),
    U32("samples.amis_iterations", OFF(amis_iterations), 1, 64),
    U32("samples.directional", OFF(directional_rays), 1, 65536),
    U32_AUTO("bounces", OFF(bounces), 0, 64),
    U32("bounces_auto.max", OFF(bounces_max), 1, 64),
    FLOAT("bounces_auto.tail", OFF(bounces_tail), 0, 1, OPEN_LO | OPEN_HI),
    ENUM("gather.method", OFF(gather_method), gather_methods),
    ENUM("gather.amis_weights", OFF(amis_weights), amis_weights),
    FLOAT("gather.defensive", OFF(defensive_fraction), 0, 1, OPEN_HI),
    U32("gather.guide_stride", OFF(guide_stride), 0, 64),
    U32("gather.lobes", OFF(guide_lobes), 1, 3),
    BOOL("gather.direct_at_hits", OFF(direct_at_hits)),
    BOOL("denoise.indirect", OFF(denoise_indirect)),
    U32("denoise.levels", OFF(denoise_levels), 1, 8),
    BOOL("denoise.direct", OFF(denoise_direct)),
    FLOAT("denoise.strength", OFF(denoise_strength), 0, 100, OPEN_LO),
    FLOAT("irradiance_cache.error", OFF(ic_error), 0, 10, 0),
    FLOAT("irradiance_cache.min_spacing", OFF(ic_min_spacing), 0.5, 4096, 0),
    FLOAT("irradiance_cache.max_spacing", OFF(ic_max_spacing), 1, 4096, 0),
    U32("irradiance_cache.ray_scale", OFF(ic_ray_scale), 1, 1024),
    ENUM("irradiance_cache.records", OFF(ic_records), ic_records_modes),
    U64("farm.min_step_rays", OFF(farm_min_step_rays), 0, 1000000000000000LL),
    U64("seed", OFF(seed), 0, 9223372036854775807LL),
    U32("threads", OFF(threads), 0, 1024),
    FLAGS("output.formats", OFF(output_formats), output_formats),
    BOOL("output.directional", OFF(directional)),
    ENUM("output.ktx2_format", OFF(ktx2_format), ktx2_formats),
    ENUM("output.ktx2_supercompression", OFF(ktx2_zstd), ktx2_supercompressions),
    BOOL("output.ktx2_mipmaps", OFF(ktx2_mipmaps)),
    ENUM("output.scale", OFF(output_scale), output_scales),
    FLOAT_AUTO("output.rgbm_range", OFF(rgbm_range), 0, 1e9, OPEN_LO),
    LIST("lightmap.include", lmb_cfg_set_globs, OFF(include), OFF(include_count)),
    LIST("lightmap.exclude", lmb_cfg_set_globs, OFF(exclude), OFF(exclude_count)),
    STRING("lightmap.extras_key", OFF(extras_key)),
    FLOAT("lights.intensity_scale", OFF(light_intensity_scale), 0, 1e9, 0),
    FLOAT("lights.emissive_scale", OFF(emissive_scale), 0, 1e9, 0),
    ENUM("lights.emission_sides", OFF(emission_sides), emission_sides),
    ENUM("materials.reflect_sides", OFF(reflect_sides), emission_sides),
    FLOAT("lights.sun_angle", OFF(sun_angle), 0, 30, 0),
    {.path = "lights.modes", .set = set_light_modes, .offset = OFF(light_modes), .count_offset = OFF(light_mode_count),
     .max_items = LMB_MAX_PATTERNS, .items = &light_mode_schema, .item_size = sizeof(lmb_light_mode_rule)},
    BOOL("output.shadowmask", OFF(shadowmask)),
    {.path = "output.light_groups", .set = set_light_groups, .offset = OFF(light_groups),
     .count_offset = OFF(light_group_count), .max_items = LMB_MAX_LIGHT_GROUPS, .items = &light_group_schema,
     .item_size = sizeof(lmb_light_group_spec)},
    FLOAT("sky.intensity", OFF(sky_intensity), 0, 1e9, 0),
    RGB("sky.color", OFF(sky_color), 0, 1e9, 0),
    RGB("sky.ground_color", OFF(sky_ground), 0, 1e9, OPEN_NONE),
    PATH("sky.image", OFF(sky_image)),
    FLOAT("sky.rotation", OFF(sky_rotation), -360, 360, 0),
    DIRECTION("sky.up", OFF(sky_up)),
    RGB("materials.default.albedo", OFF(default_albedo), 0, 1, OPEN_NONE),
    {.path = "materials.override", .set = set_material_overrides, .offset = OFF(material_overrides),
     .count_offset = OFF(material_override_count), .max_items = LMB_MAX_PATTERNS, .items = &material_override_schema,
     .item_size = sizeof(lmb_material_override)},
    U32("sky.samples", OFF(sky_samples), 1, 65536),
    ENUM("sky.sampling", OFF(sky_cosine_only), sky_samplings),
    BOOL("seams.stitch", OFF(seam_stitch)),
    BOOL("probes.auto", OFF(probes_auto)),
    FLOAT_AUTO("probes.spacing", OFF(probe_spacing), 0, 1e9, OPEN_LO),
    U32("probes.rays", OFF(probe_rays), 16, 65536),
    {.path = "probes.volumes", .set = set_probe_volumes, .offset = OFF(probe_volumes),
     .count_offset = OFF(probe_volume_count), .max_items = LMB_MAX_PROBE_VOLUMES, .items = &probe_volume_schema,
     .item_size = sizeof(lmb_probe_volume_spec)},
    BOOL("fireflies.spread", OFF(firefly_spread)),
};

/* One density_overrides entry, filled into an lmb_density_override. */
static const key_spec override_keys[] = {
    STRING("density_overrides.match", offsetof(lmb_density_override, pattern)),
    FLOAT("density_overrides.texel_density", offsetof(lmb_density_override, texel_density), 0, 100000, OPEN_LO),
};

/* One materials.override entry, filled into an lmb_material_override. */
static const key_spec material_override_keys[] = {
    STRING("materials.override.match", offsetof(lmb_material_override, pattern)),
    RGB("materials.override.albedo", offsetof(lmb_material_override, albedo), 0, 1, OPEN_NONE),
    RGB("materials.override.emissive", offsetof(lmb_material_override, emissive), 0, 1e9, OPEN_NONE),
};
/* One probes.volumes entry, filled into an lmb_probe_volume_spec. */
static const key_spec probe_volume_keys[] = {
    {.path = "probes.volumes.min", .set = lmb_cfg_set_point, .offset = offsetof(lmb_probe_volume_spec, min)},
    {.path = "probes.volumes.max", .set = lmb_cfg_set_point, .offset = offsetof(lmb_probe_volume_spec, max)},
    {.path = "probes.volumes.resolution", .set = lmb_cfg_set_u32x3, .offset = offsetof(lmb_probe_volume_spec, resolution),
     .ilo = 1, .ihi = 256},
};
static const schema probe_volume_schema = {probe_volume_keys, sizeof probe_volume_keys / sizeof *probe_volume_keys};

/* One lights.modes entry, filled into an lmb_light_mode_rule. */
static const key_spec light_mode_keys[] = {
    STRING("lights.modes.match", offsetof(lmb_light_mode_rule, pattern)),
    ENUM("lights.modes.mode", offsetof(lmb_light_mode_rule, mode), light_mode_names),
};
static const schema light_mode_schema = {light_mode_keys, sizeof light_mode_keys / sizeof *light_mode_keys};

/* One output.light_groups entry, filled into an lmb_light_group_spec. */
static const key_spec light_group_keys[] = {
    STRING("output.light_groups.name", offsetof(lmb_light_group_spec, name)),
    STRING("output.light_groups.match", offsetof(lmb_light_group_spec, pattern)),
    BOOL("output.light_groups.sky", offsetof(lmb_light_group_spec, sky)),
    BOOL("output.light_groups.emissive", offsetof(lmb_light_group_spec, emissive)),
    BOOL("output.light_groups.one_per_light", offsetof(lmb_light_group_spec, one_per_light)),
    FLOAT("output.light_groups.scale", offsetof(lmb_light_group_spec, scale), 0, 1e9, 0),
};
static const schema light_group_schema = {light_group_keys, sizeof light_group_keys / sizeof *light_group_keys};

static const schema material_override_schema = {material_override_keys,
                                                sizeof material_override_keys / sizeof *material_override_keys};

static const schema config_schema = {config_keys, sizeof config_keys / sizeof *config_keys};
static const schema override_schema = {override_keys, sizeof override_keys / sizeof *override_keys};

const schema *lmb_cfg_schema(void)
{
    return &config_schema;
}

const schema *lmb_cfg_override_schema(void)
{
    return &override_schema;
}

void lmb_config_default(lmb_config *cfg)
{
    memset(cfg, 0, sizeof *cfg); /* also the padding bytes, so configs compare with memcmp */
    cfg->texel_density = 0;      /* auto */
    cfg->atlas_texels = 0;       /* auto: lmb_config_atlas_texels */
    cfg->max_atlas_size = 4096;  /* atlases are cropped to what they hold; texels follow atlas.texels */
    cfg->padding = 2;
    cfg->min_chart_texels = 4; /* a prop a few centimetres across in a 100 m level is still lit */
    cfg->keep_uv1 = 0;
    cfg->skip_hidden = 1; /* faces nothing can see cost texels and padding (docs/unwrap.md) */
    cfg->texel_samples = 4;
    cfg->direct_samples = 16;
    cfg->adaptive = 1;
    cfg->noise_target = 0.01;
    cfg->max_rays = 4096;
    cfg->denoise_indirect = 1;
    cfg->denoise_levels = 4;
    cfg->denoise_direct = 1;
    cfg->denoise_strength = 2;
    cfg->gather_rays = 256;
    cfg->bounce_rays = 64;
    cfg->bounce_rays_high = 16; /* docs/defaults.md: no measurable loss, 15% faster */
    cfg->amis_iterations = 4;
    cfg->bounces = LMB_AUTO;
    cfg->bounces_max = 32;
    cfg->bounces_tail = 0.05;
    cfg->gather_method = LMB_GATHER_AMIS_DEFENSIVE;
    cfg->defensive_fraction = 0.1;
    cfg->guide_stride = 8;
    cfg->guide_lobes = 2;
    cfg->ic_error = 0.3;
    cfg->ic_min_spacing = 4;
    cfg->ic_max_spacing = 8;
    cfg->sun_angle = 0.53; /* the real sun's angular diameter */
    cfg->sky_intensity = 0;
    cfg->sky_color[0] = cfg->sky_color[1] = cfg->sky_color[2] = 1;
    cfg->sky_ground[0] = cfg->sky_ground[1] = cfg->sky_ground[2] = -1; /* none */
    cfg->sky_up[1] = 1;
    cfg->sky_samples = 64;
    cfg->probes_auto = 1;
    cfg->probe_spacing = 0; /* auto */
    cfg->probe_rays = 512;
    cfg->ktx2_format = 0; /* e5b9g9r9 */
    cfg->ktx2_zstd = 1;
    cfg->default_albedo[0] = cfg->default_albedo[1] = cfg->default_albedo[2] = -1; /* none: glTF's metal */
    cfg->ic_ray_scale = 4;
    cfg->farm_min_step_rays = 250000; /* under 0.1 s of one core: below, a step's wait and merge cost more */
    cfg->ic_records = LMB_IC_RECORDS_SHARED; /* docs/irradiance-cache.md: as accurate, 1.0-1.4x faster */
    cfg->seed = 1;
    cfg->threads = 0;
    cfg->output_formats = LMB_OUTPUT_EXR | LMB_OUTPUT_HDR | LMB_OUTPUT_PNG;
    strcpy(cfg->include[0], "*");
    cfg->include_count = 1;
    strcpy(cfg->extras_key, "lightmap");
    cfg->light_intensity_scale = 1.0;
    cfg->emissive_scale = 1.0;
    cfg->emission_sides = LMB_EMIT_FRONT; /* docs/artists.md */
    cfg->reflect_sides = LMB_EMIT_MATERIAL; /* docs/materials.md: glTF's doubleSided, both sides reflect */
    cfg->seam_stitch = 1;
    cfg->firefly_spread = 1;
    cfg->directional = 1; /* docs/artists.md: +5% time on level-single-10 */
    cfg->directional_rays = 32;
}

uint64_t lmb_config_atlas_texels(const lmb_config *cfg)
{
    /* one 1024^2 atlas (or one max_size atlas if smaller) at 0.6, the share of an atlas the
     * packer fills with chart texels on real levels (docs/defaults.md) */
    double side = cfg->max_atlas_size < 1024 ? cfg->max_atlas_size : 1024;
    return cfg->atlas_texels ? cfg->atlas_texels : (uint64_t)(0.6 * side * side);
}

/* ---- density overrides: a list of mappings walked with their own schema ---- */

static lmb_status walk_mapping(parse_ctx *c, const schema *s, const yaml_node_t *map, const char *prefix,
                               char *base);

/* {match: GLOB, texel_density: N}, both required */
static lmb_status override_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index)
{
    lmb_density_override *o = (lmb_density_override *)(void *)(base + k->offset) + index;
    memset(o, 0, sizeof *o); /* empty pattern, density 0: both invalid, so "missing" shows */
    if (item->type != YAML_MAPPING_NODE)
        return lmb_cfg_bad_value(c, k, item, "a mapping {match: GLOB, texel_density: N}");
    lmb_status st = walk_mapping(c, &override_schema, item, k->path, (char *)o);
    if (st == LMB_OK && (!o->pattern[0] || !(o->texel_density > 0)))
        return lmb_cfg_key_error(c, item, k->path, "each entry needs both match and texel_density");
    return st;
}

static lmb_status material_override_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base,
                                         uint32_t index)
{
    lmb_material_override *o = (lmb_material_override *)(void *)(base + k->offset) + index;
    memset(o, 0, sizeof *o);
    o->albedo[0] = o->albedo[1] = o->albedo[2] = -1; /* keep the file's */
    o->emissive[0] = o->emissive[1] = o->emissive[2] = -1;
    if (item->type != YAML_MAPPING_NODE)
        return lmb_cfg_bad_value(c, k, item, "a mapping {match: GLOB, albedo: [r, g, b], emissive: [r, g, b]}");
    lmb_status st = walk_mapping(c, &material_override_schema, item, k->path, (char *)o);
    if (st == LMB_OK && (!o->pattern[0] || (o->albedo[0] < 0 && o->emissive[0] < 0)))
        return lmb_cfg_key_error(c, item, k->path, "each entry needs match and at least one of albedo and emissive");
    return st;
}

static lmb_status set_material_overrides(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count = 0;
    lmb_status st = lmb_cfg_each_item(c, k, n, base, material_override_item, &count);
    return lmb_cfg_set_count(k, base, count, st);
}

/* {match: GLOB, mode: baked | indirect | realtime}, both required */
static lmb_status light_mode_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index)
{
    lmb_light_mode_rule *o = (lmb_light_mode_rule *)(void *)(base + k->offset) + index;
    memset(o, 0, sizeof *o);
    o->mode = -1;
    if (item->type != YAML_MAPPING_NODE)
        return lmb_cfg_bad_value(c, k, item, "a mapping {match: GLOB, mode: baked | indirect | realtime}");
    lmb_status st = walk_mapping(c, &light_mode_schema, item, k->path, (char *)o);
    if (st == LMB_OK && (!o->pattern[0] || o->mode < 0))
        return lmb_cfg_key_error(c, item, k->path, "each entry needs both match and mode");
    return st;
}

static lmb_status set_light_modes(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count = 0;
    lmb_status st = lmb_cfg_each_item(c, k, n, base, light_mode_item, &count);
    return lmb_cfg_set_count(k, base, count, st);
}

/* {name: NAME, match: GLOB, sky: BOOL, emissive: BOOL, scale: S}: name required (letters, digits,
 * '_', '-'; the group's files carry it), unique; scale 1 unless given. Or {match: GLOB,
 * one_per_light: true, scale: S}: a group per light it matches, and without match the sky's and
 * the emissive surfaces' (lights/light_groups.h names them). */
static lmb_status light_group_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index)
{
    lmb_light_group_spec *all = (lmb_light_group_spec *)(void *)(base + k->offset), *o = all + index;
    memset(o, 0, sizeof *o);
    o->scale = 1;
    o->line = (uint32_t)lmb_cfg_line_of(item);
    if (item->type != YAML_MAPPING_NODE)
        return lmb_cfg_bad_value(c, k, item, "a mapping {name: NAME, match: GLOB, sky: BOOL, emissive: BOOL, scale: S}");
    lmb_status st = walk_mapping(c, &light_group_schema, item, k->path, (char *)o);
    if (st == LMB_OK && o->one_per_light && (o->name[0] || o->sky || o->emissive))
        return lmb_cfg_key_error(c, item, k->path, "one_per_light: true names its groups after its lights: no name, sky "
                                 "or emissive with it (without match it gives the sky and the emissive "
                                 "surfaces groups of their own too)");
    if (st == LMB_OK && !o->name[0] && !o->one_per_light)
        return lmb_cfg_key_error(c, item, k->path, "each entry needs a name (or one_per_light: true)");
    for (const char *p = o->name; st == LMB_OK && *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '_' || *p == '-'))
            return lmb_cfg_key_error(c, item, k->path, "name '%s': letters, digits, '_' and '-' only (it names the "
                                     "group's files)", o->name);
    for (uint32_t j = 0; st == LMB_OK && o->name[0] && j < index; j++)
        if (!strcmp(all[j].name, o->name))
            return lmb_cfg_key_error(c, item, k->path, "name '%s' is given twice (lines %u and %u)", o->name,
                                     all[j].line, o->line);
    return st;
}

static lmb_status set_light_groups(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count = 0;
    lmb_status st = lmb_cfg_each_item(c, k, n, base, light_group_item, &count);
    return lmb_cfg_set_count(k, base, count, st);
}

/* {min: [x, y, z], max: [x, y, z], resolution: [x, y, z]}, all required, min < max */
static lmb_status probe_volume_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base,
                                    uint32_t index)
{
    lmb_probe_volume_spec *o = (lmb_probe_volume_spec *)(void *)(base + k->offset) + index;
    memset(o, 0, sizeof *o); /* resolution 0: missing shows */
    o->min[0] = o->max[0] = NAN;
    if (item->type != YAML_MAPPING_NODE)
        return lmb_cfg_bad_value(c, k, item, "a mapping {min: [x, y, z], max: [x, y, z], resolution: [x, y, z]}");
    lmb_status st = walk_mapping(c, &probe_volume_schema, item, k->path, (char *)o);
    if (st == LMB_OK && (isnan(o->min[0]) || isnan(o->max[0]) || !o->resolution[0]))
        return lmb_cfg_key_error(c, item, k->path, "each entry needs min, max and resolution");
    for (int a = 0; st == LMB_OK && a < 3; a++)
        if (!(o->min[a] < o->max[a]))
            return lmb_cfg_key_error(c, item, k->path, "min %g is not below max %g on the %c axis", o->min[a],
                                     o->max[a], "xyz"[a]);
    return st;
}

static lmb_status set_probe_volumes(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count = 0;
    lmb_status st = lmb_cfg_each_item(c, k, n, base, probe_volume_item, &count);
    return lmb_cfg_set_count(k, base, count, st);
}

static lmb_status set_overrides(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count = 0;
    lmb_status st = lmb_cfg_each_item(c, k, n, base, override_item, &count); /* before count is read: argument order is unspecified */
    return lmb_cfg_set_count(k, base, count, st);
}


/* ---- mappings ----------------------------------------------------------------- */

static const key_spec *find_key(const schema *s, const char *path)
{
    for (size_t i = 0; i < s->count; i++)
        if (!strcmp(s->keys[i].path, path))
            return &s->keys[i];
    return NULL;
}

/* A section is a path that some key's path continues with '.'. */
static int is_section(const schema *s, const char *path)
{
    size_t len = strlen(path);
    for (size_t i = 0; i < s->count; i++)
        if (!strncmp(s->keys[i].path, path, len) && s->keys[i].path[len] == '.')
            return 1;
    return 0;
}

/* The name after "prefix." in key i's path (up to the next '.'), or 0 if not under prefix. */
static size_t child_name(const schema *s, size_t i, const char *prefix, const char **name)
{
    const char *p = s->keys[i].path;
    size_t plen = strlen(prefix);
    if (plen && (strncmp(p, prefix, plen) || p[plen] != '.'))
        return 0;
    *name = p + (plen ? plen + 1 : 0);
    return strcspn(*name, ".");
}

/* "max_size, padding, keep_uv1": the names directly under prefix, each once. */
static void known_names(const schema *s, const char *prefix, char *out, size_t size)
{
    size_t len = 0;
    out[0] = '\0';
    for (size_t i = 0; i < s->count && len < size; i++) {
        const char *name, *prev;
        size_t n = child_name(s, i, prefix, &name), j;
        for (j = 0; n && j < i; j++)
            if (child_name(s, j, prefix, &prev) == n && !strncmp(prev, name, n))
                break;
        if (n && j == i)
            len += (size_t)snprintf(out + len, size - len, "%s%.*s", len ? ", " : "", (int)n, name);
    }
}

static lmb_status unknown_key(parse_ctx *c, const schema *s, const yaml_node_t *kn, const char *prefix,
                              const char *path)
{
    char known[512];
    known_names(s, prefix, known, sizeof known);
    if (!*prefix)
        return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: unknown key '%s' (known keys: %s)", c->file,
                             lmb_cfg_line_of(kn), path, known);
    return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: unknown key '%s' (known keys under '%s': %s)", c->file,
                         lmb_cfg_line_of(kn), path, prefix, known);
}

/* The pair's dotted path into out; keys must be scalars. */
static lmb_status key_path(parse_ctx *c, const yaml_node_t *kn, const char *prefix, char *out, size_t size)
{
    const char *name = lmb_cfg_scalar(kn);
    if (!name)
        return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: a key must be a plain name, not %s%s%s%s", c->file,
                             lmb_cfg_line_of(kn), kn->type == YAML_SEQUENCE_NODE ? "a list" : "a mapping",
                             *prefix ? " (under '" : "", prefix, *prefix ? "')" : "");
    snprintf(out, size, "%s%s%s", prefix, *prefix ? "." : "", name);
    return LMB_OK;
}

/* A key given twice in one mapping is an error (libyaml keeps both). */
static lmb_status check_duplicate(parse_ctx *c, const yaml_node_t *map, const yaml_node_pair_t *p, const char *path)
{
    const yaml_node_t *kn = lmb_cfg_node(c, p->key);
    for (const yaml_node_pair_t *q = map->data.mapping.pairs.start; q < p; q++) {
        const yaml_node_t *qn = lmb_cfg_node(c, q->key);
        if (lmb_cfg_scalar(qn) && !strcmp(lmb_cfg_scalar(qn), lmb_cfg_scalar(kn)))
            return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: key '%s' is given twice (first on line %zu)", c->file,
                                 lmb_cfg_line_of(kn), path, lmb_cfg_line_of(qn));
    }
    return LMB_OK;
}

static lmb_status walk_section(parse_ctx *c, const schema *s, const yaml_node_t *vn, const char *path, char *base)
{
    if (lmb_cfg_is_null(vn))
        return LMB_OK; /* "atlas:" with nothing under it */
    if (vn->type != YAML_MAPPING_NODE) {
        char got[128];
        lmb_cfg_describe_got(vn, got, sizeof got);
        return lmb_cfg_key_error(c, vn, path, "expected a mapping of keys, got %s", got);
    }
    return walk_mapping(c, s, vn, path, base);
}

static lmb_status walk_pair(parse_ctx *c, const schema *s, const yaml_node_t *map, const yaml_node_pair_t *p,
                            const char *prefix, char *base)
{
    const yaml_node_t *kn = lmb_cfg_node(c, p->key), *vn = lmb_cfg_node(c, p->value);
    char path[256];
    lmb_status st = key_path(c, kn, prefix, path, sizeof path);
    if (st == LMB_OK)
        st = check_duplicate(c, map, p, path);
    if (st != LMB_OK)
        return st;
    if (is_section(s, path))
        return walk_section(c, s, vn, path, base);
    const key_spec *k = find_key(s, path);
    if (!k)
        return unknown_key(c, s, kn, prefix, path);
    return k->set(c, k, vn, base);
}

static lmb_status walk_mapping(parse_ctx *c, const schema *s, const yaml_node_t *map, const char *prefix,
                               char *base)
{
    for (const yaml_node_pair_t *p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top; p++) {
        lmb_status st = walk_pair(c, s, map, p, prefix, base);
        if (st != LMB_OK)
            return st;
    }
    return LMB_OK;
}

/* ---- the document -------------------------------------------------------------- */

/* 1-based line of a byte offset (libyaml's reader errors give only the offset). */
static size_t line_at(const char *text, size_t length, size_t offset)
{
    size_t line = 1;
    for (size_t i = 0; i < offset && i < length; i++)
        line += text[i] == '\n';
    return line;
}

static lmb_status yaml_error(const char *name, const yaml_parser_t *p, const char *text, size_t length,
                             lmb_error *err)
{
    if (p->error == YAML_MEMORY_ERROR)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory reading the YAML", name);
    size_t line = p->error == YAML_READER_ERROR ? line_at(text, length, p->problem_offset) : p->problem_mark.line + 1;
    const char *problem = p->problem ? p->problem : "unreadable YAML";
    if (strstr(problem, "undefined alias")) /* *Floor reads as an alias */
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "%s:%zu: YAML syntax error: %s (put a glob that starts with * in quotes)", name, line,
                             problem);
    if (p->context)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s:%zu: YAML syntax error: %s (%s at line %zu)", name, line,
                             problem, p->context, p->context_mark.line + 1);
    return lmb_error_set(err, LMB_ERR_INPUT, "%s:%zu: YAML syntax error: %s", name, line, problem);
}

/* Loads the first document into doc and checks that no second one follows. On error
 * nothing is left to delete. */
static lmb_status load_document(const char *name, yaml_parser_t *p, const char *text, size_t length,
                                yaml_document_t *doc, lmb_error *err)
{
    yaml_document_t next;
    if (!yaml_parser_load(p, doc))
        return yaml_error(name, p, text, length, err);
    if (!yaml_parser_load(p, &next)) {
        yaml_document_delete(doc);
        return yaml_error(name, p, text, length, err);
    }
    const yaml_node_t *root = yaml_document_get_root_node(&next);
    size_t line = next.start_mark.line + 1;
    int second = root && !lmb_cfg_is_null(root);
    yaml_document_delete(&next);
    if (second) {
        yaml_document_delete(doc);
        return lmb_error_set(err, LMB_ERR_INPUT, "%s:%zu: a second YAML document starts here; a config is one mapping",
                             name, line);
    }
    return LMB_OK;
}

static lmb_status apply_root(parse_ctx *c, const yaml_node_t *root, lmb_config *cfg)
{
    if (!root || lmb_cfg_is_null(root))
        return LMB_OK; /* empty file or only comments: the defaults */
    if (root->type != YAML_MAPPING_NODE) {
        char got[128];
        lmb_cfg_describe_got(root, got, sizeof got);
        return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: the config must be a mapping of keys (key: value), got %s",
                             c->file, lmb_cfg_line_of(root), got);
    }
    return walk_mapping(c, &config_schema, root, "", (char *)cfg);
}

lmb_status lmb_config_parse(const char *name, const char *text, size_t length, lmb_config *cfg, lmb_error *err)
{
    yaml_parser_t parser;
    yaml_document_t doc;
    if (!name)
        name = "config";
    if (!text) {
        text = "";
        length = 0;
    }
    if (!yaml_parser_initialize(&parser))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot start the YAML parser", name);
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, length);
    lmb_status st = load_document(name, &parser, text, length, &doc, err);
    double intensity_before = cfg->sky_intensity;
    if (st == LMB_OK) {
        parse_ctx c = {name, &doc, err};
        cfg->sky_intensity = NAN; /* stays NaN when the config does not set it */
        st = apply_root(&c, yaml_document_get_root_node(&doc), cfg);
        yaml_document_delete(&doc);
    }
    /* sky.image without sky.intensity: the map's own radiance (intensity 1), not no sky */
    if (isnan(cfg->sky_intensity))
        cfg->sky_intensity = st == LMB_OK && cfg->sky_image[0] && intensity_before == 0 ? 1 : intensity_before;
    if (st == LMB_OK && cfg->ic_min_spacing > cfg->ic_max_spacing)
        st = lmb_error_set(err, LMB_ERR_INPUT,
                           "%s: irradiance_cache.min_spacing (%g) is larger than irradiance_cache.max_spacing (%g)",
                           name, cfg->ic_min_spacing, cfg->ic_max_spacing);
    yaml_parser_delete(&parser);
    return st;
}

lmb_status lmb_config_load(const char *path, lmb_config *cfg, lmb_error *err)
{
    char *buf;
    size_t n;
    lmb_status st = lmb_read_file(path, "config", &buf, &n, err);
    if (st != LMB_OK)
        return st;
    st = lmb_config_parse(path, buf, n, cfg, err);
    free(buf);
    snprintf(cfg->config_path, sizeof cfg->config_path, "%s", path);
    return st;
}
