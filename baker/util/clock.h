/* Wall-clock seconds from a monotonic clock, for stage timings in reports. */
#ifndef LMBAKE_CLOCK_H
#define LMBAKE_CLOCK_H

double lmb_seconds(void);

#endif
