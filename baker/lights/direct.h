/*
 * Direct light at gather points (the "direct" step of the pipeline): KHR_lights_punctual
 * point and spot lights (candela, inverse square, the spec's range window and smooth cone
 * falloff), directional lights (lux), and emissive triangles as area lights (nits), each
 * with Embree shadow rays. Output: irradiance E (lux) per texel, linear RGB, before albedo.
 * Also marks texels whose points lie inside geometry invalid (most rays from them hit back
 * faces), so light does not leak under walls and shadows do not leak out.
 */
#ifndef LMBAKE_DIRECT_H
#define LMBAKE_DIRECT_H

#include "lights/sky.h"
#include "raytrace/rt_scene.h"
#include "load/textures.h"
#include "texels/texels.h"
#include "util/rng.h"

typedef struct lmb_emitters lmb_emitters; /* opaque: emissive triangles and their power CDF */

/* What the emitters take of the config: emission_sides (lights.emission_sides: front only, or
 * both where the material is double-sided) and scale (lights.emissive_scale, an intensity:
 * multiplies every emissive material's emission; 0: nothing emits). unit: every emissive
 * triangle emits 1 (times its texture) instead of its material's emission x scale: the
 * emitters of a unit light group (light_groups.h), whose emission is its weight. */
typedef struct lmb_emitter_options {
    lmb_emission_sides emission_sides;
    double scale;
    int unit;
} lmb_emitter_options;

/* Emissive triangles of every instance; `textures` (may be NULL) holds decoded emissive
 * textures, which multiply the material's emissive factor x strength. */
lmb_status lmb_emitters_build(const lmb_scene *scene, const lmb_emitter_options *opt, const lmb_textures *textures,
                              lmb_emitters **out, lmb_error *err);
void lmb_emitters_free(lmb_emitters *e);
uint32_t lmb_emitters_count(const lmb_emitters *e);
/* Their power, pi x sum of area x luminance of the emission (x 2 for a surface emitting from
 * both sides; a texture's mean): what the light groups rank them by; 0 without emitters. */
double lmb_emitters_power(const lmb_emitters *e);

typedef struct lmb_direct lmb_direct; /* opaque: a scene's lights ready to evaluate at any point */

/* What the direct stage takes of the bake's config (the driver fills it from lmb_config:
 * pipeline/stage_options.h). The sampling inputs come first; what an artist dials about the
 * light itself (light_scale) is kept apart, so that no sampling decision need read it. */
typedef struct lmb_direct_options {
    uint32_t samples;       /* samples.direct: area-light, sun-disc and many-light samples per point */
    uint32_t sky_samples;   /* sky.samples */
    uint32_t texel_samples; /* samples.texel: gather points per texel */
    double sun_angle;       /* lights.sun_angle, degrees: the sun's disc (0: a direction) */
    uint64_t seed;          /* the bake's seed: keys every random stream */
    uint32_t threads;       /* 0: OpenMP's default */
    int directional;        /* output.directional: keep each texel's light direction */
    int adaptive;           /* samples.adaptive: more rounds where a texel's noise is above noise_target */
    double noise_target;    /* samples.noise */
    uint32_t max_rays;      /* samples.max_rays: a texel's most rays */
    double light_scale;     /* lights.intensity_scale: multiplies every punctual light's intensity */
} lmb_direct_options;

/* The lights of scene (punctual from scene->lights, area from emitters, the sky if not NULL),
 * for any number of threads at once. Copies opt; borrows everything else it is given; free with
 * lmb_direct_free. */
lmb_status lmb_direct_create(const lmb_scene *scene, const lmb_direct_options *opt, const lmb_rt *rt,
                             const lmb_emitters *emitters, const lmb_sky *sky, lmb_direct **out, lmb_error *err);
void lmb_direct_free(lmb_direct *d);

/* 0 when nothing in the scene emits light (no punctual light that the config keeps, no
 * emissive triangle, no sky): every lightmap is exactly 0 and no gather needs to run. */
int lmb_direct_any_light(const lmb_direct *d);

/* A point on a surface: position, shading and geometric normals (unit, front side) and the
 * offset along ng that rays start from (so they do not hit the surface itself). */
