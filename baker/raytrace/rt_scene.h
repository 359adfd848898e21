/*
 * The ray-tracing scene: every instance of the level (lightmapped or not) as world-space
 * triangles in one Embree 3 scene, committed once and then shared read-only by all
 * threads. Embree's C API is used directly (no adapter needed).
 */
#ifndef LMBAKE_RT_SCENE_H
#define LMBAKE_RT_SCENE_H

#include <lmbake/lmbake.h>

#include <embree3/rtcore.h>

typedef struct lmb_rt_geom {
    uint32_t instance;       /* lmb_scene instance */
    uint32_t primitive;      /* lmb_scene primitive */
    uint32_t first_triangle; /* its first triangle in the instance mesh's triangle list */
    int flips_winding;
} lmb_rt_geom;

typedef struct lmb_rt {
    RTCDevice device;
    RTCScene scene;
    lmb_rt_geom *geoms; /* by Embree geometry id */
    uint32_t geom_count;
    double extent;      /* diagonal of the scene's bounding box */
    double eps;         /* ray offset: 1e-5 x extent */
} lmb_rt;

typedef struct lmb_rt_hit {
    double t;
    uint32_t geom, prim;
    float u, v;       /* Embree barycentrics of corners 1 and 2 */
    float ng[3];      /* geometric normal of the hit, world, front side, unit */
    int backface;     /* the ray hit the back of the triangle */
} lmb_rt_hit;

lmb_status lmb_rt_build(const lmb_scene *scene, lmb_rt *rt, lmb_error *err);
void lmb_rt_free(lmb_rt *rt);

/* 1 if anything lies on the segment o + t d, t in (tmin, tmax). d need not be unit. */
int lmb_rt_occluded(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax);

/* Closest hit in (tmin, tmax); returns 0 on a miss. d must be unit for t to be a distance. */
int lmb_rt_intersect(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax, lmb_rt_hit *hit);

/* Sets flush-to-zero / denormals-are-zero, which Embree wants in every tracing thread. */
void lmb_rt_thread_init(void);

#endif
