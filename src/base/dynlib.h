/*
** Libraries opened at run time (dlopen), at their first use, instead of linked: a command that
** does not use them does not pay for loading them. Gmsh's library (io/mesh.c) and the sparse
** solvers CHOLMOD and MUMPS with the BLAS, LAPACK and Fortran runtime they pull in
** (model/sparse_dl.c) are opened this way; src/notes/performance.md has what it saves.
*/
#ifndef CF_DYNLIB_H
#define CF_DYNLIB_H

#include "conifit/error.h"

/* Opens the first of names[] (NULL-terminated file names, the library's SONAME first) that
** loads, with its symbols resolved now and kept out of the process's global scope. NULL with
** CF_E_INTERNAL when none loads: the message names what the library is for (`what`, e.g.
** "CHOLMOD, the sparse Cholesky factorisation"), the first name and the loader's reason. */
void *cf_dynlib_open(const char *what, const char *const names[], cf_error *err);

/* The address of symbol sym in the library h opened as `lib` (for the message); NULL with
** CF_E_INTERNAL when the library lacks it. */
void *cf_dynlib_sym(void *h, const char *lib, const char *sym, cf_error *err);

/* Closes a library opened by cf_dynlib_open (one whose functions could not all be found). */
void cf_dynlib_close(void *h);

#endif
