/*
 * libFuzzer target: glTF load (issue 15). The input is written as scene.glb when it starts with
 * the GLB magic, else as scene.gltf, in a scratch folder, and goes through what `lmbake bake`
 * does before unwrapping: preflight, the tinygltf adapter, accessor/node/material validation,
 * selection of lightmapped instances, scene statistics and the textures' decoding (data URIs).
 */
#include "fuzz_common.h"
#include "load/textures.h"

#include <lmbake/lmbake.h>

#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[4096];
    int glb = size >= 4 && !memcmp(data, "glTF", 4);
    if (!lmb_fuzz_write(glb ? "scene.glb" : "scene.gltf", data, size, path))
        return 0;
    lmb_config cfg;
    lmb_config_default(&cfg);
    lmb_scene *scene = NULL;
    lmb_error err;
    const lmb_log *log = (const lmb_log *)lmb_fuzz_quiet_log();
    if (lmb_scene_load(path, &cfg, &scene, log, &err) != LMB_OK)
        return 0;
    lmb_scene_select_lightmapped(scene, &cfg);
    lmb_scene_stats stats;
    lmb_scene_stats_compute(scene, &stats);
    lmb_textures textures;
    (void)lmb_textures_load(scene, &textures, log, &err); /* an error still leaves textures to free */
    lmb_textures_free(&textures);
    lmb_scene_free(scene);
    return 0;
}
