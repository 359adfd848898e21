/* Whole-file reading shared by the stages that parse text (config, glTF preflight). */
#ifndef LMBAKE_FILE_H
#define LMBAKE_FILE_H

#include <lmbake/lmbake.h>

/* Reads path into a new NUL-terminated buffer (caller frees). `what` names the file's role
 * in messages, e.g. "config" -> "cannot open config 'x.yaml': No such file or directory". */
lmb_status lmb_read_file(const char *path, const char *what, char **out, size_t *size, lmb_error *err);

#endif
