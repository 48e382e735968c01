/*
** Status codes and error messages shared by every conifit module.
**
** The library never prints and never exits. A function that can fail returns a cf_status (zero on
** success, negative on failure, in the spirit of NLopt's result codes) and, when the caller passes
** a cf_error, leaves a one-line message there that names the file, line, column, key or parameter
** and the offending value, made safe for a terminal (control characters shown as \xNN). Only
** main() turns a status into text on stderr and an exit code.
*/
#ifndef CF_ERROR_H
#define CF_ERROR_H

#include <stddef.h>

typedef enum cf_status {
    CF_OK = 0,
    CF_E_USAGE = -1,    /* bad command-line arguments (exit 2) */
    CF_E_DATA = -2,     /* bad input data or invalid parameters (exit 65) */
    CF_E_NOINPUT = -3,  /* an input file is missing or unreadable (exit 66) */
    CF_E_CANTWRITE = -4,/* an output file cannot be written (exit 73) */
    CF_E_INTERNAL = -5, /* a bug, out of memory, a library failure (exit 70) */
    CF_E_NOCONV = -6    /* a solver did not converge (exit 70) */
} cf_status;

/* Exit statuses documented in conifit(1) and src/notes/commands.md (BSD sysexits values). */
enum {
    CF_EXIT_OK = 0,
    CF_EXIT_USAGE = 2,
    CF_EXIT_DATAERR = 65,
    CF_EXIT_NOINPUT = 66,
    CF_EXIT_SOFTWARE = 70,
    CF_EXIT_CANTCREAT = 73
};

#define CF_ERROR_MSG_LEN 512

/* The last failure of a call: its status and a message. A zeroed cf_error means "no error". */
typedef struct cf_error {
    cf_status status;
    char msg[CF_ERROR_MSG_LEN];
} cf_error;

/* Records status and a printf-style message in err (if err is not NULL); returns status so that a
** caller can write `return cf_error_set(err, CF_E_DATA, "...")`. */
cf_status cf_error_set(cf_error *err, cf_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Clears err to "no error". */
void cf_error_clear(cf_error *err);

/* A short fixed description of a status ("bad data", ...). */
const char *cf_strerror(cf_status status);

/* The process exit status for a status (0, 2, 65, 66, 70, 73). */
int cf_exit_code(cf_status status);

#endif
