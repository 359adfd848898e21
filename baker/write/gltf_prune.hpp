/*
 * Drops what a bake left unused in the output glTF (C++ only, part of the glTF writer).
 */
#ifndef LMBAKE_GLTF_PRUNE_HPP
#define LMBAKE_GLTF_PRUNE_HPP

#include "../load/gltf_doc.hpp"

/* Removes the meshes that nodes used before they got their lightmapped copies and that no
 * node uses any more, then the accessors and buffer views only those meshes used, renumbering
 * every reference. A mesh the input itself left unused is kept, and so is everything when the
 * file uses an extension whose references to meshes or accessors lmbake does not know
 * (renumbering could break them). Returns how many meshes it removed. */
int lmb_gltf_prune_replaced(lmb_gltf_doc *doc);

#endif
