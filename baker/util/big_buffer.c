/* Huge-page buffers (big_buffer.h). */
#define _GNU_SOURCE
#include "big_buffer.h"

#include <stdlib.h>
#include <sys/mman.h>

#define HUGE_PAGE ((size_t)2 << 20)

void *lmb_big_alloc(size_t n)
{
    if (n < 2 * HUGE_PAGE)
        return malloc(n ? n : 1);
    void *p = NULL;
    size_t rounded = (n + HUGE_PAGE - 1) / HUGE_PAGE * HUGE_PAGE;
    if (posix_memalign(&p, HUGE_PAGE, rounded) != 0)
        return NULL;
#ifdef MADV_HUGEPAGE
    madvise(p, rounded, MADV_HUGEPAGE); /* advice: without it the buffer works as well, slower */
#endif
    return p;
}
