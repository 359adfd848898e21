/*
 * The per-level bake config: YAML read with libyaml's document API (which keeps each
 * node's line), checked against one schema table. Every key is optional; its default is
 * set by lmb_config_default (and documented in docs/config.md and
 * assets/example-config.yaml). Unknown keys, duplicate keys, wrong types and values out of
 * range are LMB_ERR_INPUT naming "file:line: key 'a.b'". On error cfg may be partly
 * updated; callers discard it.
 */
#include <lmbake/lmbake.h>

#include "../util/file.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

typedef enum kind {
    K_DOUBLE, K_U32, K_U64, K_BOOL, K_METHOD, K_FORMATS, K_INCLUDE, K_EXCLUDE, K_WORD, K_OVERRIDES
} kind;

typedef struct key_spec {
    const char *path;
    kind kind;
    double min, max;
    int min_exclusive; /* value must be > min */
    size_t offset;
} key_spec;

#define OFF(f) offsetof(lmb_config, f)
static const key_spec keys[] = {
    {"texel_density", K_DOUBLE, 0, 100000, 1, OFF(texel_density)},
    {"density_overrides", K_OVERRIDES, 0, 0, 0, 0},
    {"atlas.max_size", K_U32, 16, 16384, 0, OFF(max_atlas_size)},
    {"atlas.padding", K_U32, 0, 64, 0, OFF(padding)},
    {"atlas.keep_uv1", K_BOOL, 0, 1, 0, OFF(keep_uv1)},
    {"samples.texel", K_U32, 1, 256, 0, OFF(texel_samples)},
    {"samples.direct", K_U32, 1, 65536, 0, OFF(direct_samples)},
    {"samples.gather", K_U32, 1, 1048576, 0, OFF(gather_rays)},
    {"samples.amis_iterations", K_U32, 1, 64, 0, OFF(amis_iterations)},
    {"bounces", K_U32, 0, 64, 0, OFF(bounces)},
    {"gather.method", K_METHOD, 0, 0, 0, OFF(gather_method)},
    {"gather.defensive", K_DOUBLE, 0, 0.999, 0, OFF(defensive_fraction)},
    {"seed", K_U64, 0, 9.2233720368547758e18, 0, OFF(seed)},
    {"threads", K_U32, 0, 1024, 0, OFF(threads)},
    {"output.formats", K_FORMATS, 0, 0, 0, OFF(output_formats)},
    {"lightmap.include", K_INCLUDE, 0, 0, 0, 0},
    {"lightmap.exclude", K_EXCLUDE, 0, 0, 0, 0},
    {"lightmap.extras_key", K_WORD, 0, 0, 0, OFF(extras_key)},
    {"lights.intensity_scale", K_DOUBLE, 0, 1e9, 0, OFF(light_intensity_scale)},
    {"lights.emissive_scale", K_DOUBLE, 0, 1e9, 0, OFF(emissive_scale)},
};
static const char *const sections[] = {"atlas", "samples", "gather", "output", "lightmap", "lights"};
static const char *const methods[] = {"cosine", "amis", "amis_defensive"};

void lmb_config_default(lmb_config *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->texel_density = 8.0;
    cfg->max_atlas_size = 1024;
    cfg->padding = 2;
    cfg->keep_uv1 = 0;
    cfg->texel_samples = 4;
    cfg->direct_samples = 16;
    cfg->gather_rays = 256;
    cfg->amis_iterations = 4;
    cfg->bounces = 2;
    cfg->gather_method = LMB_GATHER_AMIS_DEFENSIVE;
    cfg->defensive_fraction = 0.1;
    cfg->seed = 1;
    cfg->threads = 0;
    cfg->output_formats = LMB_OUTPUT_EXR | LMB_OUTPUT_HDR | LMB_OUTPUT_PNG;
    snprintf(cfg->include[0], LMB_PATTERN_LEN, "*");
    cfg->include_count = 1;
    snprintf(cfg->extras_key, LMB_PATTERN_LEN, "lightmap");
    cfg->light_intensity_scale = 1.0;
    cfg->emissive_scale = 1.0;
}

typedef struct parse_ctx {
    const char *file;
    yaml_document_t *doc;
    lmb_config *cfg;
    lmb_error *err;
    char seen[64][160];/* key paths already set: duplicates are errors */
    unsigned seen_count;
} parse_ctx;

static unsigned line_of(const yaml_node_t *n)
{
    return (unsigned)n->start_mark.line + 1;
}

