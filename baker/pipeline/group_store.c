/* Each light group's kept images in a file of their own while no stage reads them (group_store.h). */
#define _POSIX_C_SOURCE 200809L
#include "group_store.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Where atlas a's images start in a group's file: every earlier atlas's light and directions. */
static off_t atlas_offset(const lmb_group_light *gl, uint32_t a)
{
    off_t at = 0;
    for (uint32_t b = 0; b < a; b++)
        at += (off_t)(gl->direction ? 6 : 3) * (off_t)gl->texels[b] * (off_t)sizeof(float);
    return at;
}

/* An unnamed file in TMPDIR (else /tmp): made, then unlinked at once. -1 and errno on failure. */
static int unnamed_file(char *dir_out, size_t size)
{
    const char *dir = getenv("TMPDIR");
    if (!dir || !*dir)
        dir = "/tmp";
    snprintf(dir_out, size, "%s", dir);
    char path[4200];
    snprintf(path, sizeof path, "%s/lmbake-group-XXXXXX", dir);
    int fd = mkstemp(path);
    if (fd >= 0)
        unlink(path);
    return fd;
}

/* All n bytes at offset `at`, written from p (writing) or read into p; 0, or -1 and errno. */
static int whole(int fd, void *p, size_t n, off_t at, int writing)
{
    char *b = p;
    while (n) {
        ssize_t k = writing ? pwrite(fd, b, n, at) : pread(fd, b, n, at);
        if (k <= 0)
            return k < 0 ? -1 : (errno = writing ? ENOSPC : EIO, -1);
        b += k;
        n -= (size_t)k;
        at += k;
    }
    return 0;
}

/* Group g's images freed (their pointers NULL). */
static void free_images(lmb_group_light *gl, uint32_t g)
{
    for (uint32_t a = 0; a < gl->atlases; a++) {
        size_t k = (size_t)g * gl->atlases + a;
        free(gl->irradiance[k]);
        gl->irradiance[k] = NULL;
        if (gl->direction) {
            free(gl->direction[k]);
            gl->direction[k] = NULL;
        }
    }
}

void lmb_group_light_put_away(lmb_group_light *gl, uint32_t g, const lmb_log *log)
{
    if (gl->in_memory || gl->away[g])
        return;
    char dir[4096] = "";
    if (gl->file[g] < 0)
        gl->file[g] = unnamed_file(dir, sizeof dir);
    int ok = gl->file[g] >= 0;
    for (uint32_t a = 0; ok && a < gl->atlases; a++) {
        size_t k = (size_t)g * gl->atlases + a, bytes = 3 * (size_t)gl->texels[a] * sizeof(float);
        off_t at = atlas_offset(gl, a);
        ok = whole(gl->file[g], gl->irradiance[k], bytes, at, 1) == 0 &&
             (!gl->direction || whole(gl->file[g], gl->direction[k], bytes, at + (off_t)bytes, 1) == 0);
    }
    if (!ok) { /* the images stay where they are, and so do every later group's */
        lmb_warn(log, "light groups: each group's light stays in memory until the files are written (a file in %s for "
                 "it: %s)", *dir ? dir : "TMPDIR", strerror(errno));
        gl->in_memory = 1;
        return;
    }
    free_images(gl, g);
    gl->away[g] = 1;
}

lmb_status lmb_group_light_bring_back(lmb_group_light *gl, uint32_t g, lmb_error *err)
{
    if (!gl->away[g])
        return LMB_OK;
    for (uint32_t a = 0; a < gl->atlases; a++) {
        size_t k = (size_t)g * gl->atlases + a, n = 3 * (size_t)gl->texels[a];
        gl->irradiance[k] = malloc(n * sizeof(float) + 1);
        if (gl->direction)
            gl->direction[k] = malloc(n * sizeof(float) + 1);
        if (!gl->irradiance[k] || (gl->direction && !gl->direction[k]))
            return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory for group %u's light, atlas %u",
                                 g + 1, a);
    }
    for (uint32_t a = 0; a < gl->atlases; a++) {
        size_t k = (size_t)g * gl->atlases + a;
        lmb_status st = lmb_group_light_read_span(gl, g, a, 0, gl->texels[a], gl->irradiance[k],
                                                  gl->direction ? gl->direction[k] : NULL, err);
        if (st != LMB_OK)
            return st;
    }
    gl->away[g] = 0; /* the file stays: a later put_away writes over it */
    return LMB_OK;
}

lmb_status lmb_group_light_read_span(const lmb_group_light *gl, uint32_t g, uint32_t a, size_t i0, size_t i1, float *e,
                                     float *d, lmb_error *err)
{
    size_t k = (size_t)g * gl->atlases + a, bytes = 3 * (i1 - i0) * sizeof(float);
    if (!gl->away[g]) {
        memcpy(e, gl->irradiance[k] + 3 * i0, bytes);
        if (d)
            memcpy(d, gl->direction[k] + 3 * i0, bytes);
        return LMB_OK;
    }
    off_t at = atlas_offset(gl, a), skip = (off_t)(3 * i0 * sizeof(float));
    off_t dirs = (off_t)(3 * (size_t)gl->texels[a] * sizeof(float));
    if (whole(gl->file[g], e, bytes, at + skip, 0) != 0 || (d && whole(gl->file[g], d, bytes, at + dirs + skip, 0) != 0))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: reading group %u's light back from its file in TMPDIR: %s",
                             g + 1, strerror(errno));
    return LMB_OK;
}

void lmb_group_light_drop(lmb_group_light *gl, uint32_t g)
{
    free_images(gl, g);
    if (gl->file[g] >= 0)
        close(gl->file[g]);
    gl->file[g] = -1;
    gl->away[g] = 0;
}

void lmb_group_store_close(lmb_group_light *gl)
{
    for (uint32_t g = 0; gl->file && g < gl->groups; g++)
        if (gl->file[g] >= 0)
            close(gl->file[g]);
}
