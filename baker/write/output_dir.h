/*
 * The output folder of a bake: files are written into a staging folder inside it and
 * moved into place by commit only when the whole bake succeeded; abort removes the
 * staging folder (and the output folder if the bake created it). The input's own folder
 * is refused, so the input and its buffers are never written over.
 * The staging folder is named .lmbake-staging-HOST-PID. A bake that was killed leaves its
 * own behind; the next bake into the folder removes those of this host whose process is
 * gone, and says so (folders of other hosts, or of a process still running, are kept).
 */
#ifndef LMBAKE_OUTPUT_DIR_H
#define LMBAKE_OUTPUT_DIR_H

#include <lmbake/lmbake.h>

typedef struct lmb_output_dir {
    char dir[4096];     /* the output folder as given */
    char staging[4400]; /* dir/.lmbake-staging-HOST-PID */
    char stem[256];     /* input file name without extension */
    int created_dir;    /* the bake created dir */
} lmb_output_dir;

lmb_status lmb_output_dir_open(lmb_output_dir *od, const char *dir, const char *input_path, const lmb_log *log,
                               lmb_error *err);

/* Copies `uri` (a path relative to the input's folder, e.g. a texture) into staging. */
lmb_status lmb_output_dir_copy_input_file(lmb_output_dir *od, const char *input_path, const char *uri, lmb_error *err);

lmb_status lmb_output_dir_commit(lmb_output_dir *od, lmb_error *err);
void lmb_output_dir_abort(lmb_output_dir *od);

#endif
