/*
 * Light groups (output.light_groups, a light's extras.lightmap_group; docs/light-groups.md):
 * which of the level's light sources each group holds. The bake lights every group on its own
 * (its lights alone, at their own intensities) and writes a lightmap per group; the lightmap it
 * writes as the level's is their sum at the groups' scales, the same sum a game computes to
 * switch or dim the groups at run time. Light is linear in its sources, so each group's
 * lightmap is what a bake of that group's lights alone gives, and no group's sampling reads
 * another's light or any group's scale: the sum at other scales is exact.
 *
 * A group that holds one light is lit with it at unit intensity and white, then weighed by its
 * intensity and colour: the light of a single light is linear in both, so an edit of either is a
 * new weight, and the bake of the edited level composes the same floats. Its own files hold the
 * light at 1; the glTF names the weight (`intensity`) for the game to multiply. So is the config's sky
 * alone in a group (sky.intensity, and sky.color when no ground colour is set: the sky's radiance
 * is then the colour times one map or one constant, and its samples follow the map alone), and the
 * emissive surfaces alone when they share one emission.
 *
 * Which group a source is in: a light's extras.lightmap_group (its own, else its node's); else
 * the first config group whose match its name or node name matches; the sky and the emissive
 * surfaces: the first group with sky: true / emissive: true. What no group claims goes to a
 * group named "rest" (made when needed). Realtime lights are in no group (they are not baked).
 * A config entry with one_per_light gives each light it matches a group of its own, named after
 * the light, after the named groups; one with no match (every light) gives the sky and the
 * emissive surfaces theirs too ("sky", "emissive") unless an entry claims them. When they do not
 * all fit in LMB_MAX_LIGHT_GROUPS with the rest's, the sources that rank lowest (rank_order: a
 * directional light first, then the sky, then by power) share "rest" and the log names them.
 */
#ifndef LMBAKE_LIGHT_GROUPS_H
#define LMBAKE_LIGHT_GROUPS_H

#include <lmbake/lmbake.h>

typedef struct lmb_light_groups {
    uint32_t count; /* 0: the level has no groups (one lightmap, as without the key) */
    char name[LMB_MAX_LIGHT_GROUPS][LMB_PATTERN_LEN];
    double scale[LMB_MAX_LIGHT_GROUPS];
    uint32_t lights[LMB_MAX_LIGHT_GROUPS]; /* how many of the level's lights each holds */
    int32_t *of_light;                     /* per scene light: its group, -1 (realtime: in none) */
    uint8_t *merged;                       /* per scene light: 1 when one_per_light gave it no group of its
                                              own (more lights than groups; it ranks lowest) but `rest` */
    int32_t sky, emissive;                 /* the group holding the sky / the emissive surfaces, -1 none */
    int sky_merged, emissive_merged;       /* one_per_light gave the sky / the emissive surfaces no group of
                                              their own (more sources than groups; they rank lowest) but `rest` */
    /* A group of one light (neither the sky nor the emissive surfaces) is lit with that light at
     * intensity 1 and white (unit), and weighed by its intensity x colour (weight, per channel);
     * a group of the config's sky alone is lit at sky.intensity 1 and weighed by it (and at
     * sky.color white, weighed by it, when lmb_sky_color_is_weight); a group of
     * the emissive surfaces alone, when they share one emission (factor x strength x
     * lights.emissive_scale; textures only on one material), is lit at emission 1 and weighed by
     * it: an edit of those is a new weight, not a new lighting. Other groups: weight 1 1 1. */
    int unit[LMB_MAX_LIGHT_GROUPS];
    int sky_color_weight; /* the sky's unit group is lit at sky.color white too (lmb_sky_color_is_weight) */
    double weight[LMB_MAX_LIGHT_GROUPS][3];
} lmb_light_groups;

/* The groups of scene s under cfg (after lmb_scene_set_light_modes). has_sky: whether the level
 * has a sky; emissive_power: its emissive surfaces' power (lmb_emitters_power; 0: none). Errors (LMB_ERR_INPUT, nothing baked): a
 * config group that ends up holding no light source (named with its line), a light's group
 * that would make more than LMB_MAX_LIGHT_GROUPS (the file, light and node named), groups with
 * output.shadowmask. Free with lmb_light_groups_free. */
lmb_status lmb_light_groups_resolve(const lmb_scene *s, const lmb_config *cfg, int has_sky, double emissive_power,
                                    lmb_light_groups *out, lmb_error *err);
void lmb_light_groups_free(lmb_light_groups *g);

/* Whether a unit sky group's colour is a weight too: the config sets no ground colour, so the
 * sky's radiance is sky.color x intensity x (its image or 1) everywhere and a sky lit at white
 * draws its samples by the image's luminance alone, whatever the colour. With a ground colour the
 * ground is not tinted by sky.color, and the two colours' ratio decides where samples go. */
int lmb_sky_color_is_weight(const lmb_config *cfg);

/* The log's line: each group, what it holds and its scale. */
void lmb_light_groups_report(const lmb_light_groups *g, const lmb_scene *s, const lmb_log *log);

#endif
