/*
 * The watch's variants of a bake's config: the quick look, and the direct light of named
 * lights (lmb_config_direct_of, at the end).
 *
 * The quick look of `lmbake preview --watch` and `lmbake bake --quick` (docs/watch.md): a
 * quarter of the texels (half the texel density each way: its own, coarser layout, which the
 * preview loads whole) lit with a quarter of the direct light's, the final gather's and the
 * bounce passes' rays, no adaptive sampling (on level-single-10 it cost 0.5-0.8 s of a 5 s quick
 * look for 0.04-0.2 points of the composed picture's error), cosine final gathering, the irradiance cache twice as
 * sparse, no seam stitching and no probes, at most two bounce passes (with bounces auto: the
 * tail extrapolated from them covers the rest), and no EXR, KTX2, RGBM, mask or direction maps
 * (the .hdr the page reads and the .png beside it are always written). What would bias the
 * picture stays: the gather points per texel (one instead of four made cornell-point
 * 7% darker near its lamp) and a fixed bounce count (3 of 4 bounces: 3.7% darker). The denoiser
 * stays on: it is what makes a few rays look like the final picture.
 */
#include <lmbake/lmbake.h>

#include <stdio.h>
#include <string.h>

static uint32_t fraction(uint32_t value, uint32_t divisor, uint32_t floor)
{
    uint32_t v = value / divisor;
    return v < floor ? (value < floor ? value : floor) : v;
}

void lmb_config_quick(lmb_config *cfg)
{
    /* a quarter of the texels: half the density each way */
    if (cfg->texel_density > 0)
        cfg->texel_density /= 2;
    else
        cfg->atlas_texels = lmb_config_atlas_texels(cfg) / 4;
    for (uint32_t i = 0; i < cfg->density_override_count; i++)
        cfg->density_overrides[i].texel_density /= 2;
    cfg->direct_samples = fraction(cfg->direct_samples, 4, 4);
    cfg->adaptive = 0;
    cfg->gather_rays = fraction(cfg->gather_rays, 4, 16);
    /* cosine final gathering: with a quarter of the rays AMIS's pilot and guide cost more than
     * they save (level-single-10 4.27 -> 3.65 s, bevy's Cornell box 4.2 -> 2.6 s; the composed
     * picture's error 12.96 -> 12.34% and a quick look's own noise 1.38 -> 1.65%) */
    cfg->gather_method = LMB_GATHER_COSINE;
    cfg->bounce_rays = fraction(cfg->bounce_rays, 4, 8);
    cfg->bounce_rays_high = fraction(cfg->bounce_rays_high ? cfg->bounce_rays_high : cfg->bounce_rays, 2, 4);
    cfg->directional_rays = fraction(cfg->directional_rays, 4, 4);
    cfg->sky_samples = fraction(cfg->sky_samples, 4, 8);
    if (cfg->ic_error > 0)
        cfg->ic_error *= 2;
    cfg->seam_stitch = 0;
    cfg->probes_auto = 0;
    cfg->probe_volume_count = 0;
    /* at most two bounce passes before the final gather; the auto tail extrapolates the rest
     * from their ratio (a fixed count is kept) */
    if (cfg->bounces == LMB_AUTO && cfg->bounces_max > 3)
        cfg->bounces_max = 3;
    /* what the page reads: the .hdr (written with the .png whatever the formats), no direction maps */
    cfg->output_formats = LMB_OUTPUT_HDR;
    cfg->directional = 0;
}

/*
 * `bake --direct-of`: the direct light of the named lights alone, at the bake's layout and
 * sampling (one light's share of a bake, for a script that relights a level light by light;
 * the watch itself takes the direct light from its own bakes, watch/stages_out.h). Everything else that
 * lights the level is left out (other lights realtime through lmb_scene_set_light_modes, no sky,
 * no emission, no bounces); the lights' own modes stay (an `indirect` light has no direct light in
 * the lightmap here either). The layout keys are untouched: the layout and the gather points'
 * validity are the bake's (read back from a layout cache).
 */
lmb_status lmb_config_direct_of(lmb_config *cfg, const char *const *names, uint32_t count, lmb_error *err)
{
    if (count > LMB_MAX_DIRECT_OF)
        return lmb_error_set(err, LMB_ERR_USAGE, "--direct-of: at most %d lights", LMB_MAX_DIRECT_OF);
    for (uint32_t i = 0; i < count; i++) {
        if (strlen(names[i]) >= LMB_PATTERN_LEN)
            return lmb_error_set(err, LMB_ERR_USAGE, "--direct-of: '%.40s...' is longer than %d characters", names[i],
                                 LMB_PATTERN_LEN - 1);
        snprintf(cfg->direct_of[i], LMB_PATTERN_LEN, "%s", names[i]);
    }
    cfg->direct_of_count = count;
    cfg->bounces = 0;
    cfg->sky_intensity = 0;
    cfg->sky_image[0] = '\0';
    cfg->emissive_scale = 0;
    cfg->seam_stitch = 0;
    cfg->output_formats = LMB_OUTPUT_HDR;
    cfg->directional = 0;
    cfg->shadowmask = 0;
    return LMB_OK;
}
