/*
 * libFuzzer target: the plan's layout decoder (baker/steps/plan_codec.c). Plans come from a
 * farm's shared folder, so their bodies are input too: the checksum catches damage, not
 * malice. Each input is decoded as a plan body for one scene (LMB_FUZZ_PLAN_SCENE, loaded
 * once); a decoded layout is encoded again and must give the same bytes.
 * Seed: `LMB_FUZZ_PLAN_SEED=FILE fuzz_plan -runs=0` writes the scene's own layout to FILE
 * (tools/fuzz.sh does this; exiting inside a callback would count as a crash).
 */
#include "steps/plan_codec.h"
#include "fuzz_common.h"

#include <lmbake/lmbake.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

/* The scene, loaded on the first input and kept for the process (harness state). */
static lmb_scene *scene;

static void load_scene(void)
{
    const char *path = getenv("LMB_FUZZ_PLAN_SCENE");
    lmb_error err;
    lmb_config cfg;
    lmb_config_default(&cfg);
    if (!path || lmb_scene_load(path, &cfg, &scene, NULL, &err) != LMB_OK) {
        fprintf(stderr, "fuzz_plan: set LMB_FUZZ_PLAN_SCENE to a loadable scene (%s)\n", path ? err.message : "unset");
        abort();
    }
    lmb_scene_select_lightmapped(scene, &cfg);
    const char *seed = getenv("LMB_FUZZ_PLAN_SEED");
    if (seed) {
        lmb_layout l;
        uint8_t *bytes = NULL;
        size_t n = 0;
        cfg.atlas_texels = 4096; /* a small layout: a short seed */
        if (lmb_layout_build(scene, &cfg, NULL, NULL, NULL, &l, &err) != LMB_OK ||
            lmb_plan_encode(&l, &bytes, &n, &err) != LMB_OK)
            abort();
        FILE *f = fopen(seed, "wb");
        if (!f || fwrite(bytes, 1, n, f) != n || fclose(f) != 0)
            abort();
        free(bytes);
        lmb_layout_free(&l);
    }
}

/* libFuzzer calls this once before any input (the replay driver does not: the first input loads). */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    load_scene();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!scene)
        load_scene();
    lmb_layout l;
    lmb_error err;
    if (lmb_plan_decode("fuzz.plan", data, size, scene, &l, &err) == LMB_OK) {
        uint8_t *again = NULL;
        size_t n = 0;
        if (lmb_plan_encode(&l, &again, &n, &err) != LMB_OK || n != size || memcmp(again, data, size))
            abort(); /* a decoded layout must encode to the same bytes */
        free(again);
    }
    lmb_layout_free(&l);
    return 0;
}
