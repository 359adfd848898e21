/* Staged, all-or-nothing output folder, safe under kill -9 (see output_dir.h). Linux file
 * calls: renameat2(RENAME_EXCHANGE) swaps two folders in one step. */
#define _GNU_SOURCE
#include "output_dir.h"

#include "load/uri.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* How many characters of the output folder's name the sibling staging folder carries (the
 * whole name stays under NAME_MAX with the host and pid). */
#define STAGING_NAME_CHARS 64

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

/* Removes a folder and everything in it. Symbolic links are removed, never followed: the old
 * output folder may hold a user's links to folders elsewhere. */
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
            if (lstat(a, &sb) == 0 && S_ISDIR(sb.st_mode))
                remove_tree(a);
            else
                unlink(a);
        }
        closedir(d);
    }
    rmdir(path);
}

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

/* In folder `dir`, removes the entries named PREFIX HOST-PID (or the older PREFIX PID) of this
 * host whose process is gone, naming each in a warning. */
static void remove_stale_staging(const char *dir, const char *prefix, const lmb_log *log)
{
    char host[256], mine[600];
    host_name(host, sizeof host);
    snprintf(mine, sizeof mine, "%s%s-", prefix, host);
    size_t plen = strlen(prefix), mlen = strlen(mine);
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *pid_text = NULL;
        if (!strncmp(e->d_name, mine, mlen))
            pid_text = e->d_name + mlen;
        else if (!strncmp(e->d_name, prefix, plen))
            pid_text = e->d_name + plen;
        if (!pid_text || !*pid_text || strspn(pid_text, "0123456789") != strlen(pid_text))
            continue;
        long pid = strtol(pid_text, NULL, 10);
        if (pid <= 0 || pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue; /* running (or not ours to judge) */
        char path[8400];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        remove_tree(path);
        lmb_warn(log, "removed '%s', left by a bake that was stopped (process %ld is gone); its files are not "
                 "part of the output folder", path, pid);
    }
    closedir(d);
}

/* The sibling staging folder's name prefix for output folder `name`: ".NAME.lmbake-staging-". */
static void sibling_prefix(const char *name, char *out, size_t size)
{
    snprintf(out, size, ".%.*s.lmbake-staging-", STAGING_NAME_CHARS, name);
}

/* Creates dir and any missing parents, as mkdir -p, counting them in *made; names the part
 * that cannot be made. */
lmb_status lmb_make_folders(const char *dir, int *made, lmb_error *err)
{
    *made = 0;
    char path[4096];
    size_t len = strlen(dir);
    if (len >= sizeof path)
        return lmb_error_set(err, LMB_ERR_INPUT, "output folder '%.64s...' has too long a path", dir);
    memcpy(path, dir, len + 1);
    while (len > 1 && path[len - 1] == '/')
        path[--len] = '\0';
    for (size_t i = 1; i <= len; i++) {
        if (path[i] != '/' && path[i] != '\0')
            continue;
        char keep = path[i];
        path[i] = '\0';
        struct stat sb;
        if (stat(path, &sb) == 0) {
            if (!S_ISDIR(sb.st_mode)) {
                lmb_status st = lmb_error_set(err, LMB_ERR_INPUT, "cannot create output folder '%s': '%s' exists and "
                                              "is not a folder", dir, path);
                return st;
            }
        } else if (mkdir(path, 0777) == 0) {
            (*made)++;
        } else if (errno != EEXIST) {
            return lmb_error_set(err, LMB_ERR_INPUT, "cannot create output folder '%s': cannot create '%s': %s", dir,
                                 path, strerror(errno));
        }
        path[i] = keep;
    }
    return LMB_OK;
}

void lmb_output_stem(const char *input_path, char *stem, size_t size)
{
    const char *base = strrchr(input_path, '/');
    snprintf(stem, size, "%s", base ? base + 1 : input_path);
    char *dot = strrchr(stem, '.');
    if (dot && dot != stem)
        *dot = '\0';
}

lmb_status lmb_output_dir_open(lmb_output_dir *od, const char *dir, const char *input_path, const lmb_log *log,
                               lmb_error *err)
{
    memset(od, 0, sizeof *od);
    od->log = log;
    snprintf(od->dir, sizeof od->dir, "%s", dir);
    lmb_output_stem(input_path, od->stem, sizeof od->stem);
    struct stat sb;
    if (stat(dir, &sb) == 0) {
        if (!S_ISDIR(sb.st_mode))
            return lmb_error_set(err, LMB_ERR_INPUT, "output '%s' exists and is not a folder", dir);
    } else {
        lmb_status st = lmb_make_folders(dir, &od->created_dir, err);
        if (st != LMB_OK) {
            lmb_output_dir_abort(od);
            return st;
        }
    }
    char in_dir[4096], real_in[PATH_MAX];
    dirname_of(input_path, in_dir, sizeof in_dir);
    if (!realpath(dir, od->real)) {
        lmb_status st = lmb_error_set(err, LMB_ERR_INPUT, "cannot resolve output folder '%s': %s", dir, strerror(errno));
        lmb_output_dir_abort(od);
        return st;
    }
    if (realpath(in_dir, real_in) && strcmp(real_in, od->real) == 0) {
        lmb_output_dir_abort(od);
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "output folder '%s' is the folder of the input '%s': choose another with -o, so the "
                             "input and its files are never written over",
                             dir, input_path);
    }
    char parent[4096], prefix[STAGING_NAME_CHARS + 32], host[256];
    dirname_of(od->real, parent, sizeof parent);
    const char *name = strrchr(od->real, '/') + 1; /* realpath is absolute */
    sibling_prefix(name, prefix, sizeof prefix);
    host_name(host, sizeof host);
    remove_stale_staging(parent, prefix, log);
    if (!od->created_dir)
        remove_stale_staging(dir, ".lmbake-staging-", log);
    if (*name) {
        snprintf(od->staging, sizeof od->staging, "%s/%s%s-%ld", strcmp(parent, "/") ? parent : "", prefix, host,
                 (long)getpid());
        if (mkdir(od->staging, 0777) == 0)
            return LMB_OK;
        lmb_warn(log, "cannot stage beside the output folder ('%s': %s): staging inside it; a bake killed while "
                 "its files move into place would leave old and new files mixed", od->staging, strerror(errno));
    }
    od->inside = 1;
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
    char rel[4096], in_dir[4096], from[8300], real[4096], to[8800];
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

