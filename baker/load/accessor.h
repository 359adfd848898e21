/*
 * glTF accessor decoding with every bound checked: component types, strides, buffer
 * views past their buffer, sparse substitution, normalized integers. The messages name
 * the file and the `what` given by the caller (e.g. "mesh 'Box' primitive 0 POSITION").
 */
#ifndef LMBAKE_ACCESSOR_H
#define LMBAKE_ACCESSOR_H

#include "gltf_adapter.h"

typedef struct lmb_accessor_ctx {
    const lmb_gltf_view *view;
    const char *path; /* file name for messages */
} lmb_accessor_ctx;

/* Decodes accessor `index` (which must have `components` components per element) into a
 * new float array of count * components (caller frees). Integers are converted as the
 * glTF spec says (normalized: to [0,1] or [-1,1]; otherwise as their value). */
lmb_status lmb_accessor_read_floats(const lmb_accessor_ctx *ctx, int32_t index, int components,
                                    const char *what, float **out, size_t *count, lmb_error *err);

/* Decodes an index accessor (SCALAR of unsigned byte/short/int) into a new uint32 array. */
lmb_status lmb_accessor_read_indices(const lmb_accessor_ctx *ctx, int32_t index, const char *what,
                                     uint32_t **out, size_t *count, lmb_error *err);

#endif
