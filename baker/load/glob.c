/*
 * Glob matching for node and mesh name patterns in the bake config: '*' matches any run
 * of characters (also empty), '?' exactly one; everything else literally, case-sensitive.
 * Iterative with one backtrack point (the last '*'), so it is linear-ish, never exponential.
 */
#include <lmbake/lmbake.h>

int lmb_glob_match(const char *pattern, const char *name)
{
    const char *star = NULL, *resume = NULL;
    while (*name) {
        if (*pattern == '*') {
            star = pattern++;
            resume = name;
        } else if (*pattern == '?' || *pattern == *name) {
            pattern++;
            name++;
        } else if (star) {
            pattern = star + 1;
            name = ++resume;
        } else {
            return 0;
        }
    }
    while (*pattern == '*')
        pattern++;
    return *pattern == '\0';
}
