/*
 * The lightmap layout of a scene: unwrap every lightmapped mesh once (instances of a mesh
 * share its chart layout), scale each instance's charts to the texel density in world
 * units (so a scaled instance gets more texels), and pack them into atlases. Every
 * instance gets its own texels and lands whole in one atlas (one lightmap texture per
 * instance, as glTF materials need); the writer gives each instance its own TEXCOORD_1.
 * Meshes that keep their own TEXCOORD_1 (atlas.keep_uv1) are placed whole, as squares of
 * shared atlases (keep_uv1.c), and keep their UVs: a scale/offset rectangle per instance maps
 * them into the atlas, as engines' per-instance lightmap rectangles do.
 */
#ifndef LMBAKE_LAYOUT_H
#define LMBAKE_LAYOUT_H

#include <lmbake/lmbake.h>

#include "unwrap/unwrap.h"

/* How texel densities were chosen (density.h), for reports. */
typedef struct lmb_density_report {
    int automatic;          /* texel_density: auto */
    double scene_density;   /* the density instances without an override got (before any fit cap) */
    uint64_t budget;        /* auto: the texel budget */
    uint32_t capped;        /* auto: instances lowered to fit one atlas */
    uint32_t raised;        /* instances raised above the scene density by atlas.min_chart_texels */
    uint32_t short_of_floor; /* instances below their atlas.min_chart_texels floor: the budget won */
    double floor_share_min;  /* of those, the lowest share of its floor density one got */
    uint64_t texels;         /* texels the layout makes (coverage.h); 0 when not counted (explicit density) */
    uint32_t rounds;         /* layouts made to keep the budget: 1 when the first kept it */
    double floor_texels;     /* when no density kept the budget: what the charts take at any density */
    uint32_t probe_lit;      /* instances the budget moved to the light probes (probe_lit.h) */
    uint32_t probe_lit_meshes; /* their meshes */
} lmb_density_report;

/* One mesh's primitives as a single triangle list (vertex ids offset per primitive). */
typedef struct lmb_mesh_soup {
    uint32_t vertex_count, triangle_count;
    float *positions;  /* 3 per vertex, object space */
    float *normals;    /* 3 per vertex, object space; 0 for a primitive without NORMAL (see flat) */
    uint32_t *indices; /* 3 per triangle */
    uint8_t *skip;     /* per triangle: zero area */
    uint8_t *flat;     /* per triangle: its primitive has no NORMAL, so it is shaded flat (glTF) */
} lmb_mesh_soup;

typedef struct lmb_layout_mesh {
    int used;           /* some lightmapped instance uses it */
    lmb_mesh_soup soup;
    lmb_charts charts;  /* chart-local UVs, isometric; with kept_uv1 one chart of the mesh's TEXCOORD_1 */
    int kept_uv1;       /* atlas.keep_uv1 and the mesh has TEXCOORD_1 everywhere */
    uint32_t hidden_count; /* triangles skipped as hidden (atlas.skip_hidden; not kept in a plan) */
    double chart_seconds; /* hidden faces, unwrap, and the glue-all unwrap when the budget needed one */
} lmb_layout_mesh;

typedef struct lmb_layout_instance {
    int lightmapped;
    int probe_lit;        /* not lightmapped: its mesh's charts could not keep the texel budget at any density, so
                             the light probes light it (probe_lit.h); the probes cover its box */
    uint32_t atlas;
    double texel_density; /* texels per world unit used for it */
    uint32_t triangle_count; /* its mesh's triangles */
    double *uv1;          /* packed instances: 6 per mesh triangle, atlas texel coordinates; 0 for skipped
                             triangles. NULL for instances placed as rectangles: see block */
    uint32_t block;       /* placed as a rectangle (rect_instances.h): its layout in l->blocks, which the
                             copies of a node share, else UINT32_MAX; read either through lmb_layout_uv */
    double rect[4];       /* with a block: its size and place in the atlas, texels (w, h, x, y) */
    int shared_layout;    /* its TEXCOORD_1 is a layout other instances share (EXT_mesh_gpu_instancing copies,
                             atlas.share_meshes): the output writes it once, uv = (atlas uv - o) / s */
    double scale_offset[4]; /* (sx, sy, ox, oy): the output TEXCOORD_1 uv lands at uv * s + o in the atlas ([0,1]):
                               (1, 1, 0, 0) for unwrapped meshes (their TEXCOORD_1 is written in atlas space), the
                               instance's rectangle for a mesh that kept its own TEXCOORD_1 */
} lmb_layout_instance;

/* A TEXCOORD_1 layout that instances placed as rectangles share: 6 per mesh triangle in
 * [0, 1]^2 (0 for skipped triangles). Copies keep no UVs of their own, only their rectangle,
 * so memory grows with the unique triangles, not the copies. */
typedef struct lmb_layout_block {
    uint32_t mesh;
    double *uv;
} lmb_layout_block;

typedef struct lmb_layout {
    uint32_t mesh_count, instance_count;
    lmb_layout_mesh *meshes;
    lmb_layout_instance *instances;
    uint32_t atlas_count;
    uint32_t *width, *height;
    uint32_t block_count;
    lmb_layout_block *blocks; /* layouts shared by rectangle-placed instances */
    uint32_t chart_total;  /* charts placed, over all instances */
    uint32_t unfit_mesh;   /* after a placement failed with texel_density: auto because a mesh's copies fit no atlas at
                              any density (rect_instances.c): that mesh, else UINT32_MAX */
    lmb_density_report density;    /* how densities were chosen */
    double pack_seconds;
} lmb_layout;

/* Builds the layout for the lightmapped instances of scene (see lmb_scene_select_lightmapped).
 * progress and log may be NULL. Free with lmb_layout_free, also after an error. */
lmb_status lmb_layout_build(const lmb_scene *scene, const lmb_config *cfg, lmb_progress_fn progress,
                            void *progress_user, const lmb_log *log, lmb_layout *out, lmb_error *err);

void lmb_layout_free(lmb_layout *l);

/* Instance i's mesh triangle f in atlas texel coordinates (6 doubles): its own uv1, or its block
 * scaled and moved to its rectangle; zeros for a skipped (zero-area) triangle. */
static inline void lmb_layout_uv(const lmb_layout *l, uint32_t i, size_t f, double out[6])
{
    const lmb_layout_instance *li = &l->instances[i];
    if (li->uv1) {
        for (int k = 0; k < 6; k++)
            out[k] = li->uv1[6 * f + k];
        return;
    }
    const lmb_layout_block *b = &l->blocks[li->block];
    const lmb_charts *c = &l->meshes[b->mesh].charts;
    for (int k = 0; k < 6; k++)
        out[k] = c->chart_of[f] == UINT32_MAX ? 0
                 : k % 2                      ? b->uv[6 * f + k] * li->rect[1] + li->rect[3]
                                              : b->uv[6 * f + k] * li->rect[0] + li->rect[2];
}

/* Area of a triangle given as 9 doubles (three corners). */
double lmb_triangle_area(const double q[9]);

/* World-space corners of instance i's mesh triangle f (9 doubles). */
void lmb_layout_world_triangle(const lmb_scene *scene, const lmb_layout *l, uint32_t instance, uint32_t f,
                               double out[9]);

#endif
