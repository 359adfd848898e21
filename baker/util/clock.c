/* Monotonic wall clock (see clock.h); POSIX clock_gettime. */
#define _POSIX_C_SOURCE 200809L
#include "clock.h"

#include <time.h>

double lmb_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
