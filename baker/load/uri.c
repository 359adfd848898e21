/* Where a glTF URI may point (see uri.h). */
#define _GNU_SOURCE
#include "uri.h"

#include <ctype.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int hex(int c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

/* A scheme: ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ) ":" (RFC 3986 section 3.1). */
static int has_scheme(const char *s)
{
    if (!isalpha((unsigned char)s[0]))
        return 0;
    for (const char *p = s + 1; *p; p++) {
        if (*p == ':')
            return 1;
        if (!isalnum((unsigned char)*p) && *p != '+' && *p != '-' && *p != '.')
            return 0;
    }
    return 0;
}

lmb_uri_kind lmb_uri_check(const char *uri, char *relative, size_t size)
{
    if (!uri || !*uri)
        return LMB_URI_MALFORMED;
    if (!strncmp(uri, "data:", 5))
        return LMB_URI_EMBEDDED;
    if (has_scheme(uri))
        return LMB_URI_SCHEME;
    /* percent-decode */
    size_t n = strlen(uri);
    char *dec = malloc(n + 1);
    if (!dec)
        return LMB_URI_MALFORMED;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (uri[i] == '%') {
            int a = i + 1 < n ? hex(uri[i + 1]) : -1, b = i + 2 < n ? hex(uri[i + 2]) : -1;
            if (a < 0 || b < 0 || (a == 0 && b == 0)) { /* a bad escape, or %00 */
                free(dec);
                return LMB_URI_MALFORMED;
            }
            dec[m++] = (char)(a * 16 + b);
            i += 2;
        } else {
            dec[m++] = uri[i];
        }
    }
    dec[m] = '\0';
    lmb_uri_kind kind = LMB_URI_INSIDE;
    if (strchr(dec, '\\'))
        kind = LMB_URI_MALFORMED;
    else if (dec[0] == '/' || (isalpha((unsigned char)dec[0]) && dec[1] == ':'))
        kind = LMB_URI_ABSOLUTE;
    /* normalise segment by segment; a ".." with nothing left to pop escapes */
    size_t out = 0;
    char *seg = dec, *next;
    if (relative && size)
        relative[0] = '\0';
    for (; kind == LMB_URI_INSIDE && seg; seg = next) {
        next = strchr(seg, '/');
        if (next)
            *next++ = '\0';
        if (!*seg || !strcmp(seg, "."))
            continue;
        if (!strcmp(seg, "..")) {
            if (!out) {
                kind = LMB_URI_ESCAPES;
                break;
            }
            while (out && relative[out - 1] != '/')
                out--;
            if (out)
                out--; /* the '/' before the popped segment */
            relative[out] = '\0';
            continue;
        }
        size_t len = strlen(seg);
        if (!relative || out + len + 2 > size) {
            kind = LMB_URI_MALFORMED;
            break;
        }
        if (out)
            relative[out++] = '/';
        memcpy(relative + out, seg, len + 1);
        out += len;
    }
    if (kind == LMB_URI_INSIDE && !out)
        kind = LMB_URI_MALFORMED; /* names the folder itself */
    free(dec);
    return kind;
}

const char *lmb_uri_refusal(lmb_uri_kind kind)
{
    switch (kind) {
    case LMB_URI_SCHEME: return "uses a URI scheme (lmbake reads only files inside the input's folder)";
    case LMB_URI_ABSOLUTE: return "is an absolute path (lmbake reads only files inside the input's folder)";
    case LMB_URI_ESCAPES: return "leaves the input's folder through '..'";
    case LMB_URI_MALFORMED: return "is not a usable relative path (empty, a bad %-escape, a NUL or a backslash)";
    default: return "";
    }
}

int lmb_path_inside(const char *folder, const char *path, char *resolved, size_t size)
{
    char root[PATH_MAX], real[PATH_MAX];
    struct stat sb;
    if (!realpath(folder, root) || !realpath(path, real) || stat(real, &sb) != 0 || !S_ISREG(sb.st_mode))
        return 0;
    size_t rl = strlen(root);
    int inside = !strncmp(real, root, rl) && (real[rl] == '/' || !strcmp(root, "/"));
    if (!inside || strlen(real) >= size)
        return 0;
    memcpy(resolved, real, strlen(real) + 1);
    return 1;
}
