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

void lmb_info(const lmb_log *log, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    if (!log || !log->info)
        return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    log->info(log->user, buf);
}

void lmb_warn(const lmb_log *log, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    if (!log || !log->warn)
        return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    log->warn(log->user, buf);
}
