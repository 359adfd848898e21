/* Buffers of many megabytes that are written once right after they are made (a farm step's merged
 * results): on this kind of machine a fresh page costs a fault the first time it is touched,
 * several microseconds each under a hypervisor, so a 34 MB merge spent more time faulting pages
 * in than copying into them. Transparent huge pages make it one fault per 2 MB. */
#ifndef LMBAKE_BIG_BUFFER_H
#define LMBAKE_BIG_BUFFER_H

#include <stddef.h>

/* n bytes, uninitialised, released with free() (and realloc()-able). From 4 MB up: aligned to
 * 2 MB and marked for huge pages (madvise MADV_HUGEPAGE, which the kernel may ignore); below,
 * plain malloc. NULL when out of memory. */
void *lmb_big_alloc(size_t n);

#endif