static lmb_status fail(parse_ctx *c, const yaml_node_t *n, const char *path, const char *fmt, const char *detail)
{
    char what[512];
    snprintf(what, sizeof what, fmt, detail);
    return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%u: key '%s': %s", c->file, line_of(n), path, what);
}

static const char *scalar(const yaml_node_t *n)
{
    return n && n->type == YAML_SCALAR_NODE ? (const char *)n->data.scalar.value : NULL;
}

static lmb_status expect_scalar(parse_ctx *c, const yaml_node_t *n, const char *path, const char *expected,
                                const char **out)
{
    *out = scalar(n);
    if (!*out)
        return fail(c, n, path, "expected %s, got a list or mapping", expected);
    return LMB_OK;
}

/* Parses a number into dst (a double, uint32_t or uint64_t as k->kind says). */
static lmb_status set_number(parse_ctx *c, const key_spec *k, const yaml_node_t *n, void *dst)
{
    const char *s;
    char range[128], *end;
    int integer = k->kind != K_DOUBLE;
    if (integer)
        snprintf(range, sizeof range, "expected an integer in %.0f..%.0f, got '%%s'", k->min, k->max);
    else
        snprintf(range, sizeof range, "expected a number %s %g and <= %g, got '%%s'", k->min_exclusive ? ">" : ">=", k->min,
                 k->max);
    lmb_status st = expect_scalar(c, n, k->path, integer ? "an integer" : "a number", &s);
    if (st != LMB_OK)
        return st;
    errno = 0;
    double v;
    if (integer) {
        if (*s == '-' && strcmp(s, "-0") != 0)
            return fail(c, n, k->path, range, s);
        unsigned long long u = strtoull(s, &end, 10);
        if (end == s || *end || errno || (double)u > k->max || (double)u < k->min)
            return fail(c, n, k->path, range, s);
        if (k->kind == K_U64)
            *(uint64_t *)dst = (uint64_t)u;
        else
            *(uint32_t *)dst = (uint32_t)u;
        return LMB_OK;
    }
    v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v) || v > k->max || v < k->min || (k->min_exclusive && v <= k->min))
        return fail(c, n, k->path, range, s);
    *(double *)dst = v;
    return LMB_OK;
}

static int ieq(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return 0;
    return *a == *b;
}

static lmb_status set_bool(parse_ctx *c, const key_spec *k, const yaml_node_t *n)
{
    const char *s;
    lmb_status st = expect_scalar(c, n, k->path, "true or false", &s);
    if (st != LMB_OK)
        return st;
    int *dst = (int *)((char *)c->cfg + k->offset);
    if (ieq(s, "true") || ieq(s, "yes") || ieq(s, "on"))
        *dst = 1;
    else if (ieq(s, "false") || ieq(s, "no") || ieq(s, "off"))
        *dst = 0;
    else
        return fail(c, n, k->path, "expected true or false, got '%s'", s);
    return LMB_OK;
}

static lmb_status set_method(parse_ctx *c, const key_spec *k, const yaml_node_t *n)
{
    const char *s;
    lmb_status st = expect_scalar(c, n, k->path, "a gather method", &s);
    if (st != LMB_OK)
        return st;
    for (size_t i = 0; i < sizeof methods / sizeof *methods; i++)
        if (!strcmp(s, methods[i])) {
            c->cfg->gather_method = (lmb_gather_method)i;
            return LMB_OK;
        }
    return fail(c, n, k->path, "expected one of cosine, amis, amis_defensive, got '%s'", s);
}

static lmb_status set_word(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *dst)
{
    const char *s;
    lmb_status st = expect_scalar(c, n, k->path, "a string", &s);
    if (st != LMB_OK)
        return st;
    if (!*s || strlen(s) >= LMB_PATTERN_LEN) {
        char detail[32];
        snprintf(detail, sizeof detail, "%d", LMB_PATTERN_LEN - 1);
        return fail(c, n, k->path, "expected a non-empty string of at most %s characters", detail);
    }
    memcpy(dst, s, strlen(s) + 1);
    return LMB_OK;
}

/* A sequence of scalars (or one scalar) visited one by one. */
typedef lmb_status (*item_fn)(parse_ctx *c, const key_spec *k, const yaml_node_t *item, unsigned index);

