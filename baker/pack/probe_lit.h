/*
 * Props the light probes light when the texel budget cannot hold their charts (probe_lit.c).
 *
 * Every chart touches a few texels and is padded, whatever the density, so a prop drawn
 * thousands of times can take more texels than atlas.texels before any density is chosen
 * (10,000 copies of an 18-chart prop: about 1.2 million texels at any density). Lowering the
 * density then takes texels only from the surfaces that could use them. Engines light small,
 * numerous props with light probes instead (Unity's "Receive Global Illumination: Light
 * Probes", Unreal's volumetric lightmap for instanced foliage, bevy's irradiance volumes for
 * meshes without a lightmap): when no density keeps the budget, lmbake does the same for the
 * meshes drawn more than once whose charts cost the most texels per world area, until the
 * rest fits. They still cast shadows and bounce light; the probe grid covers their boxes.
 */
#ifndef LMBAKE_PROBE_LIT_H
#define LMBAKE_PROBE_LIT_H

#include "layout.h"

/* The charts' floor (what they take at any density) the kept instances may still have: at
 * most this share of the budget, so the density keeps the rest for their surfaces. */
#define LMB_PROBE_LIT_FLOOR_SHARE 0.5

typedef struct lmb_probe_lit_choice {
    uint32_t kept;          /* instances still lightmapped, written to keep[] */
    uint32_t moved;         /* instances moved to the probes (moved[i] = 1) */
    uint32_t moved_meshes;  /* their meshes */
    double kept_floor;      /* the kept instances' share of floor_texels (estimate) */
} lmb_probe_lit_choice;

/* Chooses what the probes light, for a layout l placed with the lightmapped instances
 * list[0..n) (area[k]: list[k]'s world area) whose charts take floor_texels at any density,
 * over `budget`. A mesh's share of the floor is estimated by its charts times its copies over
 * all charts placed; meshes drawn at least twice go, most floor texels per world area first
 * (mesh index breaks ties), until the kept floor is at most LMB_PROBE_LIT_FLOOR_SHARE of the
 * budget. forced (per mesh, may be NULL): meshes that go first whatever their cost (copies that
 * fit no atlas at any density). The last lightmapped mesh always stays. keep: n entries; moved: instance_count
 * bytes, zeroed here. Deterministic: it reads only the layout and the scene. Returns 0 with
 * out->moved == 0 when nothing can go; -1 when out of memory. */
int lmb_probe_lit_choose(const lmb_scene *scene, const lmb_layout *l, const uint32_t *list, uint32_t n,
                         const double *area, double floor_texels, uint64_t budget, const uint8_t *forced,
                         uint32_t *keep, uint8_t *moved, lmb_probe_lit_choice *out);

#endif
