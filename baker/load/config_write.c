/*
 * The effective config as YAML text (lmb_config_write): every key of the schema table
 * (config.c), in table order, grouped by section, with values that read back exactly
 * (doubles with the fewest digits, 15 to 17, that read back to the same value). Two configs give the same text exactly when the
 * bake sees the same settings, which is what the farm's parts compare (docs/farm.md) and
 * what `lmbake bake --print-config` shows. Keys the command line sets (reference) follow
 * as a comment: they are not config keys, but they change the bake.
 */
#include <lmbake/lmbake.h>

#include "config_internal.h"

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct text_out {
    char *buf;
    size_t size, used; /* used may pass size: the length the whole text needs */
} text_out;

static void put(text_out *o, const char *fmt, ...) LMB_PRINTF(2, 3);
static void put(text_out *o, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    size_t room = o->used < o->size ? o->size - o->used : 0;
    int n = vsnprintf(room ? o->buf + o->used : NULL, room, fmt, ap);
    va_end(ap);
    if (n > 0)
        o->used += (size_t)n;
}

/* A YAML double-quoted string. */
static void put_quoted(text_out *o, const char *s)
{
    put(o, "\"");
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            put(o, "\\%c", *s);
        else if ((unsigned char)*s < 0x20)
            put(o, "\\x%02x", (unsigned)(unsigned char)*s);
        else
            put(o, "%c", *s);
    }
    put(o, "\"");
}

/* One key's value at base (an lmb_config or an lmb_density_override). */
static void put_value(text_out *o, const key_spec *k, const char *base)
{
    const char *at = base + k->offset;
    if (k->set == lmb_cfg_set_float || k->set == lmb_cfg_set_float_or_auto) {
        double v;
        memcpy(&v, at, sizeof v);
        char text[40];
        for (int digits = 15; digits <= 17; digits++) { /* the shortest that reads back exactly */
            snprintf(text, sizeof text, "%.*g", digits, v);
            if (strtod(text, NULL) == v)
                break;
        }
        put(o, "%s", k->set == lmb_cfg_set_float_or_auto && v == 0 ? "auto" : text);
    } else if (k->set == lmb_cfg_set_u32 || k->set == lmb_cfg_set_u32_or_auto) {
        uint32_t v;
        memcpy(&v, at, sizeof v);
        if (k->set == lmb_cfg_set_u32_or_auto && v == LMB_AUTO)
            put(o, "auto");
        else
            put(o, "%u", v);
    } else if (k->set == lmb_cfg_set_u64 || k->set == lmb_cfg_set_u64_or_auto) {
        uint64_t v;
        memcpy(&v, at, sizeof v);
        if (k->set == lmb_cfg_set_u64_or_auto && v == 0)
            put(o, "auto");
        else
            put(o, "%llu", (unsigned long long)v);
    } else if (k->set == lmb_cfg_set_bool) {
        int v;
        memcpy(&v, at, sizeof v);
        put(o, "%s", v ? "true" : "false");
    } else if (k->set == lmb_cfg_set_enum) {
        lmb_gather_method v; /* every enum key has this size (config_values.c) */
        memcpy(&v, at, sizeof v);
        put(o, "%s", k->names[v]);
    } else if (k->set == lmb_cfg_set_flags) {
        unsigned bits;
        memcpy(&bits, at, sizeof bits);
        put(o, "[");
        for (unsigned i = 0, first = 1; k->names[i]; i++)
            if (bits & (1u << i)) {
                put(o, "%s%s", first ? "" : ", ", k->names[i]);
                first = 0;
            }
        put(o, "]");
    } else if (k->set == lmb_cfg_set_string || k->set == lmb_cfg_set_path) {
        put_quoted(o, at);
    } else if (k->set == lmb_cfg_set_u32x3) {
        uint32_t v[3];
        memcpy(v, at, sizeof v);
        put(o, "[%u, %u, %u]", v[0], v[1], v[2]);
    } else if (k->set == lmb_cfg_set_rgb || k->set == lmb_cfg_set_direction || k->set == lmb_cfg_set_point) {
        double v[3];
        memcpy(v, at, sizeof v);
        if (k->set == lmb_cfg_set_rgb && (k->open & OPEN_NONE) && v[0] < 0) {
            put(o, "none");
        } else {
            put(o, "[");
            for (int i = 0; i < 3; i++) {
                char text[40];
                for (int digits = 15; digits <= 17; digits++) {
                    snprintf(text, sizeof text, "%.*g", digits, v[i]);
                    if (strtod(text, NULL) == v[i])
                        break;
                }
                put(o, "%s%s", i ? ", " : "", text);
            }
            put(o, "]");
        }
    } else if (k->set == lmb_cfg_set_globs) {
        uint32_t count;
        memcpy(&count, base + k->count_offset, sizeof count);
        put(o, "[");
        for (uint32_t i = 0; i < count; i++) {
            put(o, "%s", i ? ", " : "");
            put_quoted(o, at + (size_t)i * LMB_PATTERN_LEN);
        }
        put(o, "]");
    } else { /* lists of mappings: density_overrides ({match, texel_density}), materials.override, probes.volumes */
        const schema *ov = k->items ? k->items : lmb_cfg_override_schema();
        size_t item_size = k->items ? k->item_size : sizeof(lmb_density_override);
        uint32_t count;
        memcpy(&count, base + k->count_offset, sizeof count);
        put(o, "[");
        for (uint32_t i = 0; i < count; i++) {
            const char *item = at + (size_t)i * item_size;
            put(o, "%s{", i ? ", " : "");
            for (size_t f = 0, first = 1; f < ov->count; f++) {
                const key_spec *fk = &ov->keys[f];
                /* an unset string (a light group's match or a one_per_light's name) is left out:
                 * "" is no value a config may give, and the printed config must read back */
                if ((fk->set == lmb_cfg_set_string || fk->set == lmb_cfg_set_path) && !item[fk->offset])
                    continue;
                put(o, "%s%s: ", first ? "" : ", ", strrchr(fk->path, '.') + 1);
                put_value(o, fk, item);
                first = 0;
            }
            put(o, "}");
        }
        put(o, "]");
    }
}

