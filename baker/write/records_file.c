/* The records file (records_file.h). */
#include "records_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lmb_records_file_name(const char *stem, char *buf, size_t size)
{
    snprintf(buf, size, "%s-records.bin", stem);
}

lmb_status lmb_write_records(const char *dir, const char *name, const lmb_ic_points *points, lmb_error *err)
{
    char path[8600];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    size_t n = 4 * (size_t)points->count;
    unsigned char *bytes = malloc(4 * n + 1);
    if (!bytes)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory for %u records", path, points->count);
    for (size_t i = 0; i < n; i++) { /* little-endian whatever the host */
        uint32_t u;
        memcpy(&u, &points->xyzr[i], sizeof u);
        for (int b = 0; b < 4; b++)
            bytes[4 * i + (size_t)b] = (unsigned char)(u >> (8 * b));
    }
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(bytes, 1, 4 * n, f) == 4 * n;
    ok = (f && fclose(f) == 0) && ok;
    free(bytes);
    if (!ok)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write the irradiance cache records", path);
    return LMB_OK;
}
