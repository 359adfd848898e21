/*
 * Light probes: what moves through the level gets the baked light (docs/probes.md). A probe is
 * a point in free space holding the irradiance a small diffuse object there would receive
 * from every direction, all of the level's light: the direct light of every `baked` light and
 * the sky, and the light the level's surfaces reflect (read from the bounce cache as the final
 * gather reads it). Stored two ways:
 *   - SH L2 irradiance, RGB, 27 floats: E(n) ~ sum_lm E_lm Y_lm(n), with E_lm = A_l L_lm the
 *     radiance's coefficients convolved with the clamped cosine (Ramamoorthi and Hanrahan 2001:
 *     A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4), in the real SH basis and order of sky.c's sh9
 *     (glTF axes), the convention of EXT_lights_image_based's irradianceCoefficients;
 *   - an ambient cube: the irradiance for the six axis normals +X, -X, +Y, -Y, +Z, -Z, computed
 *     for those normals directly (not from the SH, whose truncation smooths it).
 * Values are lux (E) or E / pi like the lightmaps (output.scale), set at writing.
 *
 * Placement (placement.c): a grid of cells over the lightmapped geometry's bounds at
 * probes.spacing; a cell with surface in it is split into 8 and holds a probe at each child's
 * centre, an empty cell one at its centre (Godot and Unreal refine near geometry the same
 * way). Probes inside geometry (most rays that hit anything hit back faces) or far from every
 * surface (outside the level) are dropped. Then the light (probe_light.c), one step of the
 * bake per range of probes, so a farm splits it like texels.
 */
#ifndef LMBAKE_PROBES_H
#define LMBAKE_PROBES_H

#include <lmbake/lmbake.h>

#include "cache/bounce_cache.h"
#include "lights/direct.h"
#include "pack/layout.h"
#include "raytrace/rt_scene.h"
#include "steps/runner.h"
#include "write/gltf_write.h"

#define LMB_PROBE_SH 27   /* floats: 9 coefficients x RGB, coefficient-major (c0 r g b, c1 r g b, ...) */
#define LMB_PROBE_CUBE 18 /* floats: +X, -X, +Y, -Y, +Z, -Z, each r g b */
#define LMB_PROBES_MAX 1000000 /* 45 floats and a position each: 200 MB of output at most */

/* A grid of probes: the auto grid over the level, or a probes.volumes box. */
typedef struct lmb_probe_grid {
    double lo[3], cell[3]; /* corner and cell size per axis */
    uint32_t res[3];       /* cells per axis */
    uint32_t first_voxel;  /* its first voxel among all grids' */
    uint32_t volume;       /* 0: the auto grid; k: probes.volumes entry k (1-based) */
    int from_node;         /* a node's extras.lightmap_probes: lo and cell span the unit cube centred
                              on the origin, placed by world */
    double world[16];
    uint32_t node;         /* from_node: the glTF node, and its name */
    const char *node_name;
} lmb_probe_grid;

/* The Delaunay tetrahedra of a set of probe positions (tetrahedra.c, qhull): 4 probe indices
 * each, positive volume, flat ones dropped. Fewer than 4 probes, or all in a plane: none, and
 * `why` says what qhull said. */
typedef struct lmb_probe_tetrahedra_out {
    uint32_t *tetrahedra; /* 4 per tetrahedron */
    uint32_t count;
    uint32_t flat;        /* flat tetrahedra dropped */
    char why[256];
} lmb_probe_tetrahedra_out;

typedef struct lmb_probe_set {
    uint32_t count;
    double *position;  /* 3 per probe, world */
    float *sh;         /* LMB_PROBE_SH per probe, lux */
    float *cube;       /* LMB_PROBE_CUBE per probe, lux */
    double spacing;    /* the auto grid's cell size, world units (probes near surfaces: half of it) */
    uint32_t refined;  /* auto grid cells split because they hold surface */
    uint32_t moved;  /* probes moved out of geometry or off a surface (virtual offset) */
    uint32_t wall_probes; /* probes added on both sides of walls the tetrahedra crossed (wall_probes.c) */
    uint32_t dropped_inside, dropped_outside;
    uint32_t rays;     /* rays per probe (probes.rays) */
    uint32_t *cell;    /* per probe: its voxel among all grids' (lmb_probe_grid.first_voxel + x fastest) */
    lmb_probe_grid *grids;
    lmb_probe_tetrahedra_out tets; /* the placed set's tetrahedra once made (lmb_probe_set_tetrahedra) */
    int tets_made;
    uint32_t grid_count; /* the auto grid (probes.auto) first, then each probes.volumes entry, then
                            each node's extras.lightmap_probes */
} lmb_probe_set;

/* An irradiance volume as bevy reads one (IrradianceVolume: a unit cube centred on the origin,
 * placed by its transform): the grid's box and per voxel the ambient cube. */
typedef struct lmb_probe_volume {
    double lo[3], hi[3];
    uint32_t res[3];
    float *cube;       /* LMB_PROBE_CUBE per voxel, x fastest, then y, then z */
    uint32_t filled;   /* voxels whose probes were all dropped (inside geometry), filled from neighbours */
} lmb_probe_volume;

