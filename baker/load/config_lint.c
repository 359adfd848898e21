/*
 * Keys that another key switches off (lmb_config_lint). A config is read key by key, and a
 * key whose effect depends on another one (a sky colour with no sky, a KTX2 format with no
 * KTX2 output) would otherwise be accepted and do nothing without a word: an artist
 * iterating on a config loses minutes to that. A key counts as set when its value differs
 * from the default: a key at its default loses nothing when it is switched off.
 * Paths are checked whether or not they are used.
 */
#include "load/config_file.h"

#include <lmbake/lmbake.h>

#include <string.h>

static int differs(const double *a, const double *b, int n)
{
    return memcmp(a, b, (size_t)n * sizeof *a) != 0;
}

/* "NAME has no effect: WHY" once per key. */
static void off(const lmb_log *log, const char *cfg_name, const char *key, const char *why)
{
    lmb_warn(log, "%s: key '%s' has no effect: %s", cfg_name, key, why);
}

lmb_status lmb_config_lint(const lmb_config *c, const lmb_log *log, lmb_error *err)
{
    lmb_config d;
    lmb_config_default(&d);
    const char *name = c->config_path[0] ? c->config_path : "config";
    int sky = c->sky_intensity > 0;
    if (c->sky_image[0]) {
        char real[4096];
        lmb_status st = lmb_config_file(c->config_path, "sky.image", c->sky_image, real, sizeof real, err);
        if (st != LMB_OK)
            return st;
        if (!sky)
            off(log, name, "sky.image", "sky.intensity is 0, which turns the sky off (leave sky.intensity out to light "
                                        "by the map's own radiance, intensity 1)");
    }
    const char *no_sky = "there is no sky (sky.intensity is 0; set it, or sky.image, for a sky)";
    if (!sky) {
        if (differs(c->sky_color, d.sky_color, 3))
            off(log, name, "sky.color", no_sky);
        if (differs(c->sky_ground, d.sky_ground, 3))
            off(log, name, "sky.ground_color", no_sky);
        if (differs(c->sky_up, d.sky_up, 3))
            off(log, name, "sky.up", no_sky);
        if (c->sky_samples != d.sky_samples)
            off(log, name, "sky.samples", no_sky);
    }
    if ((!sky || !c->sky_image[0]) && c->sky_rotation != d.sky_rotation)
        off(log, name, "sky.rotation", sky ? "the sky is uniform (no sky.image to turn)" : no_sky);
    if ((!sky || !c->sky_image[0]) && c->sky_cosine_only != d.sky_cosine_only)
        off(log, name, "sky.sampling", sky ? "the sky is uniform (no sky.image to sample)" : no_sky);
    if (!(c->output_formats & LMB_OUTPUT_KTX2)) {
        if (c->ktx2_format != d.ktx2_format)
            off(log, name, "output.ktx2_format", "output.formats has no ktx2");
        if (c->ktx2_zstd != d.ktx2_zstd)
            off(log, name, "output.ktx2_supercompression", "output.formats has no ktx2");
        if (c->ktx2_mipmaps != d.ktx2_mipmaps)
            off(log, name, "output.ktx2_mipmaps", "output.formats has no ktx2");
    }
    if (!(c->output_formats & LMB_OUTPUT_RGBM) && c->rgbm_range != d.rgbm_range)
        off(log, name, "output.rgbm_range", "output.formats has no rgbm");
    if (!c->directional && c->directional_rays != d.directional_rays)
        off(log, name, "samples.directional", "output.directional is false");
    if (c->bounces != LMB_AUTO) {
        if (c->bounces_max != d.bounces_max)
            off(log, name, "bounces_auto.max", "bounces is a number, not auto");
        if (c->bounces_tail != d.bounces_tail)
            off(log, name, "bounces_auto.tail", "bounces is a number, not auto");
    }
    if (c->gather_method == LMB_GATHER_COSINE) {
        if (c->amis_weights != d.amis_weights)
            off(log, name, "gather.amis_weights", "gather.method is cosine");
        if (c->amis_iterations != d.amis_iterations)
            off(log, name, "samples.amis_iterations", "gather.method is cosine");
    }
    if (c->gather_method != LMB_GATHER_AMIS_DEFENSIVE && c->defensive_fraction != d.defensive_fraction)
        off(log, name, "gather.defensive", "gather.method is not amis_defensive");
    if (c->guide_stride == 0 && c->guide_lobes != d.guide_lobes)
        off(log, name, "gather.lobes", "gather.guide_stride is 0 (no guided gathering)");
    if (!c->adaptive) {
        if (c->noise_target != d.noise_target)
            off(log, name, "samples.noise", "samples.adaptive is false");
        if (c->max_rays != d.max_rays)
            off(log, name, "samples.max_rays", "samples.adaptive is false");
    }
    if (!c->denoise_indirect && !c->denoise_direct) {
        if (c->denoise_levels != d.denoise_levels)
            off(log, name, "denoise.levels", "denoise.indirect and denoise.direct are false");
        if (c->denoise_strength != d.denoise_strength)
            off(log, name, "denoise.strength", "denoise.indirect and denoise.direct are false");
    }
    if (c->ic_error == 0) {
        if (c->ic_min_spacing != d.ic_min_spacing)
            off(log, name, "irradiance_cache.min_spacing", "irradiance_cache.error is 0 (a gather at every texel)");
        if (c->ic_max_spacing != d.ic_max_spacing)
            off(log, name, "irradiance_cache.max_spacing", "irradiance_cache.error is 0 (a gather at every texel)");
    }
    return LMB_OK;
}
