/*
 * Texel states (a texel of an atlas: empty, valid, or with every point inside geometry) and
 * dilation, which the lighting's cache, the post stage, the seams and the writers all use.
 * Dilation: texels that hold no valid value take the average of their
 * filled 8-neighbours, ring by ring outward from the valid texels. Padding (texels no
 * triangle touches) is filled all the way, so bilinear filtering and mipmaps never pull in
 * black; texels whose points lie inside geometry (under a wall or a box) are filled only
 * within LMB_DILATE_INSIDE_RINGS rings of a valid texel, enough for filtering at the
 * contact line, and stay 0 deeper in, so no light appears under geometry. Such a texel takes
 * its darkest filled neighbour (luminance), not their average: under a wall between a lit and
 * a dark room, the lit room's light does not cross into the dark room's filtering (the lit
 * side gets a contact shadow one texel wide instead, docs/leaks.md).
 */
#ifndef LMBAKE_DILATE_H
#define LMBAKE_DILATE_H

#include <lmbake/lmbake.h>

enum { LMB_TEXEL_EMPTY = 0, LMB_TEXEL_VALID = 1, LMB_TEXEL_INSIDE = 2 };
#define LMB_DILATE_INSIDE_RINGS 2

/* rgb: width*height*3 floats, modified in place; state: width*height LMB_TEXEL_* values.
 * threads: 0 for all cores; the result does not depend on it. */
lmb_status lmb_dilate(float *rgb, const uint8_t *state, uint32_t width, uint32_t height, int threads, lmb_error *err);

#endif
