/*
 * The bake config's values: one YAML node into one typed field of lmb_config (see
 * config_internal.h), with the "FILE:LINE: key 'a.b': expected ..., got '...'" messages.
 * Numbers are decimal only; "auto" is accepted where the schema says so.
 */
#include "config_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- nodes and messages ---------------------------------------------------- */

size_t lmb_cfg_line_of(const yaml_node_t *n)
{
    return n->start_mark.line + 1;
}

const yaml_node_t *lmb_cfg_node(const parse_ctx *c, int id)
{
    return yaml_document_get_node(c->doc, id);
}

/* The lmb_cfg_scalar's text, or NULL for a list or mapping. */
const char *lmb_cfg_scalar(const yaml_node_t *n)
{
    return n->type == YAML_SCALAR_NODE ? (const char *)n->data.scalar.value : NULL;
}

/* A plain (unquoted) YAML null: nothing after the colon, ~ or null. */
int lmb_cfg_is_null(const yaml_node_t *n)
{
    static const char *const nulls[] = {"", "~", "null", "Null", "NULL"};
    if (n->type != YAML_SCALAR_NODE || n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE)
        return 0;
    for (size_t i = 0; i < sizeof nulls / sizeof *nulls; i++)
        if (!strcmp(lmb_cfg_scalar(n), nulls[i]))
            return 1;
    return 0;
}

