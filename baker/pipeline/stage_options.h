/*
 * Each stage's options from the bake's config: the whole lmb_config stays in the driver
 * (pipeline/), and a stage sees only what it uses, in its own struct (as xatlas's
 * ChartOptions / PackOptions). The lighting stages' intensities (what an artist dials about a
 * light) are kept apart from their sampling inputs there, so that a sampling decision can be
 * shown not to read them.
 */
#ifndef LMBAKE_STAGE_OPTIONS_H
#define LMBAKE_STAGE_OPTIONS_H

#include <lmbake/lmbake.h>

#include "lights/direct.h"
#include "lights/sky.h"

/* The direct stage's options (lights/direct.h) from cfg. */
lmb_direct_options lmb_direct_options_of(const lmb_config *cfg);

/* The emitters' options (lights/direct.h) from cfg. */
lmb_emitter_options lmb_emitter_options_of(const lmb_config *cfg);

/* The sky's options (lights/sky.h) from cfg: its strings point into cfg. */
lmb_sky_options lmb_sky_options_of(const lmb_config *cfg);

#endif