/* Grid g of the set as a volume (probe_volume.c): a voxel per cell, the mean of its probes'
 * cubes (the set's, or `cube`'s when not NULL: LMB_PROBE_CUBE per probe, a light group's); a cell
 * with none (inside geometry) takes the mean of its neighbours', pass by pass, so that trilinear
 * filtering next to walls does not read black. */
lmb_status lmb_probe_volume_make(const lmb_probe_set *set, uint32_t g, const float *cube, lmb_probe_volume *out,
                                 lmb_error *err);
void lmb_probe_volume_free(lmb_probe_volume *v);

/* The volume in bevy's layout as KTX2 (E5B9G9R9, vkFormat 123, no supercompression): a texture
 * of (Rx, 2 Ry, 3 Rz) texels, voxel (x, y, z)'s face +A at (x, y, z + k Rz) and -A at
 * (x, y + Ry, z + k Rz), k = 0, 1, 2 for A = X, Y, Z; values times `scale`. */
lmb_status lmb_probe_volume_write_ktx2(const lmb_probe_volume *v, double scale, const char *path, lmb_error *err);

/* Places the probes of the level (probes.auto, then probes.volumes and the nodes whose
 * extras.lightmap_probes asks for a volume: a probe at each cell's centre, dropped inside
 * geometry) into out. Empty (count 0) when there are none. */
lmb_status lmb_probes_place(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, const lmb_rt *rt,
                            const lmb_log *log, lmb_probe_set *out, lmb_error *err);

/* Lights the placed probes as one step of the bake (steps/runner.h): direct light from
 * `direct`, reflected light from the finished cache, rounds of probes.rays directions until
 * samples.noise (samples.adaptive). dark: nothing emits (all zero, no rays). */
lmb_status lmb_probes_light(lmb_probe_set *set, const lmb_config *cfg, const lmb_direct *direct,
                            const lmb_cache *cache, lmb_steps *steps, int dark, lmb_progress_fn progress, void *user,
                            const lmb_log *log, lmb_error *err);

void lmb_probe_set_free(lmb_probe_set *set);

/* The auto grid's voxel holding world point q, or the edge voxel for q less than a cell outside
 * the grid (UINT32_MAX: no auto grid, or q farther out): where a probe moved or added after
 * placement counts in the irradiance volume. */
uint32_t lmb_probe_voxel_of(const lmb_probe_set *set, const double q[3]);

/* Adds probes on both sides of every wall (lightmapped geometry: not a prop the probes light) an
 * edge of the probes' tetrahedra crosses, `offset` in front of it, none within `spacing` of
 * another probe (wall_probes.c), at most up to `limit`
 * probes in all; `inside` says whether a point is inside geometry. Before the probes are lit
 * (set->sh and set->cube not yet allocated). */
lmb_status lmb_probes_line_walls(lmb_probe_set *set, const lmb_layout *layout, const lmb_rt *rt,
                                 double offset, double spacing, uint32_t limit, int threads,
                                 int (*inside)(const lmb_rt *rt, const double p[3]), lmb_error *err);

/* The Delaunay tetrahedra of the probe positions (lmb_probe_tetrahedra). */
lmb_status lmb_probe_tetrahedra(const lmb_probe_set *set, lmb_probe_tetrahedra_out *out, lmb_error *err);
void lmb_probe_tetrahedra_free(lmb_probe_tetrahedra_out *out);
/* The placed set's tetrahedra into set->tets, unless made already (or read back with the set
 * from a layout cache, watch/probe_cache.h): made once, for the output. */
lmb_status lmb_probe_set_tetrahedra(lmb_probe_set *set, lmb_error *err);
/* The set as the output holds it (probe_output.c): owned arrays, free with lmb_probes_output_free
 * (also after an error), the tetrahedra the set's (made here when not yet); its grid as DIR/STEM-irradiance-volume.ktx2 (bevy's layout). Empty, no
 * file, when the set is. */
lmb_status lmb_probes_output(lmb_probe_set *set, const lmb_config *cfg, const char *dir, const char *stem,
                             const lmb_log *log, lmb_gltf_probes *out, lmb_error *err);
/* Light groups: group g's own probes' light (sh_lux, cube_lux: LMB_PROBE_SH and LMB_PROBE_CUBE per
 * probe, lux, as lmb_probe_set holds them; a group of one source at intensity 1; NULL: dark) into
 * out, in the output's scale, with its scale and intensity (RGB, what the game multiplies it by),
 * and each of the set's grids as the group's own bevy volume, DIR/<the grid's volume
 * name>-group-NAME.ktx2 (out->volumes[k].group_uri[g]); out->groups = g + 1. */
lmb_status lmb_probes_output_group(lmb_gltf_probes *out, const lmb_probe_set *set, const lmb_config *cfg,
                                   const char *dir, const char *stem, uint32_t g, const char *name, double scale,
                                   const double intensity[3], const float *sh_lux, const float *cube_lux,
                                   lmb_error *err);
void lmb_probes_output_free(lmb_gltf_probes *out);

#endif
