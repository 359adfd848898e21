/* Message output and option parsing shared by the subcommands (see cli_common.h). */
#include "cli_common.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

static void print_warning(void *user, const char *message)
{
    cli_warnings *w = user;
    w->count++;
    if (!w->quiet)
        fprintf(stderr, "lmbake: warning: %s\n", message);
}

/* Report lines go to stdout with the summary (progress is on stderr). */
static void print_info(void *user, const char *message)
{
    cli_warnings *w = user;
    if (!w->quiet) {
        printf("%s\n", message);
        fflush(stdout);
    }
}

lmb_log cli_log(cli_warnings *w)
{
    lmb_log log = {print_warning, w, print_info};
    return log;
}

int cli_fail(const lmb_error *err)
{
    fprintf(stderr, "lmbake: error: %s\n", err->message);
    return (int)err->status;
}

int cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "lmbake %s: ", cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nTry 'lmbake %s --help'.\n", cmd);
    return LMB_ERR_USAGE;
}

int cli_is_flag(const char *arg, const char *name, const char *alias)
{
    return !strcmp(arg, name) || (alias && !strcmp(arg, alias));
}

int cli_opt_value(int argc, char **argv, int *i, const char *name, const char *alias, const char **value)
{
    const char *arg = argv[*i];
    size_t n = strlen(name);
    if (!strncmp(arg, name, n) && arg[n] == '=') {
        *value = arg + n + 1;
        return 1;
    }
    if (!cli_is_flag(arg, name, alias))
        return 0;
    if (*i + 1 >= argc)
        return -1;
    *value = argv[++*i];
    return 1;
}

int cli_parse_uint(const char *s, unsigned long long max, unsigned long long *out)
{
    char *end;
    if (!s || !*s || *s == '-')
        return 0;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end || v > max)
        return 0;
    *out = v;
    return 1;
}
