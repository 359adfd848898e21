/*
 * The ray-tracing scene: every instance of the level (lightmapped or not) in one Embree 3
 * scene, committed once and then shared read-only by all threads. A mesh used once is stored
 * as world-space triangles; a mesh several instances use (EXT_mesh_gpu_instancing copies, a
 * mesh on several nodes) is stored once, in object space, and placed by Embree instances, so
 * memory grows with the unique triangles, not the placed ones. Embree's C API is used directly
 * (no adapter needed).
 */
#ifndef LMBAKE_RT_SCENE_H
#define LMBAKE_RT_SCENE_H

#include <lmbake/lmbake.h>

#include <embree3/rtcore.h>

/* One (instance, primitive) with triangles: a "geometry slot". A world-space geometry's Embree id
 * is its slot; an instanced one is hit as (instance geometry id = the instance's first slot) +
 * (the primitive's place among its mesh's primitives with triangles). */
typedef struct lmb_rt_geom {
    uint32_t instance;       /* lmb_scene instance */
    uint32_t primitive;      /* lmb_scene primitive */
    uint32_t first_triangle; /* its first triangle in the instance mesh's triangle list */
    int flips_winding;
    int instanced;           /* placed by an Embree instance: hit normals come in object space */
    float normal_matrix[9];  /* instanced: the world matrix's inverse transpose (row-major 3 x 3) */
} lmb_rt_geom;

typedef struct lmb_rt {
    RTCDevice device;
    RTCScene scene;
    RTCScene *mesh_scenes; /* per lmb_scene mesh: its object-space scene when instanced, else NULL */
    uint32_t mesh_count;
    lmb_rt_geom *geoms; /* by geometry slot */
    uint32_t geom_count;
    uint64_t placed_triangles, stored_triangles; /* triangles in the level, and in memory */
    double build_seconds;
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
