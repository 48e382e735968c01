/*
** Linear solves with sparse symmetric matrices (linsolve.c, linsolve_krylov.c): a solver object
** holds one sparsity pattern, the Jacobi scale of the last matrix, its factorisations and their
** workspaces. It knows nothing of where the matrix comes from: the caller gives the pattern once
** and a function that writes the matrix's values at the caller's current state. A solve scales
** the matrix symmetrically, A' = D^-1 A D^-1 with D = sqrt|diag A| (a congruence: the inertia is
** that of A), and runs the cascade sparse Cholesky or L D L^T (CHOLMOD, MUMPS: sparse_chol.h),
** banded LDL^T, dense LU, GMRES. Between solves of fresh matrices, the factors of the last one
** give chord steps and preconditioned Krylov steps (linsolve_krylov.c). Private to the model
** layer; the size limits are read by the cost estimate of a scene (io/budget.c), so that the
** estimate follows the cascade.
*/
#ifndef CF_MODEL_LINSOLVE_H
#define CF_MODEL_LINSOLVE_H

#include <stddef.h>

#include "conifit/error.h"

/* The banded LDL^T is tried only when its band fits in this many doubles, */
#define CF_LINSOLVE_BAND_MAX_ENTRIES 5e7
/* dense LU only up to this many unknowns (a 7x7x7 lattice has about 1500), */
#define CF_LINSOLVE_DENSE_MAX_DOF 1200
/* and GMRES restarts after this many basis vectors (fewer when there are fewer unknowns). */
#define CF_LINSOLVE_GMRES_RESTART 150

typedef struct cf_linsolve cf_linsolve; /* opaque */

/* Writes the values of the matrix at the caller's current state into v, in the order of the
** pattern given to cf_linsolve_create (colp[n] doubles, every entry written). */
typedef void cf_linsolve_fill(void *ctx, double *v);

/* A solver for n x n symmetric matrices with the compressed-column pattern colp[n + 1],
** rowi[colp[n]] (both triangles present, the rows within a column increasing, every diagonal
** entry present); both arrays are copied. fill(ctx, v) assembles the matrix; ctx must outlive the
** solver. banded_only skips the sparse factorisation (the band's is then band_ldlt.h's).
** CF_E_INTERNAL when out of memory. */
cf_status cf_linsolve_create(cf_linsolve **out, size_t n, const int *colp, const int *rowi,
                             cf_linsolve_fill *fill, void *ctx, int banded_only, cf_error *err);
void cf_linsolve_free(cf_linsolve *ls);

/* The solver's copy of the pattern (valid while it lives): *colp the column starts, *rowi the
** rows; an entry's index there is its index in the values fill writes. */
void cf_linsolve_pattern(const cf_linsolve *ls, const int **colp, const int **rowi);

/* Assembles the matrix A (through fill), scales it and solves A x = b by the cascade. *solves
** (may be NULL) is increased by the linear solves done: one per factorisation accepted, one per
** GMRES restart. The inertia found is then cf_linsolve_neg_pivots(). */
cf_status cf_linsolve_direction(cf_linsolve *ls, const double *b, double *x, size_t *solves,
                                cf_error *err);

/* The matrices are indefinite by construction (a mixed form): the sparse factorisation goes to
** L D L^T at once (cf_sparse_chol_indefinite). */
void cf_linsolve_indefinite(cf_linsolve *ls);

/* Negative pivots of the matrix of the last cf_linsolve_direction (its negative eigenvalues), -1
** when no factorisation reported them. */
long cf_linsolve_neg_pivots(const cf_linsolve *ls);

/* 1 when the sparse factors of the last cf_linsolve_direction's matrix are there for chord and
** Krylov steps. */
int cf_linsolve_factored(const cf_linsolve *ls);

/* x from the sparse factors of an earlier matrix (a chord step), accepted when it solves that
** matrix. Returns 1 when x holds it; sets *fatal for an out-of-memory that no fallback would
** survive. */
int cf_linsolve_chord(cf_linsolve *ls, const double *b, double *x, int *fatal, cf_error *err);

/* x from the current matrix (assembled through fill, scaled by the D of the last factorisation),
** by GMRES preconditioned with the sparse factors of an earlier one. `need` is the reduction of
** the residual that would end the caller's Newton iteration (tolerance over residual, below 1):
** the linear residual is brought to a tenth of it (kept between 1e-10 and 0.1 of the right-hand
** side: an inexact Newton step); after 16 GMRES steps short of that, a linear residual within
** `need` or 0.1, whichever is larger (at most 0.5), is still returned, a shorter step for the
** caller to judge. Returns 1 when x holds it, 0 when the factors are too stale for even that (the
** caller refactors); sets *fatal for an out-of-memory that no fallback would survive. */
int cf_linsolve_krylov(cf_linsolve *ls, const double *b, double *x, double need, int *fatal,
                       cf_error *err);

/* Assembles the matrix (through fill), scales it as a direction does and factors it by the
** sparse Cholesky, or L D L^T when it is not positive definite, without solving and without the
** cascade's fallbacks: for a caller that solves many right-hand sides with one matrix
** (cf_linsolve_solve). CF_E_NOCONV when the matrix cannot be factored (singular, not finite, or
** the sparse solvers are missing), CF_E_INTERNAL when memory runs out. The factors then also
** serve cf_linsolve_chord and cf_linsolve_krylov. */
cf_status cf_linsolve_factor(cf_linsolve *ls, cf_error *err);

/* x = A^-1 b from the factors of the last factored matrix (its scale applied to b and undone on
** x), one forward and one back substitution: no residual check nor refinement (the caller's
** iteration checks its own residual). b and x may not alias. CF_E_NOCONV when no factors are
** kept or x comes out not finite. */
cf_status cf_linsolve_solve(cf_linsolve *ls, const double *b, double *x, cf_error *err);

#endif
