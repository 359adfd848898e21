/* Staged, all-or-nothing output folder (see output_dir.h). POSIX file calls. */
#define _XOPEN_SOURCE 700
#include "output_dir.h"

#include "load/uri.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void dirname_of(const char *path, char *out, size_t size)
{
    snprintf(out, size, "%s", path);
    char *slash = strrchr(out, '/');
    if (!slash)
        snprintf(out, size, ".");
    else if (slash == out)
        out[1] = '\0';
    else
        *slash = '\0';
}

static void remove_tree(const char *path);

/* This host's name, as staging folders carry it ('-' and '/' would confuse the parse). */
static void host_name(char *out, size_t size)
{
    if (gethostname(out, size) != 0 || !out[0])
        snprintf(out, size, "localhost");
    out[size - 1] = '\0';
    for (char *p = out; *p; p++)
        if (*p == '-' || *p == '/')
            *p = '_';
}

/* Removes dir/.lmbake-staging-HOST-PID folders of this host whose process is gone (and the
 * older .lmbake-staging-PID form), naming each in a warning. */
static void remove_stale_staging(const char *dir, const lmb_log *log)
{
    char host[256], prefix[300];
    host_name(host, sizeof host);
    snprintf(prefix, sizeof prefix, ".lmbake-staging-%s-", host);
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *pid_text = NULL;
        if (!strncmp(e->d_name, prefix, strlen(prefix)))
            pid_text = e->d_name + strlen(prefix);
        else if (!strncmp(e->d_name, ".lmbake-staging-", 16) && strspn(e->d_name + 16, "0123456789") == strlen(e->d_name + 16))
            pid_text = e->d_name + 16;
        if (!pid_text || !*pid_text || strspn(pid_text, "0123456789") != strlen(pid_text))
            continue;
        long pid = strtol(pid_text, NULL, 10);
        if (pid <= 0 || pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue; /* running (or not ours to judge) */
        char path[8400];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        remove_tree(path);
        lmb_warn(log, "removed '%s', left by a bake that was stopped (process %ld is gone); its files were never "
                 "part of the output", path, pid);
    }
    closedir(d);
}

lmb_status lmb_output_dir_open(lmb_output_dir *od, const char *dir, const char *input_path, const lmb_log *log,
                               lmb_error *err)
{
    memset(od, 0, sizeof *od);
    snprintf(od->dir, sizeof od->dir, "%s", dir);
    const char *base = strrchr(input_path, '/');
    snprintf(od->stem, sizeof od->stem, "%s", base ? base + 1 : input_path);
    char *dot = strrchr(od->stem, '.');
    if (dot && dot != od->stem)
        *dot = '\0';
    struct stat sb;
    if (stat(dir, &sb) == 0) {
        if (!S_ISDIR(sb.st_mode))
            return lmb_error_set(err, LMB_ERR_INPUT, "output '%s' exists and is not a folder", dir);
    } else if (mkdir(dir, 0777) != 0) {
        return lmb_error_set(err, LMB_ERR_INPUT, "cannot create output folder '%s': %s", dir, strerror(errno));
    } else {
        od->created_dir = 1;
    }
    char in_dir[4096], real_in[PATH_MAX], real_out[PATH_MAX];
    dirname_of(input_path, in_dir, sizeof in_dir);
    if (realpath(in_dir, real_in) && realpath(dir, real_out) && strcmp(real_in, real_out) == 0) {
        lmb_output_dir_abort(od);
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "output folder '%s' is the folder of the input '%s': choose another with -o, so the "
                             "input and its files are never written over",
                             dir, input_path);
    }
    if (!od->created_dir)
        remove_stale_staging(dir, log);
    char host[256];
    host_name(host, sizeof host);
    snprintf(od->staging, sizeof od->staging, "%s/.lmbake-staging-%s-%ld", dir, host, (long)getpid());
    if (mkdir(od->staging, 0777) != 0) {
        lmb_status st = lmb_error_set(err, LMB_ERR_INTERNAL, "cannot create '%s': %s", od->staging, strerror(errno));
        od->staging[0] = '\0';
        lmb_output_dir_abort(od);
        return st;
    }
    return LMB_OK;
}

