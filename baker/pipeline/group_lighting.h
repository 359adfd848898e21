/*
 * The lighting of a level with light groups (lights/light_groups.h; docs/light-groups.md): the
 * lighting passes (lighting.h) and the probes run once per group, each with that group's light
 * sources alone at their own intensities, or a group of one light with it at unit intensity and
 * white (lmb_light_groups.unit) (the other lights left out as realtime lights are, the
 * sky and the emitters only in the group that holds them), and each group's light is kept apart:
 * its dilated images, its directions and its probes. Then (lmb_group_compose) the cache and the
 * probes hold their sum at the groups' scales: what the bake writes as the level's lightmap, and
 * the sum a game computes from the groups' own files.
 * Every group runs the same steps in every farm process (steps/runner.h): a group's rays, its
 * records and its decisions depend on its own lights only, never on another group or a scale.
 * Costs one lighting per group in time; each group's images are kept out of memory while no stage
 * reads them (group_store.h).
 */
#ifndef LMBAKE_GROUP_LIGHTING_H
#define LMBAKE_GROUP_LIGHTING_H

#include "pipeline/lighting.h"
#include "lights/light_groups.h"
#include "lights/point_validity.h"
#include "probes/probes.h"

/* Each group's light, kept: [g x atlases + a] per atlas image (3 floats per atlas texel,
 * dilated), directions (output.directional, else NULL) and per probe its SH and ambient cube. */
typedef struct lmb_group_light {
    uint32_t groups, atlases;
    float **irradiance;
    float **direction;
    float **sh, **cube;     /* [g]: the probe set's arrays for that group (NULL without probes) */
    lmb_ic_points *records; /* [g]: the group's final-gather records (owned) */
    uint8_t (*key)[32];     /* [g]: its key in the cache between bakes (group_cache.h), when kept */
    uint8_t *cached;        /* [g]: 1 when read back from that cache (its post stage done) */
    uint64_t *texels;       /* [a]: the atlas's width x height (its images hold 3 floats per texel) */
    int *file;              /* [g]: the file its images are put away in (group_store.h), -1: none yet */
    uint8_t *away;          /* [g]: 1 while its images are in that file only (their pointers NULL) */
    int in_memory;          /* 1: a file could not be made or written; the images stay in memory */
} lmb_group_light;

/* What a group's lighting needs (the bake driver's, borrowed). */
typedef struct lmb_group_env {
    lmb_scene *scene;
    const lmb_config *cfg;
    const lmb_direct_options *direct_opt;
    const lmb_rt *rt;
    const lmb_emitters *emitters;
    const lmb_sky *sky;
    lmb_cache *cache;
    lmb_steps *steps;
    const lmb_lighting_hooks *hooks; /* progress only: the stages' light is not handed out per group */
    lmb_point_validity *validity;    /* the gather points' validity memo, or NULL */
    lmb_probe_set *probes;           /* placed, or NULL (no probes lit) */
    int keep;                        /* this process writes the output: each group's light is kept */
    const char *cache_dir;           /* with keep: the groups' light kept between bakes here
                                        (group_cache.h; the layout cache's folder), or NULL */
    const lmb_log *log;
} lmb_group_env;

/* Every group's lighting in turn (stats: the first group's figures, the rays of all; records: the
 * last group's final-gather records); with env->keep, each group's light into *out, and with
 * env->cache_dir a group whose key is there read back instead of lit (out->cached). */
lmb_status lmb_group_lighting(const lmb_group_env *env, const lmb_light_groups *groups, lmb_bake_stats *stats,
                              lmb_ic_points *records, lmb_group_light *out, lmb_error *err);

/* Group g's images into the cache (swapped: the cache's go into the group's place), so that a
 * stage working on the cache (fireflies, seams) works on group g; swap again to put them back. */
void lmb_group_swap(lmb_group_light *gl, uint32_t g, lmb_cache *cache);

/* The cache's images and directions and the probes' light := the groups' sum at their scales:
 * E = sum_g s_g w_g E_g per texel (in double, in group order; E_g the group's light as lit and as
 * its own files hold it, w_g its weight: lmb_light_groups.weight, per channel, the intensity the
 * glTF names); the direction D = sum_g s_g |w_g E_g|
 * D_g / |E| (|.|: luminance; each group's D weighted by its light, as lighting.c makes D from
 * the light's parts), at most unit length. */
lmb_status lmb_group_compose(const lmb_light_groups *groups, const lmb_group_light *gl, lmb_cache *cache,
                             lmb_probe_set *probes, lmb_error *err);

void lmb_group_light_free(lmb_group_light *gl);

#endif
