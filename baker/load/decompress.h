/*
 * Compressed geometry, decoded before tinygltf reads the file: EXT_meshopt_compression
 * (buffer views, with Debian's libmeshoptimizer: its vertex, index and sequence codecs and the
 * octahedral, quaternion and exponential filters) and KHR_draco_mesh_compression (primitives,
 * with libdraco through draco_adapter.h). The file is rewritten in memory as a .glb whose one
 * binary buffer holds every buffer of the input and the decoded data, its buffer views and the
 * Draco primitives' accessors pointing there, both extensions gone: what gltfpack or
 * glTF-Transform compressed reads as the level did before. Buffers and images are read as the
 * loader reads them (data URIs, files inside the input's folder only: uri.h).
 */
#ifndef LMBAKE_DECOMPRESS_H
#define LMBAKE_DECOMPRESS_H

#include <lmbake/lmbake.h>

typedef struct lmb_decompressed {
    uint8_t *glb;     /* owned (free): the rewritten file, or NULL when nothing was compressed */
    size_t size;
    uint32_t meshopt_views, draco_primitives; /* what was decoded */
} lmb_decompressed;

/* Decodes path's compressed geometry into out (out->glb NULL: none). A stream that does not
 * decode, a view that reads past its buffer or a fallback buffer's missing data is an error
 * naming the file and the buffer view or mesh. */
lmb_status lmb_decompress(const char *path, lmb_decompressed *out, lmb_error *err);

#endif
