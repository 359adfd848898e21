/*
 * The direct stage's internals, shared by its files (direct.c: lights at a point; emitters.c:
 * emissive triangles as area lights; shadowmask.c: the visibility of the shadowmask's lights).
 * Not part of direct.h's API.
 */
#ifndef LMBAKE_DIRECT_INTERNAL_H
#define LMBAKE_DIRECT_INTERNAL_H

#include "direct.h"
#include "point_validity.h"
#include "util/sampling.h"

typedef struct light_set {
    uint32_t *local, local_count;       /* point and spot lights */
    uint32_t *directional, directional_count;
    double *cdf;                        /* local_count + 1, by power */
    uint32_t indirect_count;            /* lights in `indirect` mode (their direct light is deferred) */
    int mask_light[LMB_SHADOWMASK_CHANNELS]; /* output.shadowmask: the light of each channel, -1 */
    uint32_t mask_channels;
} light_set;

typedef struct emitter {
    double p[9];   /* world corners */
    double n[3];   /* unit front normal */
    double area;
    float le[3];   /* radiance, nits (times the texture when there is one) */
    int two_sided;
    const lmb_texture *tex; /* emissive texture or NULL */
    double uv[6];  /* its texture coordinates at the corners (KHR_texture_transform applied) */
    uint32_t instance, primitive, triangle; /* where it is in the scene (primitive: lmb_scene index) */
} emitter;

struct lmb_emitters {
    emitter *e;
    double *cdf; /* count + 1 */
    uint32_t count;
};

struct lmb_direct {
    const lmb_scene *scene;
    lmb_direct_options opt;
    const lmb_rt *rt;
    const lmb_emitters *emitters;
    const lmb_sky *sky;
    light_set lights;
    uint32_t **emitter_of; /* per Embree geometry: per triangle the emitter index + 1 (0: none), or NULL */
    lmb_point_validity *validity; /* NULL, or the gather points' validity memo (borrowed; filled as points are tested) */
};


typedef struct point_ctx {
    const lmb_direct *d;
    double o[3];    /* offset origin */
    double p[3], n[3], ng[3];
    double eps;
    uint32_t samples; /* area-light and many-light samples */
    uint64_t sequence; /* QMC key of the point (util/qmc.h); each light and technique hashes its own from it */
    uint32_t first;    /* index of the first sample in the QMC sequences */
    uint64_t rays;
    double dir[3];    /* sum of each contribution's luminance times its direction (unit, toward the light) */
    double deferred[3]; /* the part of e from `indirect` lights (not in the lightmap, not in dir) */
} point_ctx;

/* The unit direction from c's point toward light l and its distance (1e300 for a directional
 * light); 0 when the point is at the light. */
int lmb_light_direction(const point_ctx *c, const lmb_light *l, double d[3], double *dist);

/* Emitter index chosen in proportion to power for u in [0, 1); *prob its probability. */
uint32_t lmb_emitter_pick(const lmb_emitters *es, double u, double *prob);

/* A point or spot light's irradiance per candela at normal incidence from unit direction d (toward
 * the light) at distance dist: 1/dist^2 times the range window and the spot's cone (the formulas
 * atop direct.c); 1 for a directional light. */
double lmb_punctual_falloff(const lmb_light *l, const double d[3], double dist);

/* Emitted radiance of emitter x at barycentrics (b1, b2) seen from direction d (unit, toward
 * the emitter), its cosine there in *cos_y; 0 when seen from its back and one-sided. */
int lmb_emitter_radiance(const emitter *x, double b1, double b2, const double d[3], double *cos_y, double le[3]);

/* c := the shading point sp of d, no rays traced yet. */
void lmb_point_init(point_ctx *c, const lmb_direct *d, const lmb_shading_point *sp);

/* A directional light as a disc of lights.sun_angle: its cone's cosine and a frame about its
 * axis (toward the sun), made once per light and point rather than per sample. */
typedef struct lmb_sun_disc {
    double cos_max, axis[3], t[3], b[3];
} lmb_sun_disc;

void lmb_sun_disc_init(double sun_angle, const lmb_light *l, lmb_sun_disc *disc);

/* Direction (unit, toward the sun) of the sample (u1, u2) of the disc: uniform in its cone of
 * directions. */
void lmb_sun_disc_direction(const lmb_sun_disc *disc, double u1, double u2, double d[3]);

#endif