static lmb_status copy_file(const char *from, const char *to, lmb_error *err)
{
    FILE *in = fopen(from, "rb");
    if (!in)
        return lmb_error_set(err, LMB_ERR_INPUT, "cannot read '%s': %s", from, strerror(errno));
    FILE *out = fopen(to, "wb");
    if (!out) {
        fclose(in);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "cannot write '%s': %s", to, strerror(errno));
    }
    char buf[65536];
    size_t n;
    int bad = 0;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        bad |= fwrite(buf, 1, n, out) != n;
    bad |= ferror(in);
    fclose(in);
    bad |= fclose(out) != 0;
    return bad ? lmb_error_set(err, LMB_ERR_INTERNAL, "cannot copy '%s' to '%s'", from, to) : LMB_OK;
}

lmb_status lmb_output_dir_copy_input_file(lmb_output_dir *od, const char *input_path, const char *uri, lmb_error *err)
{
    char rel[4096], in_dir[4096], from[8300], real[4096], to[8600];
    lmb_uri_kind kind = lmb_uri_check(uri, rel, sizeof rel);
    if (kind != LMB_URI_INSIDE)
        return lmb_error_set(err, LMB_ERR_INPUT, "texture uri '%s' %s", uri, lmb_uri_refusal(kind));
    dirname_of(input_path, in_dir, sizeof in_dir);
    snprintf(from, sizeof from, "%s/%s", in_dir, rel);
    /* the source first: no folder is made for a file that is not there (or not inside) */
    if (!lmb_path_inside(in_dir, from, real, sizeof real))
        return lmb_error_set(err, LMB_ERR_INPUT, "texture uri '%s' is not a file inside the input's folder", uri);
    snprintf(to, sizeof to, "%s/%s", od->staging, rel);
    /* sub-folders of the (normalised, relative) path */
    for (char *p = to + strlen(od->staging) + 1; (p = strchr(p, '/')) != NULL; p++) {
        *p = '\0';
        mkdir(to, 0777);
        *p = '/';
    }
    return copy_file(real, to, err);
}

/* Moves every file under staging (recursively) to the same place under dir. */
static lmb_status move_tree(const char *from, const char *to, lmb_error *err)
{
    DIR *d = opendir(from);
    if (!d)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "cannot read '%s': %s", from, strerror(errno));
    lmb_status st = LMB_OK;
    struct dirent *e;
    while (st == LMB_OK && (e = readdir(d)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        char a[8400], b[8400];
        struct stat sb;
        snprintf(a, sizeof a, "%s/%s", from, e->d_name);
        snprintf(b, sizeof b, "%s/%s", to, e->d_name);
        if (stat(a, &sb) == 0 && S_ISDIR(sb.st_mode)) {
            mkdir(b, 0777);
            st = move_tree(a, b, err);
            rmdir(a);
        } else if (rename(a, b) != 0) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "cannot move '%s' to '%s': %s", a, b, strerror(errno));
        }
    }
    closedir(d);
    return st;
}

static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                continue;
            char a[8400];
            struct stat sb;
            snprintf(a, sizeof a, "%s/%s", path, e->d_name);
            if (stat(a, &sb) == 0 && S_ISDIR(sb.st_mode))
                remove_tree(a);
            else
                unlink(a);
        }
        closedir(d);
    }
    rmdir(path);
}

lmb_status lmb_output_dir_commit(lmb_output_dir *od, lmb_error *err)
{
    lmb_status st = move_tree(od->staging, od->dir, err);
    remove_tree(od->staging);
    return st;
}

void lmb_output_dir_abort(lmb_output_dir *od)
{
    if (od->staging[0])
        remove_tree(od->staging);
    if (od->created_dir)
        rmdir(od->dir);
}
