/*
 * Faces nothing can see: a triangle pressed back to back against other faces with a closed solid
 * on one side of it (a crate's side against its neighbour's, a wall's foot on a floor slab, a
 * crate's bottom on a one-sided floor, a pillar's base). Such a triangle gets no texels
 * (atlas.skip_hidden): a texel there would be a gather point inside geometry, left unlit, and its
 * padding ring costs as much as its texels. Two coincident faces with open space on both sides (a
 * two-sided card, a plane doubled back to back) stay lit.
 */
#ifndef LMBAKE_UNWRAP_HIDDEN_FACES_H
#define LMBAKE_UNWRAP_HIDDEN_FACES_H

#include "unwrap.h"

/* Sets hidden[f] = 1 for each triangle f of `in` (not in->skip) that is hidden as above, 0
 * otherwise, and *count to their number, on `threads` threads. Deterministic: the same mesh gives
 * the same flags at any thread count. Only `in`'s own faces count as occluders: one mesh, or the
 * world triangles of a level's meshes placed once (baker/pack/hidden_skip.h decides which). */
lmb_status lmb_find_hidden_faces(const lmb_unwrap_input *in, int threads, uint8_t *hidden, uint32_t *count,
                                 lmb_error *err);

#endif
