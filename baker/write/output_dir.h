/*
 * The output folder of a bake, all-or-nothing even under kill -9 (issue 15).
 *
 * Files are written into a staging folder beside the output folder,
 * PARENT/.NAME.lmbake-staging-HOST-PID. Commit hard-links the output folder's other files
 * (earlier outputs the bake does not write again, a user's own files) into the staging folder,
 * then swaps the two folders in one renameat2(RENAME_EXCHANGE) and removes the old one. A
 * kill before the swap leaves the output folder as it was; after it, the new bake complete.
 * Abort removes the staging folder (and the output folder if the bake created it). The input's
 * own folder is refused, so the input and its buffers are never written over.
 *
 * Fallbacks, each with a warning that the bake is not kill-safe: when the parent folder is not
 * writable the staging folder goes inside the output folder (NAME/.lmbake-staging-HOST-PID), and
 * when the file system cannot swap folders (no RENAME_EXCHANGE, or the output folder is a mount
 * point) the staged files are moved in one by one.
 *
 * A bake that was killed leaves its staging folder (or, killed after the swap, the old output
 * folder under that name); the next bake into the folder removes those of this host whose
 * process is gone, and says so (folders of other hosts, or of a process still running, are kept).
 */
#ifndef LMBAKE_OUTPUT_DIR_H
#define LMBAKE_OUTPUT_DIR_H

#include <lmbake/lmbake.h>

typedef struct lmb_output_dir {
    char dir[4096];     /* the output folder as given */
    char real[4096];    /* its real path (the folder the swap replaces) */
    char staging[4600]; /* where the bake writes: the sibling staging folder (or one inside dir) */
    char stem[256];     /* input file name without extension */
    int created_dir;    /* folders the bake created: dir and the missing parents above it */
    int inside;         /* fallback: staging is inside dir, commit moves files one by one */
    const lmb_log *log; /* for the fallbacks' warnings */
} lmb_output_dir;

/* Creates dir and any missing parents, as mkdir -p, counting them in *made; names the part
 * that cannot be made (LMB_ERR_INPUT). */
lmb_status lmb_make_folders(const char *dir, int *made, lmb_error *err);

/* The output files' stem: input_path's file name without its extension ("levels/a.glb" -> "a"),
 * at most size - 1 bytes. */
void lmb_output_stem(const char *input_path, char *stem, size_t size);

lmb_status lmb_output_dir_open(lmb_output_dir *od, const char *dir, const char *input_path, const lmb_log *log,
                               lmb_error *err);

/* Copies `uri` (a path relative to the input's folder, e.g. a texture) into staging. */
lmb_status lmb_output_dir_copy_input_file(lmb_output_dir *od, const char *input_path, const char *uri, lmb_error *err);

/* Makes the staged files the output folder's (see above); the staging folder is gone after. */
lmb_status lmb_output_dir_commit(lmb_output_dir *od, lmb_error *err);
void lmb_output_dir_abort(lmb_output_dir *od);

#endif
