/* What a bake's texels will cost in memory, and what the machine has: so that an atlas.texels
 * beyond it is an error before any work, not an out-of-memory kill. */
#ifndef LMBAKE_MEMORY_H
#define LMBAKE_MEMORY_H

#include <stdint.h>

/* Peak RSS a bake of `texels` texels is expected to reach, bytes: the process's base (OIIO,
 * Embree, the scene) and a per-texel cost above the 88 bytes measured with one bounce
 * (docs/defaults.md#memory), for the passes, the cache and the denoiser at the defaults. */
#define LMB_BAKE_BASE_BYTES (200ull << 20)
#define LMB_BAKE_BYTES_PER_TEXEL 160ull

/* Bytes this process may still take: the smaller of /proc/meminfo's MemAvailable and what the
 * cgroup's memory.max leaves; 0 when neither can be read. */
uint64_t lmb_memory_available(void);

#endif
