/*
 * The sky: radiance from every direction a ray leaves the level by (config keys sky.*;
 * docs/sky.md). A uniform colour, or an equirectangular HDR/EXR environment map, times
 * sky.intensity (nits), with an optional ground colour below the horizon. It is a light of the
 * direct stage: lmb_sky_irradiance estimates its irradiance at a point with shadow rays, by
 * multiple importance sampling of two distributions, the map's luminance x solid angle (a 2D
 * CDF over its pixels at full resolution) and the cosine. Every later stage (bounce passes,
 * final gather, irradiance cache, directional maps, the reference) reads it through direct
 * light, so a gather ray that escapes adds nothing and nothing is counted twice.
 *
 * Map layout (up = +Y, rotation 0): row 0 is the zenith, the last row the nadir; the centre
 * column (u = 0.5) looks along -Z, u = 0.75 along +X (three.js's equirectangular mapping).
 */
#ifndef LMBAKE_SKY_H
#define LMBAKE_SKY_H

#include "raytrace/rt_scene.h"
#include "util/rng.h"

typedef struct lmb_sky lmb_sky; /* opaque, read-only once made: any number of threads at once */

/* The sky's options (the driver fills them from the config's sky.* keys: pipeline/stage_options.h).
 * intensity and color are what an artist dials; the strings are borrowed. */
typedef struct lmb_sky_options {
    double intensity;        /* sky.intensity, nits; 0: no sky of the config's (the file's IBL, if any) */
    double color[3];         /* sky.color, linear RGB, times intensity (and the image) */
    double ground[3];        /* sky.ground: radiance below the horizon, times intensity; [0] < 0: none */
    const char *image;       /* sky.image: equirectangular HDR/EXR relative to config_path's folder; "": none */
    const char *config_path; /* the config file it was given in ("": none; the image is then relative to ".") */
    double rotation;         /* sky.rotation, degrees about up */
    double up[3];            /* sky.up */
    int cosine_only;         /* sky.sampling: cosine (no map samples) */
} lmb_sky_options;

/* The sky opt describes; when it sets none (intensity 0), the scene's EXT_lights_image_based
 * light if it has one (its irradiance spherical harmonics as a radiance map); else *out = NULL.
 * The log says which. opt->image is read from the folder of opt->config_path under the input
 * rules (relative, inside that folder); non-finite or negative texels are replaced by 0 with a
 * warning naming how many. */
lmb_status lmb_sky_create(const lmb_sky_options *opt, const lmb_scene *scene, const lmb_log *log, lmb_sky **out,
                          lmb_error *err);
void lmb_sky_free(lmb_sky *s);

/* Radiance (nits, RGB) of the sky seen looking along world direction w (unit). */
void lmb_sky_radiance(const lmb_sky *s, const double w[3], double out[3]);

/* A direction drawn by the map's luminance x solid angle; returns its pdf (per steradian). */
double lmb_sky_sample(const lmb_sky *s, double u1, double u2, double w[3]);

/* The pdf (per steradian) of lmb_sky_sample drawing w. */
double lmb_sky_pdf(const lmb_sky *s, const double w[3]);

/* 1 when the map sampling is worth its rays (an image); 0 for a uniform sky, where cosine
 * sampling alone is exact up to visibility. */
int lmb_sky_has_map(const lmb_sky *s);

/* Sky irradiance (lux, RGB) at a point o (already offset off the surface) with shading normal
 * n and geometric normal ng: `samples` directions, shared between the map's distribution and
 * the cosine (all cosine without a map), each with a shadow ray, combined by the balance
 * heuristic. dir (may be NULL) gains the luminance-weighted direction sum of what arrives.
 * Returns the rays traced. */
uint32_t lmb_sky_irradiance(const lmb_sky *s, const lmb_rt *rt, const double o[3], const double n[3],
                            const double ng[3], double eps, uint32_t samples, lmb_rng *rng, double e[3], double dir[3]);

#endif