typedef struct lmb_shading_point {
    double p[3], n[3], ng[3];
    double eps;
} lmb_shading_point;

/* Direct irradiance at sp (lux, RGB) from every light with shadow rays; rng drives area-light
 * and many-light sampling, `samples` of each (0: samples.direct, and sky.samples for the sky; a
 * caller that averages many evaluations, as gather rays and reference paths do, passes 1). A
 * directional light with lights.sun_angle > 0 is a disc sampled `samples` times. Returns the
 * rays traced.
 * dir (may be NULL): the sum over contributions of their luminance times their direction
 * (unit, toward the light): the direct part of the texel's light direction (lmb_direction). */
uint32_t lmb_direct_at(const lmb_direct *d, const lmb_shading_point *sp, uint32_t samples, lmb_rng *rng, double e[3],
                       double dir[3]);

/* lmb_direct_at, and deferred (may be NULL) := the part of e from `indirect` lights (mixed
 * lighting: their direct light is not in the lightmap, their bounced light is). */
uint32_t lmb_direct_at_split(const lmb_direct *d, const lmb_shading_point *sp, uint32_t samples, lmb_rng *rng,
                             double e[3], double dir[3], double deferred[3]);

/* Which lights lmb_direct_draw evaluates: those without noise (up to 8 point and spot lights
 * evaluated one by one, suns without a disc) and those that are sampled (emissive triangles,
 * sun discs, many point lights, the sky). A texel evaluates the first once and the second in
 * rounds until its noise target (texel_direct.c). */
enum { LMB_DIRECT_EXACT = 1, LMB_DIRECT_SAMPLED = 2, LMB_DIRECT_ALL = 3 };

typedef struct lmb_direct_draw {
    uint32_t parts;       /* LMB_DIRECT_EXACT | LMB_DIRECT_SAMPLED */
    uint32_t samples;     /* area-light, sun-disc and many-light samples (0: samples.direct) */
    uint32_t sky_samples; /* 0: sky.samples */
    uint64_t sequence;    /* key of the point's scrambled Sobol points (util/qmc.h) for area lights and sun discs */
    uint32_t first;       /* index of this draw's first sample in them: a later round continues the sequence */
} lmb_direct_draw;

/* lmb_direct_at_split with the draw spelled out (what, how many, which QMC points). */
uint32_t lmb_direct_eval(const lmb_direct *d, const lmb_shading_point *sp, const lmb_direct_draw *draw, lmb_rng *rng,
                         double e[3], double dir[3], double deferred[3]);

/* 1 when some light is `indirect` (lmb_direct_at_split's deferred part can be non-zero). */
int lmb_direct_has_deferred(const lmb_direct *d);

/* output.shadowmask: the channels in use (0: none), and per channel the visibility in [0, 1]
 * of its light from sp (samples.direct rays over a sun's disc, one ray to a point or spot;
 * 0 facing away). Returns the rays traced. */
uint32_t lmb_direct_shadowmask_channels(const lmb_direct *d);
uint32_t lmb_shadowmask_at(const lmb_direct *d, const lmb_shading_point *sp, lmb_rng *rng,
                           double vis[LMB_SHADOWMASK_CHANNELS]);

/* What a gather point's hemisphere rays saw besides whether it is inside geometry: near_range
 * (in) the distance within which a hit makes the point `near` (out: a wall or contact close
 * enough that the texel may straddle it; texel_direct.c then checks which of its points see
 * each other), sees_back (out: some ray hit a back face: the point is near geometry's inside,
 * in a gap, at a contact). */
typedef struct lmb_point_sight {
    double near_range;
    int near, sees_back;
} lmb_point_sight;

/* 1 when sp, gather point k of texel `texel` (y x width + x) of atlas `atlas`, lies inside
 * geometry (most of its hemisphere rays hit back faces); adds to *rays; fills *sight. With a
 * validity memo (lmb_direct_set_validity) a point tested before is read from it, and rng moves
 * past the draws the test takes, so what follows draws the same numbers either way. */
int lmb_point_inside_geometry(const lmb_direct *d, const lmb_shading_point *sp, uint32_t atlas, uint32_t texel,
                              uint32_t k, lmb_rng *rng, uint32_t *rays, lmb_point_sight *sight);

