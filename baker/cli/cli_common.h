/*
 * Shared pieces of the lmbake subcommands: message output, the warning sink handed to
 * the library, and a tiny option parser (long options, --key=value or --key value).
 */
#ifndef LMBAKE_CLI_COMMON_H
#define LMBAKE_CLI_COMMON_H

#include <lmbake/lmbake.h>

#include <stdio.h>

typedef struct cli_warnings {
    unsigned count;
    int quiet; /* count but do not print */
} cli_warnings;

/* An lmb_log that prints "lmbake: warning: ..." to stderr and counts. */
lmb_log cli_log(cli_warnings *w);

/* Prints "lmbake: error: <message>" and returns the status as the exit code. */
int cli_fail(const lmb_error *err);

/* Prints "lmbake <cmd>: <message>" and a pointer to --help; returns LMB_ERR_USAGE. */
int cli_usage_error(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Option parsing over argv[1..]: returns 1 and sets *value if argv[*i] is `name` taking a
 * value (as "--name=v" or "--name v"), advancing *i. Returns -1 if the value is missing. */
int cli_opt_value(int argc, char **argv, int *i, const char *name, const char *alias, const char **value);

/* Parses an unsigned integer option value; returns 0 on junk. */
int cli_parse_uint(const char *s, unsigned long long max, unsigned long long *out);

int cli_is_flag(const char *arg, const char *name, const char *alias);

#endif
