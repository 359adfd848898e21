/*
 * Minimal test assertions for lmbake's C unit tests: each failed CHECK prints the file,
 * line and the values, and the test's main returns check_failures() as its exit code.
 */
#ifndef LMBAKE_TESTS_CHECK_H
#define LMBAKE_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>
#include <string.h>

static int check_failed_count;

#define CHECK(cond)                                                                        \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);       \
            check_failed_count++;                                                          \
        }                                                                                  \
    } while (0)

#define CHECK_INT(a, b)                                                                    \
    do {                                                                                   \
        long long check_a_ = (long long)(a), check_b_ = (long long)(b);                    \
        if (check_a_ != check_b_) {                                                        \
            fprintf(stderr, "%s:%d: CHECK_INT failed: %s = %lld, expected %lld\n", __FILE__, \
                    __LINE__, #a, check_a_, check_b_);                                     \
            check_failed_count++;                                                          \
        }                                                                                  \
    } while (0)

/* |a - b| <= tol */
#define CHECK_NEAR(a, b, tol)                                                              \
    do {                                                                                   \
        double check_a_ = (double)(a), check_b_ = (double)(b);                             \
        if (!(fabs(check_a_ - check_b_) <= (double)(tol))) {                               \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, expected %.9g +- %g\n",  \
                    __FILE__, __LINE__, #a, check_a_, check_b_, (double)(tol));            \
            check_failed_count++;                                                          \
        }                                                                                  \
    } while (0)

/* haystack contains needle */
#define CHECK_CONTAINS(haystack, needle)                                                   \
    do {                                                                                   \
        const char *check_h_ = (haystack), *check_n_ = (needle);                           \
        if (!check_h_ || !strstr(check_h_, check_n_)) {                                    \
            fprintf(stderr, "%s:%d: CHECK_CONTAINS failed: \"%s\" does not contain \"%s\"\n", \
                    __FILE__, __LINE__, check_h_ ? check_h_ : "(null)", check_n_);          \
            check_failed_count++;                                                          \
        }                                                                                  \
    } while (0)

static inline int check_failures(void)
{
    if (check_failed_count)
        fprintf(stderr, "%d check(s) failed\n", check_failed_count);
    return check_failed_count ? 1 : 0;
}

#endif
