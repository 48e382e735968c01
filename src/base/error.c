/*
** Status codes and error messages (see error.h).
*/
#include "conifit/error.h"

#include "base/safetext.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

cf_status cf_error_set(cf_error *err, cf_status status, const char *fmt, ...)
{
    if (err) {
        /* Messages quote file names, column names and values from outside: whatever they hold
        ** is shown, never acted on by a terminal (base/safetext.h). */
        char raw[2 * CF_ERROR_MSG_LEN];
        va_list ap;
        err->status = status;
        va_start(ap, fmt);
        int n = vsnprintf(raw, sizeof raw, fmt, ap);
        va_end(ap);
        size_t len = n < 0 ? 0 : (size_t)n < sizeof raw ? (size_t)n : sizeof raw - 1;
        cf_safe_text(err->msg, sizeof err->msg, raw, len);
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
