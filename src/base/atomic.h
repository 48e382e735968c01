/*
** Writing output files so that nothing is ever half-written: write to a temporary file in the
** same folder, then rename it over the target. A failed or aborted write leaves no file at all,
** and the target is refused when it is one of the run's input files.
*/
#ifndef CF_ATOMIC_H
#define CF_ATOMIC_H

#include <stdio.h>

#include "conifit/error.h"

typedef struct cf_atomic {
    FILE *fp;          /* write here */
    char path[4096];   /* final name */
    char tmp[4112];    /* temporary name in the same folder */
} cf_atomic;

/* Opens a temporary file beside path. CF_E_CANTWRITE (message names the path and the reason)
** when it cannot be created. `inputs` (may be NULL) is a NULL-terminated list of input paths that
** path must not be: writing over one of them is refused with CF_E_CANTWRITE. */
cf_status cf_atomic_open(cf_atomic *a, const char *path, const char *const *inputs, cf_error *err);

/* Flushes, closes and renames the temporary file to its final name. On any failure the temporary
** file is removed and CF_E_CANTWRITE returned. */
cf_status cf_atomic_commit(cf_atomic *a, cf_error *err);

/* Closes and removes the temporary file (safe to call twice, or after a commit). */
void cf_atomic_abort(cf_atomic *a);

/* True when a and b name the same existing file (same device and inode). */
int cf_same_file(const char *a, const char *b);

#endif