/* Gives d a gather points' validity memo (point_validity.h; borrowed, NULL: none) for the
 * layout its texels come from. */
struct lmb_point_validity;
void lmb_direct_set_validity(lmb_direct *d, struct lmb_point_validity *validity);

/* The options the lights were made with. */
const lmb_direct_options *lmb_direct_opts(const lmb_direct *d);
const lmb_rt *lmb_direct_rt(const lmb_direct *d);

/* Gather point k of listed texel i of t as a shading point (offset scaled to the texel). */
void lmb_texel_shading_point(const lmb_direct *d, const lmb_texels *t, uint32_t i, uint32_t k, lmb_shading_point *sp);

/* 1 when point k of listed texel i lies on a cut-away part of a MASK surface: it is not on the
 * surface, so it gets no light and gathers none (a texel with no other point is invalid and
 * filled from its neighbours, as one inside geometry). */
int lmb_texel_point_cut(const lmb_direct *d, const lmb_texels *t, uint32_t i, uint32_t k);

typedef struct lmb_direct_job {
    const lmb_direct *direct;
    uint32_t atlas;      /* keys the random streams */
    float *direction;    /* NULL, or 3 floats per listed texel: lmb_direct_at's dir, averaged over the
                            texel's points as the irradiance is (directional lightmaps) */
    float *deferred;     /* NULL, or 3 floats per listed texel: the `indirect` lights' part of the irradiance */
    float *shadowmask;   /* NULL, or 4 floats per listed texel: lmb_shadowmask_at averaged over the points */
    float *variance;     /* NULL, or per listed texel: the variance of one round's estimate of its mean
                            luminance (texel_direct.c; 0: no sampled light) */
    const uint32_t *rounds; /* NULL: 2 rounds of half samples.direct at every texel (the direct step);
                               else per listed texel the rounds of a refinement (>= 2), after the
                               direct step's two and without them; 0: the texel is left as it is */
} lmb_direct_job;

/* Direct light of `bands` sets of texels in one parallel loop (a set is a band of atlas rows;
 * band b: jobs[b], t[b], irradiance[b]): fills irradiance (3 floats per listed texel),
 * t->valid and t->gather_at. A texel's light depends on its atlas, texel and rounds only, not
 * on the bands, their number or the threads. The jobs' rounds are all NULL (the direct step)
 * or all set (a refinement). Counts rays and adds the sampled lights' samples to *samples. */
lmb_status lmb_direct_compute_bands(const lmb_direct_job *jobs, lmb_texels *t, float *const *irradiance, uint32_t bands,
                                    uint64_t *rays, uint64_t *samples, lmb_error *err);

/* Samples per point in one round of the sampled lights: half samples.direct (rounded up). */
uint32_t lmb_direct_round_samples(const lmb_direct_options *opt);

/* 1 when some light is sampled (emissive triangles, sun discs, more than 8 point lights, the sky):
 * direct light has noise, and adaptive sampling has something to do. */
int lmb_direct_has_sampled(const lmb_direct *d);

/* ---- for light probes (probe_lights.c) ---- */

/* One delta light seen from a probe: unit direction toward it and the irradiance (lux, RGB) it
 * gives a surface facing it there, shadowed. */
typedef void (*lmb_delta_fn)(void *user, const double dir[3], const double e[3]);

/* Calls fn for every point, spot and directional light in `baked` mode that reaches p unoccluded
 * (a sun with lights.sun_angle counts as its disc's centre). Returns the shadow rays traced. */
uint32_t lmb_direct_deltas_at(const lmb_direct *d, const double p[3], lmb_delta_fn fn, void *user);

/* `samples` points on the emitters (triangles by power, uniform on each), seen from p unoccluded:
 * fn gets each one's direction and Le / (pdf in solid angle x samples), so that summing
 * f(w) x that over the calls estimates the integral of Le(w) f(w) over the emitters' solid angle
 * (a probe's SH projection of their light). Returns the shadow rays traced. */
uint32_t lmb_direct_emitter_samples_at(const lmb_direct *d, const double p[3], uint32_t samples, lmb_rng *rng,
                                       lmb_delta_fn fn, void *user);

/* The sky the lights were made with, or NULL. */
const lmb_sky *lmb_direct_sky(const lmb_direct *d);

#endif