/* Length of a dotted path's section ("samples.gather" -> 7), 0 for a top-level key. */
static size_t section_length(const char *path)
{
    const char *dot = strchr(path, '.');
    return dot ? (size_t)(dot - path) : 0;
}

size_t lmb_config_write(const lmb_config *cfg, char *buf, size_t size)
{
    text_out o = {buf, size, 0};
    if (size)
        buf[0] = '\0';
    const schema *sc = lmb_cfg_schema();
    put(&o, "# lmbake effective config (every key; lmbake %s)\n", LMB_VERSION_STRING);
    for (size_t i = 0; i < sc->count; i++) {
        const key_spec *k = &sc->keys[i];
        size_t len = section_length(k->path);
        if (!len) {
            put(&o, "%s: ", k->path);
            put_value(&o, k, (const char *)cfg);
            put(&o, "\n");
            continue;
        }
        int seen = 0; /* the section was written with an earlier key */
        for (size_t j = 0; j < i && !seen; j++)
            seen = section_length(sc->keys[j].path) == len && !strncmp(sc->keys[j].path, k->path, len);
        if (seen)
            continue;
        put(&o, "%.*s:\n", (int)len, k->path);
        for (size_t j = i; j < sc->count; j++)
            if (section_length(sc->keys[j].path) == len && !strncmp(sc->keys[j].path, k->path, len)) {
                put(&o, "  %s: ", sc->keys[j].path + len + 1);
                put_value(&o, &sc->keys[j], (const char *)cfg);
                put(&o, "\n");
            }
    }
    put(&o, "# command line: reference: %s\n", cfg->reference ? "true" : "false");
    return o.used;
}
