/*
 * Shared by the libFuzzer targets (issue 15): a private scratch folder per process, where each
 * input is written as the file the bake would read, so every target goes through the same
 * path-based entry points as `lmbake bake` (preflight, tinygltf's confined file callbacks, the
 * texture loader). The folder is made once and removed at exit.
 */
#ifndef LMB_FUZZ_COMMON_H
#define LMB_FUZZ_COMMON_H

#include <stddef.h>
#include <stdint.h>

/* The process's scratch folder (made on first call; removed at exit). NULL if it cannot be made. */
const char *lmb_fuzz_folder(void);

/* Writes bytes to <folder>/<name> and returns the full path in path (size >= 4096). 0 on failure. */
int lmb_fuzz_write(const char *name, const uint8_t *data, size_t size, char *path);

/* A log that drops warnings and info: the targets look for crashes, not messages. */
struct lmb_log;
const struct lmb_log *lmb_fuzz_quiet_log(void);

#endif
