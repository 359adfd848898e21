/* Scratch folder and quiet log for the fuzz targets (fuzz_common.h). */
#define _GNU_SOURCE
#include "fuzz_common.h"

#include <lmbake/lmbake.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Process-lifetime state of a test harness (not of lmbake): the folder's name. */
static char scratch[4096];

static void remove_scratch(void)
{
    DIR *d = opendir(scratch);
    if (d) {
        struct dirent *e;
        char path[8192];
        while ((e = readdir(d)))
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                snprintf(path, sizeof path, "%s/%s", scratch, e->d_name);
                unlink(path);
            }
        closedir(d);
    }
    rmdir(scratch);
}

const char *lmb_fuzz_folder(void)
{
    if (scratch[0])
        return scratch;
    const char *base = getenv("TMPDIR");
    if (!base || !*base)
        base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    snprintf(scratch, sizeof scratch, "%s/lmbake-fuzz-XXXXXX", base);
    if (!mkdtemp(scratch)) {
        scratch[0] = 0;
        return NULL;
    }
    atexit(remove_scratch);
    return scratch;
}

int lmb_fuzz_write(const char *name, const uint8_t *data, size_t size, char *path)
{
    const char *folder = lmb_fuzz_folder();
    if (!folder)
        return 0;
    snprintf(path, 4096, "%s/%s", folder, name);
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    size_t written = size ? fwrite(data, 1, size, f) : 0;
    return fclose(f) == 0 && written == size;
}

static void drop(void *user, const char *message)
{
    (void)user;
    (void)message;
}

const struct lmb_log *lmb_fuzz_quiet_log(void)
{
    static const lmb_log quiet = {drop, NULL, drop}; /* messages are still formatted */
    return &quiet;
}
