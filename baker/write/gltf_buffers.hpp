/*
 * The glTF writer's new buffer (C++ only, part of the tinygltf adapter: gltf_write.cpp,
 * gltf_probes.cpp): every array a bake adds goes into one buffer named "lmbake", a buffer view
 * each.
 */
#ifndef LMBAKE_GLTF_BUFFERS_HPP
#define LMBAKE_GLTF_BUFFERS_HPP

#include "../load/gltf_doc.hpp"

#include <cstddef>
#include <cstdint>

namespace lmb_gltf_out {

struct writer {
    tinygltf::Model &m;
    int buffer; /* the new buffer */
};

/* The "lmbake" buffer's index, made when the model has none. */
int new_buffer(tinygltf::Model &m);

/* Appends bytes as a new buffer view (4-byte aligned); returns the view index. */
int add_view(writer &w, const void *data, size_t size, int target);

/* A float VEC2 or VEC3 accessor over a new view (min and max when asked); returns its index. */
int add_float_accessor(writer &w, const float *data, uint32_t count, int comps, bool minmax);

} // namespace lmb_gltf_out

/* Adds the probes lmb_gltf_set_probes kept (gltf_probes.cpp): called by lmb_gltf_save after
 * the pruning that renumbers accessors and views. */
void lmb_gltf_add_probes(lmb_gltf_doc *doc);

#endif
