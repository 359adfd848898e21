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
