/*
** Sparse symmetric factorisation of the lattice tangent (SuiteSparse CHOLMOD), with its inertia.
**
** The pattern is analysed once (CHOLMOD's fill-reducing ordering: AMD, or METIS where AMD leaves
** much fill); every numeric factorisation reuses it. A factorisation first tries CHOLMOD's
** supernodal Cholesky LL^T (BLAS-3 on dense supernodes, the fast path); a matrix that is not
** positive definite makes it stop at the first non-positive pivot, and the matrix is then factored
** as L D L^T by MUMPS (multifrontal, BLAS-3, 1x1 and 2x2 pivots), whose count of negative pivots is
** the inertia: by Sylvester's law, the number of negative eigenvalues of the matrix. That count is
** what a static solver needs to tell a stable equilibrium (0) from an unstable one (> 0). CHOLMOD's
** own L D L^T is simplicial only (no BLAS): measured on a 27 000-unknown 3-D Laplacian, 12 s per
** factorisation against 1.3 s for MUMPS and 1.1 s for the supernodal LL^T.
**
** Private to the model layer: linsolve.c is its only user.
*/
#ifndef CF_MODEL_SPARSE_CHOL_H
#define CF_MODEL_SPARSE_CHOL_H

#include <stddef.h>

#include "conifit/error.h"

typedef struct cf_sparse_chol cf_sparse_chol; /* opaque */

/* What the last factorisation found. */
typedef struct cf_chol_info {
    long neg_pivots;   /* negative pivots = negative eigenvalues of the matrix (0: positive
                          definite); -1 when unknown (the factorisation failed) */
    int ldlt;          /* 1: the L D L^T (MUMPS) was used: the matrix is not positive definite, or
                          the previous one was not */
    int singular;      /* 1: a zero pivot, the matrix is singular to working precision */
    double fill;       /* entries of the factor over entries of the lower triangle */
} cf_chol_info;

/* Prepares the factorisation of n x n symmetric matrices with the given compressed-column pattern
** (colptr[n + 1], rowidx[colptr[n]]; both triangles may be present, rows within a column need not
** be sorted; only the lower triangle is read). The arrays must stay valid and unchanged while the
** object lives (values may change between factorisations). CF_E_INTERNAL when memory runs out,
** CF_E_NOCONV when the analysis fails otherwise. */
cf_status cf_sparse_chol_create(cf_sparse_chol **out, size_t n, int *colptr, int *rowidx,
                                cf_error *err);

/* Factors the matrix whose values are values[colptr[n]] (same pattern). CF_E_NOCONV when it is
** singular (info->singular = 1) or the values are not finite; CF_E_INTERNAL when memory runs out.
** info may be NULL. */
cf_status cf_sparse_chol_factor(cf_sparse_chol *ch, double *values, cf_chol_info *info,
                                cf_error *err);

/* Tells ch that its matrices are indefinite (a mixed form's, with a negative definite block): every
** factorisation goes to the L D L^T at once, without the LL^T attempt, whose numeric factor would
** stay allocated beside the L D L^T's (measured on a body of 4120 nodes: 61 MB of 201). */
void cf_sparse_chol_indefinite(cf_sparse_chol *ch);

/* Solves A x = b with the last factorisation (x and b may not alias). */
cf_status cf_sparse_chol_solve(cf_sparse_chol *ch, const double *b, double *x, cf_error *err);

/* Peak bytes CHOLMOD has held for this object (analysis, factors, workspace). */
size_t cf_sparse_chol_peak_bytes(const cf_sparse_chol *ch);

void cf_sparse_chol_free(cf_sparse_chol *ch);

#endif