/* Moves every file under staging (recursively) to the same place under dir: the fallback
 * commit, one rename per file. */
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
        if (lstat(a, &sb) == 0 && S_ISDIR(sb.st_mode)) {
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

/* Puts into staging a hard link to every entry of the output folder that the bake does not
 * write again (earlier outputs, a user's files), folders recursively, so that after the swap
 * the output folder holds them as before. Other bakes' staging folders are left out. */
static lmb_status link_others(const char *from, const char *to, lmb_error *err)
{
    DIR *d = opendir(from);
    if (!d)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "cannot read '%s': %s", from, strerror(errno));
    lmb_status st = LMB_OK;
    struct dirent *e;
    while (st == LMB_OK && (e = readdir(d)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") || !strncmp(e->d_name, ".lmbake-staging-", 16))
            continue;
        char a[8400], b[8400];
        struct stat sa, sb;
        snprintf(a, sizeof a, "%s/%s", from, e->d_name);
        snprintf(b, sizeof b, "%s/%s", to, e->d_name);
        if (lstat(a, &sa) != 0)
            continue; /* gone meanwhile */
        int staged = lstat(b, &sb) == 0;
        if (S_ISDIR(sa.st_mode)) {
            if (staged && !S_ISDIR(sb.st_mode))
                continue; /* the bake writes a file where a folder was: the bake's wins */
            if (!staged && mkdir(b, sa.st_mode & 07777) != 0)
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "cannot create '%s': %s", b, strerror(errno));
            else
                st = link_others(a, b, err);
        } else if (!staged && linkat(AT_FDCWD, a, AT_FDCWD, b, 0) != 0) {
            /* a file system without hard links: a copy keeps the file just as well */
            if (!S_ISREG(sa.st_mode))
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "cannot keep '%s' in the output folder: %s", a,
                                   strerror(errno));
            else
                st = copy_file(a, b, err);
        }
    }
    closedir(d);
    return st;
}

lmb_status lmb_output_dir_commit(lmb_output_dir *od, lmb_error *err)
{
    lmb_status st;
    if (!od->inside) {
        struct stat sb;
        st = link_others(od->real, od->staging, err);
        if (st == LMB_OK && stat(od->real, &sb) == 0)
            chmod(od->staging, sb.st_mode & 07777);
        if (st == LMB_OK && renameat2(AT_FDCWD, od->staging, AT_FDCWD, od->real, RENAME_EXCHANGE) == 0) {
            remove_tree(od->staging); /* now the old output folder */
            od->staging[0] = '\0';
            return LMB_OK;
        }
        if (st != LMB_OK) {
            lmb_output_dir_abort(od);
            return st;
        }
        if (errno != EINVAL && errno != ENOSYS && errno != EXDEV && errno != ENOTSUP && errno != EBUSY) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "cannot swap '%s' into place: %s", od->staging, strerror(errno));
            lmb_output_dir_abort(od);
            return st;
        }
        lmb_warn(od->log, "'%s': the file system cannot swap folders (%s); moving the new files in one by one (a "
                 "kill meanwhile would leave old and new files mixed)", od->dir, strerror(errno));
    }
    st = move_tree(od->staging, od->dir, err);
    remove_tree(od->staging);
    od->staging[0] = '\0';
    return st;
}

void lmb_output_dir_abort(lmb_output_dir *od)
{
    if (od->staging[0])
        remove_tree(od->staging);
    od->staging[0] = '\0';
    /* the folders the bake made, dir and then its parents, as long as they are empty */
    char path[sizeof od->dir];
    snprintf(path, sizeof path, "%s", od->dir);
    for (int removed = 0; removed < od->created_dir;) {
        size_t len = strlen(path);
        while (len > 1 && path[len - 1] == '/')
            path[--len] = '\0';
        if (rmdir(path) == 0)
            removed++;
        else if (errno != ENOENT) /* not empty, or not ours to remove */
            break;
        char *slash = strrchr(path, '/');
        if (!slash || slash == path)
            break;
        *slash = '\0';
    }
    od->created_dir = 0;
}
