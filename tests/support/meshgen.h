/*
 * Generated test meshes for the unwrapper and the bakers (issue 3's reference meshes):
 * a Cornell box (5 walls and 2 blocks, 30 triangles), a UV sphere (segments x rings),
 * a torus (segments x sides), each an indexed triangle list with counter-clockwise
 * outward faces (inward for the Cornell walls, which face the room).
 */
#ifndef LMBAKE_TESTS_MESHGEN_H
#define LMBAKE_TESTS_MESHGEN_H

#include <stdint.h>

typedef struct gen_mesh {
    uint32_t vertex_count, triangle_count;
    float *positions; /* 3 per vertex */
    uint32_t *indices; /* 3 per triangle */
} gen_mesh;

/* 0 on success (out of memory: -1). Free with gen_mesh_free. */
int gen_cornell_box(gen_mesh *m);                                   /* 30 triangles, 0..1 cube room */
int gen_uv_sphere(gen_mesh *m, uint32_t segments, uint32_t rings, float radius); /* 2*seg*(rings-1) */
int gen_torus(gen_mesh *m, uint32_t segments, uint32_t sides, float major, float minor); /* 2*seg*sides */
/* A UV sphere whose radius is displaced by a few smooth waves (amplitude `bump` x radius):
 * a closed, curved, non-trivial mesh for the 100k-triangle charting benchmark. */
int gen_bumpy_sphere(gen_mesh *m, uint32_t segments, uint32_t rings, float radius, float bump);
void gen_mesh_free(gen_mesh *m);

#endif
