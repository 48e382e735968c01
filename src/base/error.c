/*
** Status codes and error messages (see error.h).
*/
#include "conifit/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

cf_status cf_error_set(cf_error *err, cf_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        err->status = status;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return status;
}

void cf_error_clear(cf_error *err)
{
    if (err) {
        err->status = CF_OK;
        err->msg[0] = '\0';
    }
}

const char *cf_strerror(cf_status status)
{
    switch (status) {
    case CF_OK: return "success";
    case CF_E_USAGE: return "usage error";
    case CF_E_DATA: return "bad data";
    case CF_E_NOINPUT: return "cannot open input";
    case CF_E_CANTWRITE: return "cannot write output";
    case CF_E_INTERNAL: return "internal error";
    case CF_E_NOCONV: return "no convergence";
    }
    return "unknown status";
}

int cf_exit_code(cf_status status)
{
    switch (status) {
    case CF_OK: return CF_EXIT_OK;
    case CF_E_USAGE: return CF_EXIT_USAGE;
    case CF_E_DATA: return CF_EXIT_DATAERR;
    case CF_E_NOINPUT: return CF_EXIT_NOINPUT;
    case CF_E_CANTWRITE: return CF_EXIT_CANTCREAT;
    case CF_E_INTERNAL:
    case CF_E_NOCONV: return CF_EXIT_SOFTWARE;
    }
    return CF_EXIT_SOFTWARE;
}
