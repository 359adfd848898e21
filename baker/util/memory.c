/* Available memory (see memory.h): Linux's own estimate of what can be allocated without
 * swapping (MemAvailable), capped by a cgroup v2 limit when the process runs under one. */
#include "memory.h"

#include <stdio.h>
#include <string.h>

static uint64_t read_u64(const char *path)
{
    FILE *f = fopen(path, "r");
    unsigned long long v = 0;
    char buf[64] = "";
    if (!f)
        return 0;
    if (fgets(buf, sizeof buf, f) && strncmp(buf, "max", 3) != 0)
        sscanf(buf, "%llu", &v);
    fclose(f);
    return (uint64_t)v;
}

uint64_t lmb_memory_available(void)
{
    uint64_t avail = 0;
    FILE *f = fopen("/proc/meminfo", "r");
    char line[256];
    while (f && fgets(line, sizeof line, f)) {
        unsigned long long kb;
        if (sscanf(line, "MemAvailable: %llu kB", &kb) == 1) {
            avail = (uint64_t)kb << 10;
            break;
        }
    }
    if (f)
        fclose(f);
    uint64_t limit = read_u64("/sys/fs/cgroup/memory.max"), used = read_u64("/sys/fs/cgroup/memory.current");
    if (limit && limit > used && (avail == 0 || limit - used < avail))
        avail = limit - used;
    return avail;
}
