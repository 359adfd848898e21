/*
 * A file a config key names (sky.image): a path relative to the config file's folder that stays
 * inside it, as glTF URIs stay inside the input's folder (uri.h), symbolic links followed. The
 * config's lint checks it before a bake and the stage that reads the file resolves it again.
 */
#ifndef LMBAKE_CONFIG_FILE_H
#define LMBAKE_CONFIG_FILE_H

#include <lmbake/lmbake.h>

#include <stddef.h>

/* Where `value` of config key `key` lies: a file in the folder of config_path (the config file;
 * "" for none: the working folder) or below, resolved into real (size bytes); else LMB_ERR_INPUT
 * naming the config, the key and why. */
lmb_status lmb_config_file(const char *config_path, const char *key, const char *value, char *real, size_t size,
                           lmb_error *err);

#endif