static lmb_status for_each_item(parse_ctx *c, const key_spec *k, const yaml_node_t *n, item_fn fn, unsigned *count)
{
    *count = 0;
    if (n->type == YAML_SCALAR_NODE && n->data.scalar.length > 0)
        return fn(c, k, n, (*count)++);
    if (n->type == YAML_SCALAR_NODE)
        return LMB_OK; /* "key:" with nothing: an empty list */
    if (n->type != YAML_SEQUENCE_NODE)
        return fail(c, n, k->path, "expected a list, got a mapping%s", "");
    for (yaml_node_item_t *it = n->data.sequence.items.start; it < n->data.sequence.items.top; it++) {
        if (*count >= LMB_MAX_PATTERNS) {
            char detail[16];
            snprintf(detail, sizeof detail, "%d", LMB_MAX_PATTERNS);
            return fail(c, n, k->path, "at most %s entries", detail);
        }
        lmb_status st = fn(c, k, yaml_document_get_node(c->doc, *it), (*count)++);
        if (st != LMB_OK)
            return st;
    }
    return LMB_OK;
}

static lmb_status format_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, unsigned index)
{
    static const char *const names[] = {"exr", "hdr", "png"};
    const char *s;
    (void)index;
    lmb_status st = expect_scalar(c, item, k->path, "exr, hdr or png", &s);
    if (st != LMB_OK)
        return st;
    for (unsigned i = 0; i < 3; i++)
        if (!strcmp(s, names[i])) {
            c->cfg->output_formats |= 1u << i;
            return LMB_OK;
        }
    return fail(c, item, k->path, "expected exr, hdr or png, got '%s'", s);
}

static lmb_status include_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, unsigned index)
{
    return set_word(c, k, item, c->cfg->include[index]);
}

static lmb_status exclude_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, unsigned index)
{
    return set_word(c, k, item, c->cfg->exclude[index]);
}

/* density_overrides: - {match: "Floor*", texel_density: 16} */
static lmb_status override_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, unsigned index)
{
    static const key_spec density = {"density_overrides.texel_density", K_DOUBLE, 0, 100000, 1, 0};
    static const key_spec match = {"density_overrides.match", K_WORD, 0, 0, 0, 0};
    lmb_density_override *o = &c->cfg->density_overrides[index];
    if (item->type != YAML_MAPPING_NODE)
        return fail(c, item, k->path, "each entry is a mapping {match: GLOB, texel_density: N}%s", "");
    int have_match = 0, have_density = 0;
    for (yaml_node_pair_t *p = item->data.mapping.pairs.start; p < item->data.mapping.pairs.top; p++) {
        const yaml_node_t *kn = yaml_document_get_node(c->doc, p->key), *vn = yaml_document_get_node(c->doc, p->value);
        const char *name = scalar(kn);
        lmb_status st;
        if (name && !strcmp(name, "match")) {
            st = set_word(c, &match, vn, o->pattern);
            have_match = 1;
        } else if (name && !strcmp(name, "texel_density")) {
            st = set_number(c, &density, vn, &o->texel_density);
            have_density = 1;
        } else {
            return lmb_error_set(c->err, LMB_ERR_INPUT,
                                 "%s:%u: unknown key 'density_overrides.%s' (known keys: match, texel_density)", c->file,
                                 line_of(kn), name ? name : "?");
        }
        if (st != LMB_OK)
            return st;
    }
    if (!have_match || !have_density)
        return fail(c, item, k->path, "each entry needs both match and texel_density%s", "");
    return LMB_OK;
}

static lmb_status set_value(parse_ctx *c, const key_spec *k, const yaml_node_t *n)
{
    unsigned count;
    lmb_status st;
    switch (k->kind) {
    case K_DOUBLE: case K_U32: case K_U64:
        return set_number(c, k, n, (char *)c->cfg + k->offset);
    case K_BOOL:
        return set_bool(c, k, n);
    case K_METHOD:
        return set_method(c, k, n);
    case K_WORD:
        return set_word(c, k, n, (char *)c->cfg + k->offset);
    case K_FORMATS:
        c->cfg->output_formats = 0;
        st = for_each_item(c, k, n, format_item, &count);
        if (st == LMB_OK && !c->cfg->output_formats)
            return fail(c, n, k->path, "name at least one output format (exr, hdr, png)%s", "");
        return st;
    case K_INCLUDE:
        st = for_each_item(c, k, n, include_item, &count);
        c->cfg->include_count = count;
        return st;
    case K_EXCLUDE:
        st = for_each_item(c, k, n, exclude_item, &count);
        c->cfg->exclude_count = count;
        return st;
    case K_OVERRIDES:
        st = for_each_item(c, k, n, override_item, &count);
        c->cfg->density_override_count = count;
        return st;
    }
    return LMB_OK;
}

