/* The config tests' parse: `text` as level.yaml over the defaults (test_config.c,
 * test_config_lint.c). */
#ifndef LMB_TEST_CONFIG_PARSE_H
#define LMB_TEST_CONFIG_PARSE_H

#include <lmbake/lmbake.h>

#include <string.h>

static inline lmb_status parse(const char *text, lmb_config *cfg, lmb_error *err)
{
    lmb_config_default(cfg);
    err->status = LMB_OK;
    err->message[0] = '\0';
    return lmb_config_parse("level.yaml", text, strlen(text), cfg, err);
}

#endif
