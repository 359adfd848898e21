/*
 * The ray-tracing scene: every instance of the level that occludes (lightmapped or not; what
 * moves, lmb_instance.occludes 0, is left out) in one Embree 3
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

#include "rt_surface.h"

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

/* An Embree geometry's filter data (its user pointer): the surface and, for a world-space geometry,
 * whether its instance mirrors (the stored winding is turned). */
typedef struct lmb_rt_filter_data {
    lmb_rt_surface surface;
    int flips_winding;
} lmb_rt_filter_data;

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
    lmb_rt_filter_data *filters; /* owned: world slots, then one per scene primitive (instanced meshes) */
    uint32_t cut_geoms, partial_geoms; /* geometries with MASK cut-outs, and ones light partly passes */
    uint64_t cut_triangles, partial_triangles; /* their placed triangles */
} lmb_rt;

typedef struct lmb_rt_hit {
    double t;
    double p[3];      /* the hit point, world: origin + t direction */
    uint32_t geom, prim;
    float u, v;       /* Embree barycentrics of corners 1 and 2 */
    float ng[3];      /* geometric normal of the hit, world, front side, unit */
    int backface;     /* the ray hit the back of the triangle */
} lmb_rt_hit;

/* textures: for alpha and transmission textures (NULL: factors only). */
lmb_status lmb_rt_build(const lmb_scene *scene, const lmb_textures *textures, lmb_rt *rt, lmb_error *err);
void lmb_rt_free(lmb_rt *rt);

/* Every query skips the cut-away parts of MASK surfaces (rt_surface.h). */

/* 1 if anything lies on the segment o + t d, t in (tmin, tmax). d need not be unit. Surfaces that
 * light partly passes count as there. */
int lmb_rt_occluded(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax);

/* The light that passes along the segment (RGB in [0, 1]): 0 0 0 when something opaque is in the
 * way, else the product of what each surface that light partly passes lets through (at most
 * LMB_RT_MAX_LAYERS of them; more count as opaque). Returns 1 when it is 0 0 0. */
int lmb_rt_transmittance(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax,
                         double pass[3]);

/* Closest hit in (tmin, tmax); returns 0 on a miss. d must be unit for t to be a distance. Surfaces
 * that light partly passes count as hits. */
int lmb_rt_intersect(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax, lmb_rt_hit *hit);

/* A surface that light partly passes, met before a ray's closest opaque hit. */
#define LMB_RT_MAX_LAYERS 8
typedef struct lmb_rt_layer {
    lmb_rt_hit hit;
    double pass[3]; /* what it lets through */
    double cover;   /* the share of it that is there to reflect */
} lmb_rt_layer;

/* The closest opaque hit (return 1; 0 on a miss) and, in *layers, the surfaces light partly passes
 * before it, nearest first (at most LMB_RT_MAX_LAYERS, the nearest ones; *count of them). */
int lmb_rt_intersect_layers(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax,
                            lmb_rt_hit *hit, lmb_rt_layer *layers, uint32_t *count);

/* 1 where triangle `tri` (of its instance's mesh, over the mesh's primitives) of instance
 * `instance` is cut away (MASK) at barycentrics (b1, b2): a gather point there is not on the surface. */
int lmb_rt_triangle_cut(const lmb_rt *rt, const lmb_scene *s, uint32_t instance, uint32_t tri, double b1, double b2);

/* Sets flush-to-zero / denormals-are-zero, which Embree wants in every tracing thread. */
void lmb_rt_thread_init(void);

#endif
