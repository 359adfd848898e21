/* Preflight checks on a glTF's JSON before the full parse (see preflight.c). */
#ifndef LMBAKE_PREFLIGHT_H
#define LMBAKE_PREFLIGHT_H

#include <lmbake/lmbake.h>

/* LMB_OK if lmbake can try to parse path; else LMB_ERR_INPUT naming the reason. */
lmb_status lmb_preflight(const char *path, lmb_error *err);

#endif
