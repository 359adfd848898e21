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

/* The direct stage's options (lights/direct.h) from cfg. */
lmb_direct_options lmb_direct_options_of(const lmb_config *cfg);

#endif