/* What a lmb_cfg_node is, for "got ...": the quoted text, shortened, or its kind. */
void lmb_cfg_describe_got(const yaml_node_t *n, char *out, size_t size)
{
    const char *s = lmb_cfg_scalar(n);
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

lmb_status lmb_cfg_key_error(parse_ctx *c, const yaml_node_t *n, const char *path, const char *fmt, ...)
{
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return lmb_error_set(c->err, LMB_ERR_INPUT, "%s:%zu: key '%s': %s", c->file, lmb_cfg_line_of(n), path, what);
}

/* "expected WANT, got WHAT-N-IS" */
lmb_status lmb_cfg_bad_value(parse_ctx *c, const key_spec *k, const yaml_node_t *n, const char *want)
{
    char got[128];
    lmb_cfg_describe_got(n, got, sizeof got);
    return lmb_cfg_key_error(c, n, k->path, "expected %s, got %s", want, got);
}

/* "cosine, amis, amis_defensive" */
void lmb_cfg_join_names(const char *const *names, char *out, size_t size)
{
    size_t len = 0;
    out[0] = '\0';
    for (size_t i = 0; names[i] && len < size; i++)
        len += (size_t)snprintf(out + len, size - len, "%s%s", i ? ", " : "", names[i]);
}

/* ---- lmb_cfg_scalar setters --------------------------------------------------------- */

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

lmb_status lmb_cfg_set_float(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    const char *s = lmb_cfg_scalar(n);
    double v;
    if (!s || !parse_float(s, &v) || !float_in_range(k, v)) {
        char want[96];
        snprintf(want, sizeof want, "a number %s %.15g and %s %.15g", (k->open & OPEN_LO) ? ">" : ">=", k->flo,
                 (k->open & OPEN_HI) ? "<" : "<=", k->fhi);
        return lmb_cfg_bad_value(c, k, n, want);
    }
    memcpy(base + k->offset, &v, sizeof v);
    return LMB_OK;
}

/* Decimal integer, optional sign, nothing after it (no fraction, exponent or spaces). */
static int parse_int(const yaml_node_t *n, long long lo, long long hi, long long *out)
{
    const char *s = lmb_cfg_scalar(n);
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
    return lmb_cfg_bad_value(c, k, n, want);
}

lmb_status lmb_cfg_set_u32(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    long long v;
    if (!parse_int(n, k->ilo, k->ihi, &v))
        return bad_int(c, k, n);
    uint32_t u = (uint32_t)v;
    memcpy(base + k->offset, &u, sizeof u);
    return LMB_OK;
}

lmb_status lmb_cfg_set_u64(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    long long v;
    if (!parse_int(n, k->ilo, k->ihi, &v))
        return bad_int(c, k, n);
    uint64_t u = (uint64_t)v;
    memcpy(base + k->offset, &u, sizeof u);
    return LMB_OK;
}

/* ---- "auto" or a number: auto leaves the choice to the baker (docs/defaults.md) ---- */

static int is_auto(const yaml_node_t *n)
{
    const char *s = lmb_cfg_scalar(n);
    return s && !strcmp(s, "auto") && n->data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
}

/* The message names both choices: "expected auto or a number > 0 ..., got '...'". */
static lmb_status or_auto_error(parse_ctx *c, const key_spec *k, const yaml_node_t *n, lmb_status st)
{
    if (st != LMB_ERR_INPUT || !c->err)
        return st;
    const char *want = strstr(c->err->message, "expected ");
    const char *got = want ? strstr(want, ", got ") : NULL;
    if (!want || !got)
        return st;
    char what[256];
    snprintf(what, sizeof what, "auto or %.*s", (int)(got - want - 9), want + 9);
    return lmb_cfg_bad_value(c, k, n, what);
}

/* "auto" stores auto_value (size bytes); anything else goes through set. */
static lmb_status set_or_auto(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base, setter_fn set,
                              const void *auto_value, size_t size)
{
    if (is_auto(n)) {
        memcpy(base + k->offset, auto_value, size);
        return LMB_OK;
    }
    return or_auto_error(c, k, n, set(c, k, n, base));
}

lmb_status lmb_cfg_set_float_or_auto(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    const double zero = 0;
    return set_or_auto(c, k, n, base, lmb_cfg_set_float, &zero, sizeof zero);
}

lmb_status lmb_cfg_set_u32_or_auto(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    const uint32_t a = LMB_AUTO;
    return set_or_auto(c, k, n, base, lmb_cfg_set_u32, &a, sizeof a);
}

lmb_status lmb_cfg_set_u64_or_auto(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    const uint64_t zero = 0;
    return set_or_auto(c, k, n, base, lmb_cfg_set_u64, &zero, sizeof zero);
}

static int ieq(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return 0;
    return *a == *b;
}

/* YAML 1.1 booleans: true/false, yes/no, on/off, any case. */
lmb_status lmb_cfg_set_bool(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    static const char *const words[] = {"false", "true", "no", "yes", "off", "on"};
    const char *s = lmb_cfg_scalar(n);
    for (size_t i = 0; s && i < sizeof words / sizeof *words; i++)
        if (ieq(s, words[i])) {
            int v = (int)(i % 2);
            memcpy(base + k->offset, &v, sizeof v);
            return LMB_OK;
        }
    return lmb_cfg_bad_value(c, k, n, "true or false");
}

/* Index of n's text in k->names, or -1. */
static int name_index(const key_spec *k, const yaml_node_t *n)
{
    const char *s = lmb_cfg_scalar(n);
    for (int i = 0; s && k->names[i]; i++)
        if (!strcmp(s, k->names[i]))
            return i;
    return -1;
}

static lmb_status bad_name(parse_ctx *c, const key_spec *k, const yaml_node_t *n)
{
    char names[256], want[300];
    lmb_cfg_join_names(k->names, names, sizeof names);
    snprintf(want, sizeof want, "one of %s", names);
    return lmb_cfg_bad_value(c, k, n, want);
}

/* Enum keys (gather.method, gather.amis_weights, ...) are C enums of the same size. */
_Static_assert(sizeof(lmb_gather_method) == sizeof(lmb_amis_weights) && sizeof(lmb_gather_method) == sizeof(lmb_ic_records_mode) &&
                   sizeof(lmb_gather_method) == sizeof(lmb_emission_sides),
               "enum keys share lmb_cfg_set_enum");
lmb_status lmb_cfg_set_enum(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
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
    const char *s = lmb_cfg_scalar(n);
    if (!s || !*s || n->data.scalar.length >= LMB_PATTERN_LEN || strlen(s) != n->data.scalar.length) {
        char want[96];
        snprintf(want, sizeof want, "a non-empty string of at most %d characters", LMB_PATTERN_LEN - 1);
        return lmb_cfg_bad_value(c, k, n, want);
    }
    memcpy(dst, s, n->data.scalar.length + 1);
    return LMB_OK;
}

lmb_status lmb_cfg_set_string(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    return copy_string(c, k, n, base + k->offset);
}

lmb_status lmb_cfg_set_path(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    const char *s = lmb_cfg_scalar(n);
    if (s && !*s) {
        base[k->offset] = '\0';
        return LMB_OK;
    }
    return copy_string(c, k, n, base + k->offset);
}

/* Three numbers of a YAML sequence into v; 0 if n is not one. */
static int read_three(parse_ctx *c, const yaml_node_t *n, double v[3])
{
    if (n->type != YAML_SEQUENCE_NODE || n->data.sequence.items.top - n->data.sequence.items.start != 3)
        return 0;
    for (int i = 0; i < 3; i++) {
        const char *s = lmb_cfg_scalar(lmb_cfg_node(c, n->data.sequence.items.start[i]));
        if (!s || !parse_float(s, &v[i]))
            return 0;
    }
    return 1;
}

lmb_status lmb_cfg_set_rgb(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    double v[3];
    const char *s = lmb_cfg_scalar(n);
    if ((k->open & OPEN_NONE) && s && !strcmp(s, "none")) {
        v[0] = v[1] = v[2] = -1;
    } else if (!read_three(c, n, v) || !float_in_range(k, v[0]) || !float_in_range(k, v[1]) ||
               !float_in_range(k, v[2])) {
        char want[128];
        snprintf(want, sizeof want, "[r, g, b] with each number >= %.15g and <= %.15g%s", k->flo, k->fhi,
                 (k->open & OPEN_NONE) ? ", or none" : "");
        return lmb_cfg_bad_value(c, k, n, want);
    }
    memcpy(base + k->offset, v, sizeof v);
    return LMB_OK;
}

lmb_status lmb_cfg_set_direction(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    double v[3];
    if (!read_three(c, n, v) || !(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > 1e-12) ||
        !isfinite(v[0] + v[1] + v[2]))
        return lmb_cfg_bad_value(c, k, n, "[x, y, z], finite and not all 0");
    memcpy(base + k->offset, v, sizeof v);
    return LMB_OK;
}

lmb_status lmb_cfg_set_point(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    double v[3];
    if (!read_three(c, n, v) || !isfinite(v[0] + v[1] + v[2]))
        return lmb_cfg_bad_value(c, k, n, "[x, y, z], three finite numbers");
    memcpy(base + k->offset, v, sizeof v);
    return LMB_OK;
}

lmb_status lmb_cfg_set_u32x3(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    double v[3];
    uint32_t u[3];
    int ok = read_three(c, n, v);
    for (int i = 0; ok && i < 3; i++) {
        ok = v[i] == floor(v[i]) && v[i] >= (double)k->ilo && v[i] <= (double)k->ihi;
        u[i] = ok ? (uint32_t)v[i] : 0;
    }
    if (!ok) {
        char want[96];
        snprintf(want, sizeof want, "[x, y, z], integers in %lld..%lld", k->ilo, k->ihi);
        return lmb_cfg_bad_value(c, k, n, want);
    }
    memcpy(base + k->offset, u, sizeof u);
    return LMB_OK;
}

/* ---- lists ------------------------------------------------------------------ */


/* A list's entries one by one: a null is an empty list, a lone value a list of one. */
lmb_status lmb_cfg_each_item(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base, lmb_cfg_item_fn fn,
                            uint32_t *count)
{
    *count = 0;
    if (lmb_cfg_is_null(n))
        return LMB_OK;
    if (n->type != YAML_SEQUENCE_NODE) {
        *count = 1;
        return fn(c, k, n, base, 0);
    }
    for (const yaml_node_item_t *it = n->data.sequence.items.start; it < n->data.sequence.items.top; it++) {
        const yaml_node_t *item = lmb_cfg_node(c, *it);
        if (*count >= k->max_items)
            return lmb_cfg_key_error(c, item, k->path, "expected at most %u entries, got %ld", (unsigned)k->max_items,
                             (long)(n->data.sequence.items.top - n->data.sequence.items.start));
        lmb_status st = fn(c, k, item, base, (*count)++);
        if (st != LMB_OK)
            return st;
    }
    return LMB_OK;
}

lmb_status lmb_cfg_set_count(const key_spec *k, char *base, uint32_t count, lmb_status st)
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
lmb_status lmb_cfg_set_flags(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    unsigned zero = 0;
    uint32_t count;
    memcpy(base + k->offset, &zero, sizeof zero);
    lmb_status st = lmb_cfg_each_item(c, k, n, base, flag_item, &count);
    if (st == LMB_OK && count == 0) {
        char names[256];
        lmb_cfg_join_names(k->names, names, sizeof names);
        return lmb_cfg_key_error(c, n, k->path, "expected at least one of %s, got an empty list", names);
    }
    return st;
}

static lmb_status glob_item(parse_ctx *c, const key_spec *k, const yaml_node_t *item, char *base, uint32_t index)
{
    if (item->type == YAML_MAPPING_NODE) /* [?all] reads as a mapping */
        return lmb_cfg_key_error(c, item, k->path, "expected a glob, got a mapping (put a glob that starts with ? in quotes)");
    return copy_string(c, k, item, base + k->offset + (size_t)index * LMB_PATTERN_LEN);
}

/* Into char[LMB_MAX_PATTERNS][LMB_PATTERN_LEN] and its count; replaces the default. */
lmb_status lmb_cfg_set_globs(parse_ctx *c, const key_spec *k, const yaml_node_t *n, char *base)
{
    uint32_t count = 0;
    lmb_status st = lmb_cfg_each_item(c, k, n, base, glob_item, &count); /* before count is read: argument order is unspecified */
    return lmb_cfg_set_count(k, base, count, st);
}

