/*
 * The Draco adapter (C header over C++): decodes one KHR_draco_mesh_compression stream with
 * Debian's libdraco (draco::Decoder) into plain arrays, for load/decompress.c. Nothing of
 * Draco's types crosses this header.
 */
#ifndef LMBAKE_DRACO_ADAPTER_H
#define LMBAKE_DRACO_ADAPTER_H

#include <lmbake/lmbake.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lmb_draco_mesh lmb_draco_mesh;

/* Decodes a Draco mesh (triangles) from bytes; *points and *faces its sizes. Free with
 * lmb_draco_free. An error names what Draco said. */
lmb_status lmb_draco_decode(const uint8_t *bytes, size_t size, lmb_draco_mesh **out, uint32_t *points,
                            uint32_t *faces, lmb_error *err);

/* The faces' corners as point indices (3 x faces). */
void lmb_draco_indices(const lmb_draco_mesh *m, uint32_t *out);

/* The attribute whose unique id is `id`, every point's `components` values converted to the
 * glTF component type `component_type` (5120..5126; normalized integers as Draco converts them)
 * into out (points x components values of that type). 0 when the mesh has no such attribute or
 * a value cannot be converted. */
int lmb_draco_attribute(const lmb_draco_mesh *m, int32_t id, int32_t component_type, int32_t components, void *out);

void lmb_draco_free(lmb_draco_mesh *m);

#ifdef __cplusplus
}
#endif

#endif
