/* Whole-file reading (see file.h). */
#include "file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lmb_status lmb_read_file(const char *path, const char *what, char **out, size_t *size, lmb_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return lmb_error_set(err, LMB_ERR_INPUT, "cannot open %s '%s': %s", what, path, strerror(errno));
    char *buf = NULL;
    size_t cap = 0, n = 0, r;
    do {
        if (n == cap) {
            char *nb = realloc(buf, (cap = cap ? 2 * cap : 65536) + 1);
            if (!nb) {
                free(buf);
                fclose(f);
                return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory reading the %s", path, what);
            }
            buf = nb;
        }
        r = fread(buf + n, 1, cap - n, f);
        n += r;
    } while (r > 0);
    int failed = ferror(f);
    fclose(f);
    if (failed) {
        free(buf);
        return lmb_error_set(err, LMB_ERR_INPUT, "cannot read %s '%s'", what, path);
    }
    buf[n] = '\0';
    *out = buf;
    *size = n;
    return LMB_OK;
}
