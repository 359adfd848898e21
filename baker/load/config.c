/*
 * The per-level bake config: YAML read with libyaml's document API (it keeps every node's
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

#if defined(__GNUC__)
#define LMB_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define LMB_PRINTF(f, a)
#endif

typedef struct parse_ctx {
    const char *file;
    yaml_document_t *doc;
    lmb_error *err;
} parse_ctx;

typedef struct key_spec key_spec;

/* Reads node n into the struct at base (at k->offset), or fails naming k->path. */
typedef lmb_status (*setter_fn)(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);

enum { OPEN_LO = 1, OPEN_HI = 2 }; /* float ranges: '>' lo and '<' hi instead of >=, <= */

struct key_spec {
    const char *path; /* dotted, as in the file */
    setter_fn set;
    size_t offset;           /* of the value in the struct being filled */
    double flo, fhi;         /* floats: range */
    int open;                /* floats: OPEN_* bits */
    long long ilo, ihi;      /* integers: range */
    const char *const *names; /* enums and flag lists: NULL-terminated; index = value or bit */
    size_t count_offset;     /* lists: the uint32_t entry count */
    uint32_t max_items;      /* lists: most entries */
};

typedef struct schema {
    const key_spec *keys;
    size_t count;
} schema;

static lmb_status set_float(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_u32(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_u64(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_bool(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_enum(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_flags(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_string(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_globs(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
static lmb_status set_overrides(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);

#define OFF(f) offsetof(lmb_config, f)
#define FLOAT(p, off, lo, hi, op) {.path = p, .set = set_float, .offset = off, .flo = lo, .fhi = hi, .open = op}
#define U32(p, off, lo, hi) {.path = p, .set = set_u32, .offset = off, .ilo = lo, .ihi = hi}
#define U64(p, off, lo, hi) {.path = p, .set = set_u64, .offset = off, .ilo = lo, .ihi = hi}
#define BOOL(p, off) {.path = p, .set = set_bool, .offset = off}
#define ENUM(p, off, nm) {.path = p, .set = set_enum, .offset = off, .names = nm}
#define FLAGS(p, off, nm) {.path = p, .set = set_flags, .offset = off, .names = nm, .max_items = LMB_MAX_PATTERNS}
#define STRING(p, off) {.path = p, .set = set_string, .offset = off}
#define LIST(p, fn, off, cnt) {.path = p, .set = fn, .offset = off, .count_offset = cnt, .max_items = LMB_MAX_PATTERNS}

/* Index = lmb_gather_method value; bit i = 1 << i = LMB_OUTPUT_* */
static const char *const gather_methods[] = {"cosine", "amis", "amis_defensive", NULL};
static const char *const amis_weights[] = {"unbiased", "balance", NULL};
static const char *const output_formats[] = {"exr", "hdr", "png", "mask", NULL};
_Static_assert(LMB_GATHER_COSINE == 0 && LMB_GATHER_AMIS == 1 && LMB_GATHER_AMIS_DEFENSIVE == 2, "gather_methods");
_Static_assert(LMB_OUTPUT_EXR == 1 && LMB_OUTPUT_HDR == 2 && LMB_OUTPUT_PNG == 4 && LMB_OUTPUT_MASK == 8,
               "output_formats");

static const key_spec config_keys[] = {
    FLOAT("texel_density", OFF(texel_density), 0, 100000, OPEN_LO),
    LIST("density_overrides", set_overrides, OFF(density_overrides), OFF(density_override_count)),
    U32("atlas.max_size", OFF(max_atlas_size), 16, 16384),
    U32("atlas.padding", OFF(padding), 0, 64),
    BOOL("atlas.keep_uv1", OFF(keep_uv1)),
    U32("samples.texel", OFF(texel_samples), 1, 256),
    U32("samples.direct", OFF(direct_samples), 1, 65536),
    U32("samples.gather", OFF(gather_rays), 1, 1048576),
    U32("samples.bounce", OFF(bounce_rays), 1, 1048576),
    U32("samples.amis_iterations", OFF(amis_iterations), 1, 64),
    U32("bounces", OFF(bounces), 0, 64),
    ENUM("gather.method", OFF(gather_method), gather_methods),
    ENUM("gather.amis_weights", OFF(amis_weights), amis_weights),
    FLOAT("gather.defensive", OFF(defensive_fraction), 0, 1, OPEN_HI),
    U64("seed", OFF(seed), 0, 9223372036854775807LL),
    U32("threads", OFF(threads), 0, 1024),
    FLAGS("output.formats", OFF(output_formats), output_formats),
    LIST("lightmap.include", set_globs, OFF(include), OFF(include_count)),
    LIST("lightmap.exclude", set_globs, OFF(exclude), OFF(exclude_count)),
    STRING("lightmap.extras_key", OFF(extras_key)),
    FLOAT("lights.intensity_scale", OFF(light_intensity_scale), 0, 1e9, 0),
    FLOAT("lights.emissive_scale", OFF(emissive_scale), 0, 1e9, 0),
};

/* One density_overrides entry, filled into an lmb_density_override. */
static const key_spec override_keys[] = {
    STRING("density_overrides.match", offsetof(lmb_density_override, pattern)),
    FLOAT("density_overrides.texel_density", offsetof(lmb_density_override, texel_density), 0, 100000, OPEN_LO),
};

static const schema config_schema = {config_keys, sizeof config_keys / sizeof *config_keys};
static const schema override_schema = {override_keys, sizeof override_keys / sizeof *override_keys};

void lmb_config_default(lmb_config *cfg)
{
    memset(cfg, 0, sizeof *cfg); /* also the padding bytes, so configs compare with memcmp */
    cfg->texel_density = 8.0;
    cfg->max_atlas_size = 1024;
    cfg->padding = 2;
    cfg->keep_uv1 = 0;
    cfg->texel_samples = 4;
    cfg->direct_samples = 16;
    cfg->gather_rays = 256;
    cfg->bounce_rays = 64;
    cfg->amis_iterations = 4;
    cfg->bounces = 2;
    cfg->gather_method = LMB_GATHER_AMIS_DEFENSIVE;
    cfg->defensive_fraction = 0.1;
    cfg->seed = 1;
    cfg->threads = 0;
    cfg->output_formats = LMB_OUTPUT_EXR | LMB_OUTPUT_HDR | LMB_OUTPUT_PNG;
    strcpy(cfg->include[0], "*");
    cfg->include_count = 1;
    strcpy(cfg->extras_key, "lightmap");
    cfg->light_intensity_scale = 1.0;
    cfg->emissive_scale = 1.0;
}

/* ---- nodes and messages ---------------------------------------------------- */

static size_t line_of(const yaml_node_t *n)
{
    return n->start_mark.line + 1;
}

static const yaml_node_t *node(const parse_ctx *c, int id)
{
    return yaml_document_get_node(c->doc, id);
}

/* The scalar's text, or NULL for a list or mapping. */
static const char *scalar(const yaml_node_t *n)
{
    return n->type == YAML_SCALAR_NODE ? (const char *)n->data.scalar.value : NULL;
}

/* A plain (unquoted) YAML null: nothing after the colon, ~ or null. */
static int is_null(const yaml_node_t *n)
{
    static const char *const nulls[] = {"", "~", "null", "Null", "NULL"};
    if (n->type != YAML_SCALAR_NODE || n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE)
        return 0;
    for (size_t i = 0; i < sizeof nulls / sizeof *nulls; i++)
        if (!strcmp(scalar(n), nulls[i]))
            return 1;
    return 0;
}

/* What a node is, for "got ...": the quoted text, shortened, or its kind. */
static void describe_got(const yaml_node_t *n, char *out, size_t size)
{
    const char *s = scalar(n);
    if (!s)
        snprintf(out, size, "%s", n->type == YAML_SEQUENCE_NODE ? "a list" : "a mapping");
    else if (strlen(s) != n->data.scalar.length)
        snprintf(out, size, "a string with a NUL character");
    else if (!*s)
        snprintf(out, size, "an empty value");
    else if (strlen(s) > 60)
        snprintf(out, size, "'%.40s...' (%zu characters)", s, strlen(s));
    else
        snprintf(out, size, "'%s'", s);
}

static lmb_status key_error(parse_ctx *c, const yaml_node_t *n, const char *path, const char *fmt, ...)
    LMB_PRINTF(4, 5);

/* "FILE:LINE: key 'PATH': WHAT" */
static lmb_status key_error(parse_ctx *c, const yaml_node_t *n, const char *path, const char *fmt, ...)
{
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: key '%s': %s", c->file, line_of(n), path, what);
}

/* "expected WANT, got WHAT-N-IS" */
static lmb_status bad_value(parse_ctx *c, const key_spec *k, const yaml_node_t *n, const char *want)
{
    char got[128];
    describe_got(n, got, sizeof got);
    return key_error(c, n, k->path, "expected %s, got %s", want, got);
}

/* "cosine, amis, amis_defensive" */
static void join_names(const char *const *names, char *out, size_t size)
{
    size_t len = 0;
    out[0] = '\0';
    for (size_t i = 0; names[i] && len < size; i++)
        len += (size_t)snprintf(out + len, size - len, "%s%s", i ? ", " : "", names[i]);
}

/* ---- scalar setters --------------------------------------------------------- */

/* Decimal only: digits, sign, point, exponent (no hex, inf, nan, spaces or '_'). */
static int parse_float(const char *s, double *out)
{
    char *end;
    if (!*s || strspn(s, "0123456789+-.eE") != strlen(s))
        return 0;
    errno = 0;
    *out = strtod(s, &end);
    return *end == '\0' && errno == 0 && isfinite(*out);
}

static int float_in_range(const key_spec *k, double v)
{
    int lo_ok = (k->open & OPEN_LO) ? v > k->flo : v >= k->flo;
    int hi_ok = (k->open & OPEN_HI) ? v < k->fhi : v <= k->fhi;
    return lo_ok && hi_ok;
}

static lmb_status set_float(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    const char *s = scalar(n);
    double v;
    if (!s || !parse_float(s, &v) || !float_in_range(k, v)) {
        char want[96];
        snprintf(want, sizeof want, "a number %s %.15g and %s %.15g", (k->open & OPEN_LO) ? ">" : ">=", k->flo,
                 (k->open & OPEN_HI) ? "<" : "<=", k->fhi);
        return bad_value(c, k, n, want);
    }
    memcpy(base + k->offset, &v, sizeof v);
    return LMB_OK;
}

/* Decimal integer, optional sign, nothing after it (no fraction, exponent or spaces). */
static int parse_int(const yaml_node_t *n, long long lo, long long hi, long long *out)
{
    const char *s = scalar(n);
    char *end;
    if (!s || !(isdigit((unsigned char)s[0]) || ((s[0] == '+' || s[0] == '-') && isdigit((unsigned char)s[1]))))
        return 0;
    errno = 0;
    *out = strtoll(s, &end, 10);
    return *end == '\0' && errno == 0 && *out >= lo && *out <= hi;
}

static lmb_status bad_int(parse_ctx *c, const key_spec *k, const yaml_node_t *n)
{
    char want[96];
    snprintf(want, sizeof want, "an integer in %lld..%lld", k->ilo, k->ihi);
    return bad_value(c, k, n, want);
}

static lmb_status set_u32(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    long long v;
    if (!parse_int(n, k->ilo, k->ihi, &v))
        return bad_int(c, k, n);
    uint32_t u = (uint32_t)v;
    memcpy(base + k->offset, &u, sizeof u);
    return LMB_OK;
}

static lmb_status set_u64(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    long long v;
    if (!parse_int(n, k->ilo, k->ihi, &v))
        return bad_int(c, k, n);
    uint64_t u = (uint64_t)v;
    memcpy(base + k->offset, &u, sizeof u);
    return LMB_OK;
}

static int ieq(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return 0;
    return *a == *b;
}

/* YAML 1.1 booleans: true/false, yes/no, on/off, any case. */
static lmb_status set_bool(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    static const char *const words[] = {"false", "true", "no", "yes", "off", "on"};
    const char *s = scalar(n);
    for (size_t i = 0; s && i < sizeof words / sizeof *words; i++)
        if (ieq(s, words[i])) {
            int v = (int)(i % 2);
            memcpy(base + k->offset, &v, sizeof v);
            return LMB_OK;
        }
    return bad_value(c, k, n, "true or false");
}

/* Index of n's text in k->names, or -1. */
static int name_index(const key_spec *k, const yaml_node_t *n)
{
    const char *s = scalar(n);
    for (int i = 0; s && k->names[i]; i++)
        if (!strcmp(s, k->names[i]))
            return i;
    return -1;
}

static lmb_status bad_name(parse_ctx *c, const key_spec *k, const yaml_node_t *n)
{
    char names[256], want[300];
    join_names(k->names, names, sizeof names);
    snprintf(want, sizeof want, "one of %s", names);
    return bad_value(c, k, n, want);
}

/* Enum keys (gather.method, gather.amis_weights) are C enums of the same size. */
_Static_assert(sizeof(lmb_gather_method) == sizeof(lmb_amis_weights), "enum keys share set_enum");
static lmb_status set_enum(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    int i = name_index(k, n);
    if (i < 0)
        return bad_name(c, k, n);
    lmb_gather_method v = (lmb_gather_method)i;
    memcpy(base + k->offset, &v, sizeof v);
    return LMB_OK;
}

/* Into a char[LMB_PATTERN_LEN]: non-empty, fits with its NUL, no NUL inside. */
static lmb_status copy_string(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *dst)
{
    const char *s = scalar(n);
    if (!s || !*s || n->data.scalar.length >= LMB_PATTERN_LEN || strlen(s) != n->data.scalar.length) {
        char want[96];
        snprintf(want, sizeof want, "a non-empty string of at most %d characters", LMB_PATTERN_LEN - 1);
        return bad_value(c, k, n, want);
    }
    memcpy(dst, s, n->data.scalar.length + 1);
    return LMB_OK;
}

static lmb_status set_string(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    return copy_string(c, k, n, base + k->offset);
}

/* ---- lists ------------------------------------------------------------------ */

typedef lmb_status (*item_fn)(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index);

/* A list's entries one by one: a null is an empty list, a lone value a list of one. */
static lmb_status each_item(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base, item_fn fn,
                            uint32_t *count)
{
    *count = 0;
    if (is_null(n))
        return LMB_OK;
    if (n->type != YAML_SEQUENCE_NODE) {
        *count = 1;
        return fn(c, k, n, base, 0);
    }
    for (const yaml_node_item_t *it = n->data.sequence.items.start; it < n->data.sequence.items.top; it++) {
        const yaml_node_t *item = node(c, *it);
        if (*count >= k->max_items)
            return key_error(c, item, k->path, "expected at most %u entries, got %ld", (unsigned)k->max_items,
                             (long)(n->data.sequence.items.top - n->data.sequence.items.start));
        lmb_status st = fn(c, k, item, base, (*count)++);
        if (st != LMB_OK)
            return st;
    }
    return LMB_OK;
}

static lmb_status set_count(const key_spec *k, char *base, uint32_t count, lmb_status st)
{
    if (st == LMB_OK)
        memcpy(base + k->count_offset, &count, sizeof count);
    return st;
}

static lmb_status flag_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index)
{
    int i = name_index(k, item);
    unsigned bits;
    (void)index;
    if (i < 0)
        return bad_name(c, k, item);
    memcpy(&bits, base + k->offset, sizeof bits);
    bits |= 1u << i;
    memcpy(base + k->offset, &bits, sizeof bits);
    return LMB_OK;
}

/* A non-empty list of names, each setting bit (1 << its index). */
static lmb_status set_flags(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    unsigned zero = 0;
    uint32_t count;
    memcpy(base + k->offset, &zero, sizeof zero);
    lmb_status st = each_item(c, k, n, base, flag_item, &count);
    if (st == LMB_OK && count == 0) {
        char names[256];
        join_names(k->names, names, sizeof names);
        return key_error(c, n, k->path, "expected at least one of %s, got an empty list", names);
    }
    return st;
}

static lmb_status glob_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index)
{
    if (item->type == YAML_MAPPING_NODE) /* [?all] reads as a mapping */
        return key_error(c, item, k->path, "expected a glob, got a mapping (put a glob that starts with ? in quotes)");
    return copy_string(c, k, item, base + k->offset + (size_t)index * LMB_PATTERN_LEN);
}

/* Into char[LMB_MAX_PATTERNS][LMB_PATTERN_LEN] and its count; replaces the default. */
static lmb_status set_globs(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count;
    return set_count(k, base, count, each_item(c, k, n, base, glob_item, &count));
}

static lmb_status walk_mapping(parse_ctx *c, const schema *s, const yaml_node_t *map, const char *prefix,
                               char *base);

/* {match: GLOB, texel_density: N}, both required */
static lmb_status override_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index)
{
    lmb_density_override *o = (lmb_density_override *)(void *)(base + k->offset) + index;
    memset(o, 0, sizeof *o); /* empty pattern, density 0: both invalid, so "missing" shows */
    if (item->type != YAML_MAPPING_NODE)
        return bad_value(c, k, item, "a mapping {match: GLOB, texel_density: N}");
    lmb_status st = walk_mapping(c, &override_schema, item, k->path, (char *)o);
    if (st == LMB_OK && (!o->pattern[0] || !(o->texel_density > 0)))
        return key_error(c, item, k->path, "each entry needs both match and texel_density");
    return st;
}

static lmb_status set_overrides(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count;
    return set_count(k, base, count, each_item(c, k, n, base, override_item, &count));
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
                             line_of(kn), path, known);
    return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: unknown key '%s' (known keys under '%s': %s)", c->file,
                         line_of(kn), path, prefix, known);
}

/* The pair's dotted path into out; keys must be scalars. */
static lmb_status key_path(parse_ctx *c, const yaml_node_t *kn, const char *prefix, char *out, size_t size)
{
    const char *name = scalar(kn);
    if (!name)
        return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: a key must be a plain name, not %s%s%s%s", c->file,
                             line_of(kn), kn->type == YAML_SEQUENCE_NODE ? "a list" : "a mapping",
                             *prefix ? " (under '" : "", prefix, *prefix ? "')" : "");
    snprintf(out, size, "%s%s%s", prefix, *prefix ? "." : "", name);
    return LMB_OK;
}

/* A key given twice in one mapping is an error (libyaml keeps both). */
static lmb_status check_duplicate(parse_ctx *c, const yaml_node_t *map, const yaml_node_pair_t *p, const char *path)
{
    const yaml_node_t *kn = node(c, p->key);
    for (const yaml_node_pair_t *q = map->data.mapping.pairs.start; q < p; q++) {
        const yaml_node_t *qn = node(c, q->key);
        if (scalar(qn) && !strcmp(scalar(qn), scalar(kn)))
            return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: key '%s' is given twice (first on line %zu)", c->file,
                                 line_of(kn), path, line_of(qn));
    }
    return LMB_OK;
}

static lmb_status walk_section(parse_ctx *c, const schema *s, const yaml_node_t *vn, const char *path, char *base)
{
    if (is_null(vn))
        return LMB_OK; /* "atlas:" with nothing under it */
    if (vn->type != YAML_MAPPING_NODE) {
        char got[128];
        describe_got(vn, got, sizeof got);
        return key_error(c, vn, path, "expected a mapping of keys, got %s", got);
    }
    return walk_mapping(c, s, vn, path, base);
}

static lmb_status walk_pair(parse_ctx *c, const schema *s, const yaml_node_t *map, const yaml_node_pair_t *p,
                            const char *prefix, char *base)
{
    const yaml_node_t *kn = node(c, p->key), *vn = node(c, p->value);
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
    int second = root && !is_null(root);
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
    if (!root || is_null(root))
        return LMB_OK; /* empty file or only comments: the defaults */
    if (root->type != YAML_MAPPING_NODE) {
        char got[128];
        describe_got(root, got, sizeof got);
        return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: the config must be a mapping of keys (key: value), got %s",
                             c->file, line_of(root), got);
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
    if (st == LMB_OK) {
        parse_ctx c = {name, &doc, err};
        st = apply_root(&c, yaml_document_get_root_node(&doc), cfg);
        yaml_document_delete(&doc);
    }
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
