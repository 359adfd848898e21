/*
 * Where each light group's kept light lives between its lighting and the files (group_lighting.h):
 * off the heap. A bake with G groups keeps every group's dilated images (12 bytes per atlas texel,
 * 24 with directions) from the group's lighting until the files are written; held in memory, eight
 * groups doubled a bake's peak. So a group's images go out to a file of their own as soon as no
 * stage reads them (an unnamed file in TMPDIR, else /tmp: made and unlinked at once, so nothing is
 * left behind whatever ends the bake), come back whole for the one group a stage works on (its post
 * stage, its own files) and are read span by span where every group is read at once (their sum).
 * The bytes read back are those written: the bake's output does not change.
 * When the file cannot be made or written, the images stay in memory and the log says so once.
 */
#ifndef LMBAKE_GROUP_STORE_H
#define LMBAKE_GROUP_STORE_H

#include "pipeline/group_lighting.h"

/* Group g's images (every atlas's light and directions) out to its file and freed; they stay in
 * memory (warned once in log) when the file cannot be made or written. */
void lmb_group_light_put_away(lmb_group_light *gl, uint32_t g, const lmb_log *log);

/* Group g's images in memory again (nothing to do when they are). */
lmb_status lmb_group_light_bring_back(lmb_group_light *gl, uint32_t g, lmb_error *err);

/* Texels [i0, i1) of atlas a of group g, 3 floats each: its light into e and (with directions)
 * its directions into d, from memory or from its file. */
lmb_status lmb_group_light_read_span(const lmb_group_light *gl, uint32_t g, uint32_t a, size_t i0, size_t i1, float *e,
                                     float *d, lmb_error *err);

/* Group g's images gone from memory and its file (nothing reads them again). */
void lmb_group_light_drop(lmb_group_light *gl, uint32_t g);

/* The files closed (lmb_group_light_free calls it). */
void lmb_group_store_close(lmb_group_light *gl);

#endif
