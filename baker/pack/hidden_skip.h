/*
 * atlas.skip_hidden over a level's layout: faces pressed back to back inside a solid get no chart
 * (hidden_skip.c; the test itself: baker/unwrap/hidden_faces.h).
 */
#ifndef LMBAKE_PACK_HIDDEN_SKIP_H
#define LMBAKE_PACK_HIDDEN_SKIP_H

#include "layout.h"

/* Adds every hidden triangle of the used, unwrapped meshes to their soups' skip flags and counts
 * them in hidden_count: a mesh used by one node only against the world's meshes used by one node
 * only, a shared mesh against its own faces. The time counts in each mesh's chart_seconds. */
lmb_status lmb_layout_skip_hidden(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, lmb_error *err);

/* One log line: how many triangles were hidden, and in which mesh the most (nothing when none). */
void lmb_layout_report_hidden(const lmb_scene *s, const lmb_layout *l, const lmb_log *log);

#endif
