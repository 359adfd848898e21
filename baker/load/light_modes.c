/*
 * Per-light bake modes (mixed lighting, docs/mixed-lighting.md): a light is
 * `baked` (direct and bounced light in the lightmap), `indirect` (only its bounced light: the
 * engine draws its direct light and shadows in real time, as Unity's Baked Indirect and
 * Shadowmask modes and Godot's "dynamic" bake mode) or `realtime` (left out of the bake). The
 * file says it in a light's (or its node's) extras.lightmap_mode; the config's lights.modes
 * globs win over the file. With output.shadowmask the first 4 `indirect` lights get a channel
 * of the shadowmask, which holds their visibility per texel.
 */
#include <lmbake/lmbake.h>

#include <stdio.h>
#include <string.h>

static const char *const mode_names[] = {"baked", "indirect", "realtime"};

int lmb_light_mode_parse(const char *name, lmb_light_mode *mode)
{
    for (int i = 0; i < 3; i++)
        if (!strcmp(name, mode_names[i])) {
            *mode = (lmb_light_mode)i;
            return 0;
        }
    return -1;
}

const char *lmb_light_mode_name(lmb_light_mode mode)
{
    return mode >= LMB_LIGHT_BAKED && mode <= LMB_LIGHT_REALTIME ? mode_names[mode] : "?";
}

void lmb_scene_set_light_modes(lmb_scene *s, const lmb_config *cfg, const lmb_log *log)
{
    uint32_t used[LMB_MAX_PATTERNS] = {0}, mixed = 0, channels = 0;
    for (uint32_t i = 0; i < s->light_count; i++) {
        lmb_light *l = &s->lights[i];
        for (uint32_t k = 0; k < cfg->light_mode_count; k++)
            if (lmb_glob_match(cfg->light_modes[k].pattern, l->name) ||
                lmb_glob_match(cfg->light_modes[k].pattern, l->node_name)) {
                l->mode = (lmb_light_mode)cfg->light_modes[k].mode;
                used[k]++;
                break;
            }
        int named = !cfg->direct_of_count; /* bake --direct-of: only the named lights */
        for (uint32_t k = 0; !named && k < cfg->direct_of_count; k++)
            named = lmb_glob_match(cfg->direct_of[k], l->name) || lmb_glob_match(cfg->direct_of[k], l->node_name);
        if (!named)
            l->mode = LMB_LIGHT_REALTIME;
        l->shadowmask_channel = -1;
        mixed += l->mode != LMB_LIGHT_BAKED;
    }
    for (uint32_t k = 0; k < cfg->light_mode_count; k++)
        if (!used[k])
            lmb_warn(log, "lights.modes '%s' matches no light or light node name in %s", cfg->light_modes[k].pattern,
                     s->path);
    char extra[512] = "";
    uint32_t extras = 0;
    for (uint32_t i = 0; cfg->shadowmask && i < s->light_count; i++) {
        lmb_light *l = &s->lights[i];
        if (l->mode != LMB_LIGHT_INDIRECT)
            continue;
        if (channels < LMB_SHADOWMASK_CHANNELS) {
            l->shadowmask_channel = (int)channels++;
            continue;
        }
        size_t len = strlen(extra);
        snprintf(extra + len, sizeof extra - len, "%s'%s'", extras ? ", " : "", l->name);
        l->mode = LMB_LIGHT_BAKED; /* no channel: its shadows would be lost, so it is baked whole */
        extras++;
    }
    if (extras)
        lmb_warn(log, "output.shadowmask holds 4 lights; %u more indirect light(s) are baked instead: %s", extras, extra);
    if (cfg->shadowmask && !channels)
        lmb_warn(log, "output.shadowmask: no light is `indirect` (lights.modes or extras.lightmap_mode): no shadowmask "
                 "is written");
    for (uint32_t i = 0; mixed && i < s->light_count; i++) {
        const lmb_light *l = &s->lights[i];
        if (l->shadowmask_channel >= 0)
            lmb_info(log, "light '%s': %s, shadowmask channel %c", l->name, lmb_light_mode_name(l->mode),
                     "RGBA"[l->shadowmask_channel]);
        else
            lmb_info(log, "light '%s': %s", l->name, lmb_light_mode_name(l->mode));
    }
}
