/*
 * Shared between the bake config's two files: config.c (the schema table, defaults, the
 * walk over YAML mappings and the document) and config_values.c (reading one YAML node
 * into one typed field: numbers, booleans, enums, strings, lists; the error messages).
 */
#ifndef LMBAKE_CONFIG_INTERNAL_H
#define LMBAKE_CONFIG_INTERNAL_H

#include <lmbake/lmbake.h>

#include <stddef.h>
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

enum { OPEN_LO = 1, OPEN_HI = 2, OPEN_NONE = 4 }; /* float ranges: '>' lo and '<' hi instead of >=, <=;
                                                    OPEN_NONE: an RGB key may be "none" */

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
    const struct schema *items; /* lists of mappings: each entry's keys (NULL: density_overrides) */
    size_t item_size;        /* lists of mappings: each entry's struct size */
};

typedef struct schema schema;
struct schema {
    const key_spec *keys;
    size_t count;
};

/* The schema tables (config.c), for the writer (config_write.c). */
const schema *lmb_cfg_schema(void);
const schema *lmb_cfg_override_schema(void);

/* Nodes and messages (config_values.c). */
size_t lmb_cfg_line_of(const yaml_node_t *n);
const yaml_node_t *lmb_cfg_node(const parse_ctx *c, int id);
const char *lmb_cfg_scalar(const yaml_node_t *n);                         /* NULL for a list or mapping */
int lmb_cfg_is_null(const yaml_node_t *n);                                /* nothing, ~ or null, unquoted */
void lmb_cfg_describe_got(const yaml_node_t *n, char *out, size_t size);  /* for "got ..." */
void lmb_cfg_join_names(const char *const *names, char *out, size_t size); /* "a, b, c" */
/* "FILE:LINE: key 'PATH': WHAT" */
lmb_status lmb_cfg_key_error(parse_ctx *c, const yaml_node_t *n, const char *path, const char *fmt, ...)
    LMB_PRINTF(4, 5);
/* "... expected WANT, got WHAT-N-IS" */
lmb_status lmb_cfg_bad_value(parse_ctx *c, const key_spec *k, const yaml_node_t *n, const char *want);

/* Setters: read n into base + k->offset, or fail naming k->path. */
lmb_status lmb_cfg_set_float(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
lmb_status lmb_cfg_set_float_or_auto(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base); /* auto = 0 */
lmb_status lmb_cfg_set_u32(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
lmb_status lmb_cfg_set_u32_or_auto(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base); /* auto = LMB_AUTO */
lmb_status lmb_cfg_set_u64(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
lmb_status lmb_cfg_set_u64_or_auto(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base); /* auto = 0 */
lmb_status lmb_cfg_set_bool(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
lmb_status lmb_cfg_set_enum(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
lmb_status lmb_cfg_set_flags(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
lmb_status lmb_cfg_set_string(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
lmb_status lmb_cfg_set_globs(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
/* [r, g, b], each in the key's float range; with OPEN_NONE also "none" (stored as -1, -1, -1) */
lmb_status lmb_cfg_set_rgb(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
/* [x, y, z], finite, not all 0 (stored as given: users normalize) */
lmb_status lmb_cfg_set_direction(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
/* [x, y, z], finite (a point) */
lmb_status lmb_cfg_set_point(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
/* [x, y, z], integers in the key's integer range (stored as 3 uint32_t) */
lmb_status lmb_cfg_set_u32x3(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);
/* a relative path of at most LMB_PATTERN_LEN - 1 characters, or "" for none */
lmb_status lmb_cfg_set_path(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base);

/* Lists: each entry through fn (a null is an empty list, a lone value a list of one). */
typedef lmb_status (*lmb_cfg_item_fn)(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base,
                                      uint32_t index);
lmb_status lmb_cfg_each_item(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base, lmb_cfg_item_fn fn,
                             uint32_t *count);
/* Stores count at k->count_offset when st is LMB_OK; returns st. */
lmb_status lmb_cfg_set_count(const key_spec *k, char *base, uint32_t count, lmb_status st);

#endif
