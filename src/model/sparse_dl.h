/*
** CHOLMOD and MUMPS opened at their first use (base/dynlib.h), not linked: with the BLAS, LAPACK,
** METIS, SCOTCH and the Fortran runtime they pull in, loading them cost every run of conifit
** (`conifit --version` included) about 60 % of its start-up (src/notes/performance.md). CHOLMOD
** is opened by the first sparse factorisation's analysis, MUMPS by the first indefinite matrix.
**
** Private to the model layer: sparse_chol.c is its only user (and the tests).
*/
#ifndef CF_MODEL_SPARSE_DL_H
#define CF_MODEL_SPARSE_DL_H

#include <cholmod.h>
#include <dmumps_c.h>

#include "conifit/error.h"

/* The functions conifit calls, by their own names. */
#define CF_CHOLMOD_FUNCTIONS(X)                                                                    \
    X(cholmod_start) X(cholmod_finish) X(cholmod_analyze) X(cholmod_factorize) X(cholmod_solve)    \
    X(cholmod_free_dense) X(cholmod_free_factor)
#define CF_MUMPS_FUNCTIONS(X) X(dmumps_c)

#define CF_SPARSE_DL_FIELD(f) __typeof__(&f) f;
typedef struct cf_cholmod_lib {
    CF_CHOLMOD_FUNCTIONS(CF_SPARSE_DL_FIELD)
} cf_cholmod_lib;
typedef struct cf_mumps_lib {
    CF_MUMPS_FUNCTIONS(CF_SPARSE_DL_FIELD)
} cf_mumps_lib;

/* The library's functions, opened on the first call (thread-safe; a failure is not remembered,
** the next call tries again). NULL with CF_E_INTERNAL when the library cannot be loaded or lacks
** a function: the message names the library's file and the loader's reason. */
const cf_cholmod_lib *cf_cholmod_lib_get(cf_error *err);
const cf_mumps_lib *cf_mumps_lib_get(cf_error *err);

/* For the tests: the file names tried instead of the defaults (the SONAME found when conifit was
** built, then the unversioned name), NULL for the default. Applies to a library not yet loaded. */
void cf_sparse_dl_names(const char *cholmod, const char *mumps);

#endif
