/* A file a config key names, inside the config's folder (see config_file.h). */
#include "config_file.h"

#include "load/uri.h"

#include <stdio.h>
#include <string.h>

lmb_status lmb_config_file(const char *config_path, const char *key, const char *value, char *real, size_t size,
                           lmb_error *err)
{
    char dir[4096], rel[4096], path[8300];
    const char *cfg_name = config_path[0] ? config_path : "config";
    const char *slash = strrchr(config_path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - config_path) : 1, slash ? config_path : ".");
    lmb_uri_kind kind = lmb_uri_check(value, rel, sizeof rel);
    if (kind != LMB_URI_INSIDE)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: key '%s': '%s' %s; the file must be in the config's folder or "
                             "below", cfg_name, key, value, lmb_uri_refusal(kind));
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    if (!lmb_path_inside(dir, path, real, size))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: key '%s': '%s' is not a file inside the config's folder '%s'",
                             cfg_name, key, value, dir);
    return LMB_OK;
}
