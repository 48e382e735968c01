/*
** What the tests of joint fits share: a tissue's published tables in several test modes, read
** from the shared datasets folder.
*/
#ifndef CF_TESTS_JOINTUTIL_H
#define CF_TESTS_JOINTUTIL_H

#include <stdio.h>

#include "io/measure.h"
#include "testutil.h"

/* The shared tables STEM_MODE.csv for the n modes given (e.g. "brain_cortex" and tension,
** compression, shear) into t and tabs; 0 when the shared folder is absent (the caller skips), a
** test failure when a table is refused. */
static inline int tu_load_modes(const char *stem, const char *const *modes, int n, cf_table *t,
                                const cf_table **tabs)
{
    const char *dir = tu_datasets();
    if (!dir)
        return 0;
    cf_measure_options mo = cf_measure_default_options();
    for (int k = 0; k < n; k++) {
        char path[1024];
        cf_error err = {0};
        snprintf(path, sizeof path, "%s/%s_%s.csv", dir, stem, modes[k]);
        if (cf_measure_load(path, &mo, &t[k], &err) != CF_OK)
            fail_msg("%s", err.msg);
        tabs[k] = &t[k];
    }
    return 1;
}

/* Tension, compression and shear, in that order. */
static const char *const tu_tcs[3] = {"tension", "compression", "shear"};

#endif
