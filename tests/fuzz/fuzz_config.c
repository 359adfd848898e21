/*
 * libFuzzer target: the YAML bake config (issue 15), through lmb_config_parse, the parser
 * `lmb_config_load` uses for files: every key, type and range check, glob patterns, and the
 * texel budget derived from what was read.
 */
#include <lmbake/lmbake.h>

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lmb_config cfg;
    lmb_config_default(&cfg);
    lmb_error err;
    if (lmb_config_parse("fuzz.yaml", (const char *)data, size, &cfg, &err) == LMB_OK) {
        (void)lmb_config_atlas_texels(&cfg);
        for (uint32_t i = 0; i < cfg.include_count; i++)
            (void)lmb_glob_match(cfg.include[i], "node_Name-01.mesh");
        for (uint32_t i = 0; i < cfg.exclude_count; i++)
            (void)lmb_glob_match(cfg.exclude[i], "node_Name-01.mesh");
    }
    return 0;
}
