/* Each stage's options from the bake's config (stage_options.h). */
#include "stage_options.h"

lmb_direct_options lmb_direct_options_of(const lmb_config *cfg)
{
    lmb_direct_options o = {0};
    o.samples = cfg->direct_samples;
    o.sky_samples = cfg->sky_samples;
    o.texel_samples = cfg->texel_samples;
    o.sun_angle = cfg->sun_angle;
    o.seed = cfg->seed;
    o.threads = cfg->threads;
    o.directional = cfg->directional;
    o.adaptive = cfg->adaptive;
    o.noise_target = cfg->noise_target;
    o.max_rays = cfg->max_rays;
    o.light_scale = cfg->light_intensity_scale;
    return o;
}

lmb_sky_options lmb_sky_options_of(const lmb_config *cfg)
{
    lmb_sky_options o = {0};
    o.intensity = cfg->sky_intensity;
    for (int k = 0; k < 3; k++) {
        o.color[k] = cfg->sky_color[k];
        o.ground[k] = cfg->sky_ground[k];
        o.up[k] = cfg->sky_up[k];
    }
    o.image = cfg->sky_image;
    o.config_path = cfg->config_path;
    o.rotation = cfg->sky_rotation;
    o.cosine_only = cfg->sky_cosine_only;
    return o;
}

lmb_emitter_options lmb_emitter_options_of(const lmb_config *cfg)
{
    lmb_emitter_options o = {cfg->emission_sides, cfg->emissive_scale, 0};
    return o;
}
