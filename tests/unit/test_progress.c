/*
 * Progress output when not on a terminal (logs, CI): one plain line per 10% step with
 * counts, rate and ETA, and a final "done" line; nothing when quiet.
 */
#include "check.h"

#include "cli/progress.h"

#include <stdio.h>
#include <string.h>

static int read_all(FILE *f, char *buf, size_t size)
{
    rewind(f);
    size_t n = fread(buf, 1, size - 1, f);
    buf[n] = '\0';
    return (int)n;
}

int main(void)
{
    char out[8192];
    FILE *f = tmpfile();
    if (!f)
        return 1;
    cli_progress p;
    cli_progress_init(&p, f, 0);
    CHECK_INT(p.tty, 0);
    for (uint64_t i = 0; i <= 1000; i++)
        cli_progress_update(&p, "texels", i, 1000);
    read_all(f, out, sizeof out);
    int lines = 0;
    for (const char *c = out; *c; c++)
        lines += *c == '\n';
    CHECK_INT(lines, 11); /* 0%, 10% ... 90%, done */
    CHECK_CONTAINS(out, "texels:   0% (0/1000");
    CHECK_CONTAINS(out, "texels:  50% (500/1000");
    CHECK_CONTAINS(out, "ETA");
    CHECK_CONTAINS(out, "texels: done in");
    fclose(f);

    f = tmpfile();
    if (!f)
        return 1;
    cli_progress_init(&p, f, 1);
    cli_progress_update(&p, "texels", 5, 10);
    CHECK_INT(read_all(f, out, sizeof out), 0);
    fclose(f);
    return check_failures();
}
