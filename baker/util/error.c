/*
 * The one error path: lmb_error_set formats a message into the caller's lmb_error and
 * returns the status, so a failing function can `return lmb_error_set(err, ...)`.
 * lmb_warn sends a non-fatal message to the caller's sink.
 */
#include <lmbake/lmbake.h>

#include <stdarg.h>
#include <stdio.h>

lmb_status lmb_error_set(lmb_error *err, lmb_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}

/* Formats a message into the sink (NULL: dropped). */
static void send(lmb_warn_fn sink, void *user, const char *fmt, va_list ap)
{
    char buf[1024];
    if (!sink)
        return;
    vsnprintf(buf, sizeof buf, fmt, ap);
    sink(user, buf);
}

void lmb_info(const lmb_log *log, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (log)
        send(log->info, log->user, fmt, ap);
    va_end(ap);
}

void lmb_warn(const lmb_log *log, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (log)
        send(log->warn, log->user, fmt, ap);
    va_end(ap);
}