static int is_section(const char *name)
{
    for (size_t i = 0; i < sizeof sections / sizeof *sections; i++)
        if (!strcmp(name, sections[i]))
            return 1;
    return 0;
}

static lmb_status unknown_key(parse_ctx *c, const yaml_node_t *kn, const char *prefix, const char *path)
{
    char known[512] = "";
    size_t plen = strlen(prefix);
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++) {
        const char *p = keys[i].path;
        if (plen ? (!strncmp(p, prefix, plen) && p[plen] == '.') : !strchr(p, '.')) {
            size_t len = strlen(known);
            snprintf(known + len, sizeof known - len, "%s%s", len ? ", " : "", p + (plen ? plen + 1 : 0));
        }
    }
    if (!plen)
        for (size_t i = 0; i < sizeof sections / sizeof *sections; i++) {
            size_t len = strlen(known);
            snprintf(known + len, sizeof known - len, ", %s", sections[i]);
        }
    return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%u: unknown key '%s' (known keys%s%s%s: %s)", c->file,
                         line_of(kn), path, plen ? " under '" : "", prefix, plen ? "'" : "", known);
}

static lmb_status mark_seen(parse_ctx *c, const yaml_node_t *kn, const char *path)
{
    for (unsigned i = 0; i < c->seen_count; i++)
        if (!strcmp(c->seen[i], path))
            return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%u: key '%s' is given twice", c->file, line_of(kn), path);
    if (c->seen_count < sizeof c->seen / sizeof c->seen[0])
        snprintf(c->seen[c->seen_count++], sizeof c->seen[0], "%s", path);
    return LMB_OK;
}

static lmb_status walk_mapping(parse_ctx *c, const yaml_node_t *map, const char *prefix)
{
    for (yaml_node_pair_t *p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top; p++) {
        const yaml_node_t *kn = yaml_document_get_node(c->doc, p->key), *vn = yaml_document_get_node(c->doc, p->value);
        const char *name = scalar(kn);
        char path[160];
        if (!name)
            return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%u: keys must be plain names", c->file, line_of(kn));
        snprintf(path, sizeof path, "%s%s%s", prefix, *prefix ? "." : "", name);
        lmb_status st = mark_seen(c, kn, path);
        if (st != LMB_OK)
            return st;
        if (!*prefix && is_section(name)) {
            if (vn->type == YAML_SCALAR_NODE && vn->data.scalar.length == 0)
                continue; /* "atlas:" with nothing under it */
            if (vn->type != YAML_MAPPING_NODE)
                return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%u: key '%s': expected a mapping of keys", c->file,
                                     line_of(vn), path);
            if ((st = walk_mapping(c, vn, name)) != LMB_OK)
                return st;
            continue;
        }
        const key_spec *k = NULL;
        for (size_t i = 0; i < sizeof keys / sizeof *keys && !k; i++)
            if (!strcmp(keys[i].path, path))
                k = &keys[i];
        if (!k)
            return unknown_key(c, kn, prefix, path);
        if ((st = set_value(c, k, vn)) != LMB_OK)
            return st;
    }
    return LMB_OK;
}

lmb_status lmb_config_parse(const char *name, const char *text, size_t length, lmb_config *cfg, lmb_error *err)
{
    yaml_parser_t parser;
    yaml_document_t doc;
    if (!yaml_parser_initialize(&parser))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot start the YAML parser", name);
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, length);
    if (!yaml_parser_load(&parser, &doc)) {
        lmb_status st = lmb_error_set(err, LMB_ERR_INPUT, "%s:%u: YAML syntax error: %s%s%s", name,
                                      (unsigned)parser.problem_mark.line + 1,
                                      parser.problem ? parser.problem : "unreadable",
                                      parser.context ? " " : "", parser.context ? parser.context : "");
        yaml_parser_delete(&parser);
        return st;
    }
    lmb_status st = LMB_OK;
    yaml_node_t *root = yaml_document_get_root_node(&doc);
    parse_ctx c;
    memset(&c, 0, sizeof c);
    c.file = name;
    c.doc = &doc;
    c.cfg = cfg;
    c.err = err;
    if (root && root->type == YAML_MAPPING_NODE)
        st = walk_mapping(&c, root, "");
    else if (root && !(root->type == YAML_SCALAR_NODE && root->data.scalar.length == 0))
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s:%u: the config must be a mapping of keys (key: value)", name,
                           line_of(root));
    yaml_document_delete(&doc);
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
    return st;
}
