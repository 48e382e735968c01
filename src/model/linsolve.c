/*
** Linear solves with sparse symmetric matrices (see linsolve.h): the solver object, the scaling,
** and the cascade sparse Cholesky or L D L^T (CHOLMOD, MUMPS: sparse_chol.h), banded LDL^T,
** dense LU, GMRES.
*/
#include "model/linsolve_internal.h"

#include "model/band_ldlt.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_spblas.h>
#include <gsl/gsl_splinalg.h>
#include <gsl/gsl_vector.h>

/* GMRES: residual relative to the right-hand side. The Newton update only needs a few digits more
** than the Newton tolerance asks of the residual, and Newton's own iteration removes the rest. */
#define GMRES_TOL 1e-13
#define GMRES_MAX_RESTARTS 200
#define GMRES_ACCEPT 1e-6
/* Linear solves: sparse Cholesky (CHOLMOD, L D L^T by MUMPS when the matrix is indefinite) first,
** accepted when its relative residual is below BAND_ACCEPT after at most CHOL_REFINE steps of
** refinement; if it fails, banded LDL^T (when the band fits in CF_LINSOLVE_BAND_MAX_ENTRIES
** doubles), else dense LU up to CF_LINSOLVE_DENSE_MAX_DOF unknowns, else GMRES (linsolve.h). */
#define BAND_ACCEPT 1e-10
#define CHOL_REFINE 2

/* ---- the solver object ----------------------------------------------------------------------- */

cf_status cf_linsolve_create(cf_linsolve **out, size_t n, const int *colp, const int *rowi,
                             cf_linsolve_fill *fill, void *ctx, int banded_only, cf_error *err)
{
    *out = NULL;
    cf_linsolve *s = calloc(1, sizeof *s);
    const size_t nnz = (size_t)colp[n];
    if (!s)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent matrix");
    s->n = n;
    s->fill = fill;
    s->ctx = ctx;
    s->banded_only = banded_only;
    s->neg_pivots = -1;
    /* a compressed matrix allocated directly: GSL's triplet tree and its compression crash on
    ** their own allocation failures (gsl_spmatrix_set, gsl_spmatrix_ccs) */
    s->C = gsl_spmatrix_alloc_nzmax(n ? n : 1, n ? n : 1, nnz ? nnz : 1, GSL_SPMATRIX_CSC);
    s->diag = malloc((n ? n : 1) * sizeof(int));
    s->D = calloc(n ? n : 1, sizeof(double));
    if (!s->C || !s->diag || !s->D) {
        cf_linsolve_free(s);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent matrix");
    }
    gsl_spmatrix *C = s->C;
    for (size_t e = 0; e <= n; e++)
        C->p[e] = colp[e];
    memcpy(C->i, rowi, nnz * sizeof(int));
    memset(C->data, 0, (nnz ? nnz : 1) * sizeof(double));
    C->nz = nnz;
    /* each unknown's diagonal entry, and the half-bandwidth */
    s->band = 0;
    for (size_t col = 0; col < n; col++) {
        s->diag[col] = -1;
        for (int k = C->p[col]; k < C->p[col + 1]; k++) {
            const size_t row = (size_t)C->i[k];
            const size_t off = row > col ? row - col : col - row;
            if (off > s->band)
                s->band = off;
            if (row == col)
                s->diag[col] = k;
        }
    }
    *out = s;
    return CF_OK;
}

void cf_linsolve_free(cf_linsolve *s)
{
    if (!s)
        return;
    if (s->C)
        gsl_spmatrix_free(s->C);
    if (s->AB)
        gsl_matrix_free(s->AB);
    cf_sparse_chol_free(s->chol);
    free(s->diag);
    free(s->D);
    free(s->kval);
    free(s->kbasis);
    free(s->sb);
    free(s);
}

void cf_linsolve_pattern(const cf_linsolve *s, const int **colp, const int **rowi)
{
    *colp = s->C->p;
    *rowi = s->C->i;
}

long cf_linsolve_neg_pivots(const cf_linsolve *s)
{
    return s->neg_pivots;
}

void cf_linsolve_indefinite(cf_linsolve *s)
{
    s->indefinite = 1;
}

int cf_linsolve_factored(const cf_linsolve *s)
{
    return s->chol_ready;
}

/* ---- the factorisations ---------------------------------------------------------------------- */

/* Sparse Cholesky of the scaled matrix (sparse_chol.h): the pattern is analysed once with a
** fill-reducing ordering, so a factorisation costs far less than the band's n b^2 on lattices of
** more than a few cells a side, and an indefinite matrix is factored as L D L^T with its negative
** pivots counted. Accepted when the residual is small. Returns 1 when x holds the solution;
** sets *fatal for an out-of-memory that no fallback would survive. */
static int chol_direction(cf_linsolve *s, const double *b, double *x, int *fatal, cf_error *err)
{
    const size_t n = s->n;
    gsl_spmatrix *C = s->C;
    *fatal = 0;
    s->chol_ready = 0;
    if (s->chol_failed || n == 0)
        return 0;
    cf_error lerr = {0};
    if (!s->chol) {
        cf_status cs = cf_sparse_chol_create(&s->chol, n, C->p, C->i, &lerr);
        if (cs == CF_E_INTERNAL) { /* out of memory: a fallback would only run out later */
            *fatal = 1;
            cf_error_set(err, CF_E_INTERNAL, "%s", lerr.msg);
            return 0;
        }
        if (cs != CF_OK) {
            s->chol_failed = 1;
            return 0;
        }
        if (s->indefinite)
            cf_sparse_chol_indefinite(s->chol);
    }
    cf_chol_info info;
    cf_status st = cf_sparse_chol_factor(s->chol, C->data, &info, &lerr);
    if (st == CF_E_INTERNAL) {
        *fatal = 1;
        cf_error_set(err, CF_E_INTERNAL, "%s", lerr.msg);
        return 0;
    }
    if (st != CF_OK)
        return 0;
    s->neg_pivots = info.neg_pivots; /* the inertia holds even when the solve is refused */
    int ok = cf_linsolve_chord(s, b, x, fatal, err);
    s->chol_ready = ok;
    if (ok)
        s->iters++;
    return ok;
}

/* The solution from the factors in s->chol (of C as it was factored, scaled by s->D), accepted
** when its residual against C is small. Returns 1 when x holds it. */
int cf_linsolve_chord(cf_linsolve *s, const double *b, double *x, int *fatal, cf_error *err)
{
    const size_t n = s->n;
    gsl_spmatrix *C = s->C;
    cf_error lerr = {0};
    double *rhs = malloc(4 * n * sizeof(double));
    if (!rhs) {
        *fatal = 1;
        cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent solve");
        return 0;
    }
    double *xv = rhs + n, *r = rhs + 2 * n, *dv = rhs + 3 * n;
    for (size_t e = 0; e < n; e++)
        rhs[e] = b[e] / s->D[e];
    int ok = cf_sparse_chol_solve(s->chol, rhs, xv, &lerr) == CF_OK;
    /* residual check, || rhs - C x || against || rhs ||, with up to CHOL_REFINE steps of
    ** iterative refinement (an indefinite tangent near a singular one may need them) */
    gsl_vector_view xw = gsl_vector_view_array(xv, n), rw = gsl_vector_view_array(r, n);
    gsl_vector_const_view bw = gsl_vector_const_view_array(rhs, n);
    const double bn = gsl_blas_dnrm2(&bw.vector);
    for (int k = 0; ok; k++) {
        memcpy(r, rhs, n * sizeof(double));
        ok = gsl_spblas_dgemv(CblasNoTrans, -1.0, C, &xw.vector, 1.0, &rw.vector) == GSL_SUCCESS;
        if (!ok || gsl_blas_dnrm2(&rw.vector) <= BAND_ACCEPT * bn)
            break;
        ok = k < CHOL_REFINE && cf_sparse_chol_solve(s->chol, r, dv, &lerr) == CF_OK;
        for (size_t e = 0; ok && e < n; e++)
            xv[e] += dv[e];
    }
    for (size_t e = 0; ok && e < n; e++) {
        double v = xv[e] / s->D[e];
        ok = isfinite(v);
        x[e] = v;
    }
    free(rhs);
    return ok;
}

static void assemble(cf_linsolve *s);

cf_status cf_linsolve_factor(cf_linsolve *s, cf_error *err)
{
    const size_t n = s->n;
    cf_error lerr = {0};
    s->chol_ready = 0;
    s->neg_pivots = -1;
    assemble(s);
    if (n == 0)
        return cf_error_set(err, CF_E_NOCONV, "linear solver: no unknowns to factor");
    if (!s->sb && !(s->sb = malloc(n * sizeof *s->sb)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the linear solves");
    cf_status st = CF_OK;
    if (!s->chol) {
        st = cf_sparse_chol_create(&s->chol, n, s->C->p, s->C->i, &lerr);
        if (st != CF_OK)
            return cf_error_set(err, st, "%s", lerr.msg);
        if (s->indefinite)
            cf_sparse_chol_indefinite(s->chol);
    }
    cf_chol_info info;
    if ((st = cf_sparse_chol_factor(s->chol, s->C->data, &info, &lerr)) != CF_OK)
        return cf_error_set(err, st, "%s", lerr.msg);
    s->neg_pivots = info.neg_pivots;
    s->chol_ready = 1;
    return CF_OK;
}

cf_status cf_linsolve_solve(cf_linsolve *s, const double *b, double *x, cf_error *err)
{
    const size_t n = s->n;
    if (!s->chol_ready)
        return cf_error_set(err, CF_E_NOCONV, "linear solver: no factors kept to solve with");
    /* (D^-1 A D^-1) (D x) = D^-1 b */
    for (size_t e = 0; e < n; e++)
        s->sb[e] = b[e] / s->D[e];
    cf_error lerr = {0};
    cf_status st = cf_sparse_chol_solve(s->chol, s->sb, x, &lerr);
    if (st != CF_OK)
        return cf_error_set(err, st, "%s", lerr.msg);
    for (size_t e = 0; e < n; e++) {
        x[e] /= s->D[e];
        if (!isfinite(x[e]))
            return cf_error_set(err, CF_E_NOCONV,
                                "linear solver: the solve gave a value that is not finite (%g at "
                                "unknown %zu)", x[e], e);
    }
    return CF_OK;
}

/* The scaled matrix is symmetric and often banded (a lattice's tangent, its nodes numbered layer
** by layer: half-bandwidth about 3 (nx + 1)(ny + 1)): a banded LDL^T (GSL) costs n b^2 instead of
** n^3/3; with banded_only (the stability checks' many small tangents) band_ldlt.c's, which gives
** GSL's factors faster. It does
** not pivot, so the solve is accepted only when its residual is small; otherwise the caller falls
** back to dense LU or GMRES. Returns 1 when x holds the solution. */
static int band_direction(cf_linsolve *s, const double *b, double *x)
{
    const size_t n = s->n, bw = s->band;
    const gsl_spmatrix *C = s->C;
    if (bw + 1 > n || (double)n * (double)(bw + 1) > CF_LINSOLVE_BAND_MAX_ENTRIES)
        return 0;
    if (!s->AB && !(s->AB = gsl_matrix_alloc(n, bw + 1)))
        return 0;
    double *ab = s->AB->data; /* AB(j, i - j) = A(i, j), rows of bw + 1 (band_ldlt.h) */
    memset(ab, 0, n * (bw + 1) * sizeof(double));
    for (size_t col = 0; col < n; col++)
        for (int k = C->p[col]; k < C->p[col + 1]; k++) {
            size_t row = (size_t)C->i[k];
            if (row >= col)
                ab[col * (bw + 1) + row - col] = C->data[k];
        }
    gsl_vector *rhs = gsl_vector_alloc(n), *xv = gsl_vector_alloc(n), *r = gsl_vector_alloc(n);
    int ok = rhs && xv && r;
    long neg = 0; /* the inertia from D, the first column of the decomposed band */
    if (ok) {
        for (size_t e = 0; e < n; e++)
            gsl_vector_set(rhs, e, b[e] / s->D[e]);
        if (s->banded_only) { /* the stability checks' many small tangents (band_ldlt.h) */
            ok = cf_band_ldlt_factor(ab, n, bw, &neg) == 0;
            gsl_vector_memcpy(xv, rhs);
            if (ok)
                cf_band_ldlt_solve(ab, n, bw, xv->data);
        } else {
            ok = gsl_linalg_ldlt_band_decomp(s->AB) == GSL_SUCCESS &&
                 gsl_linalg_ldlt_band_solve(s->AB, rhs, xv) == GSL_SUCCESS;
            for (size_t e = 0; ok && e < n; e++)
                neg += ab[e * (bw + 1)] < 0;
        }
    }
    if (ok) { /* residual check: r = rhs - C x */
        gsl_vector_memcpy(r, rhs);
        ok = gsl_spblas_dgemv(CblasNoTrans, -1.0, C, xv, 1.0, r) == GSL_SUCCESS &&
             gsl_blas_dnrm2(r) <= BAND_ACCEPT * gsl_blas_dnrm2(rhs);
    }
    for (size_t e = 0; ok && e < n; e++) {
        double v = gsl_vector_get(xv, e) / s->D[e];
        ok = isfinite(v);
        x[e] = v;
    }
    if (ok) {
        s->neg_pivots = neg;
        s->iters++;
    }
    gsl_vector_free(rhs);
    gsl_vector_free(xv);
    gsl_vector_free(r);
    return ok;
}

/* Small systems are solved directly: LU with partial pivoting (GSL) of the scaled tangent costs
** well under a millisecond for the few hundred DOFs of a validation lattice, where restarted GMRES
** took several (measured on the 3x3x3 hysteresis scene: 18 s before; src/notes/performance.md). */
static cf_status dense_direction(cf_linsolve *s, const double *b, double *x, cf_error *err)
{
    const size_t n = s->n;
    const gsl_spmatrix *C = s->C;
    gsl_matrix *A = gsl_matrix_calloc(n, n);
    gsl_permutation *perm = gsl_permutation_alloc(n);
    gsl_vector *bv = gsl_vector_alloc(n), *xv = gsl_vector_alloc(n);
    cf_status st = CF_OK;
    int sign;
    if (!A || !perm || !bv || !xv) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the lattice tangent (%zu DOFs)",
                          n);
        goto done;
    }
    for (size_t col = 0; col < n; col++)
        for (int k = C->p[col]; k < C->p[col + 1]; k++)
            gsl_matrix_set(A, (size_t)C->i[k], col, C->data[k]);
    for (size_t e = 0; e < n; e++)
        gsl_vector_set(bv, e, b[e] / s->D[e]);
    if (gsl_linalg_LU_decomp(A, perm, &sign) != GSL_SUCCESS ||
        gsl_linalg_LU_solve(A, perm, bv, xv) != GSL_SUCCESS) {
        st = cf_error_set(err, CF_E_NOCONV, "the lattice tangent is singular (%zu DOFs)", n);
        goto done;
    }
    for (size_t e = 0; e < n; e++) {
        double v = gsl_vector_get(xv, e) / s->D[e];
        if (!isfinite(v)) {
            st = cf_error_set(err, CF_E_NOCONV, "the lattice tangent is singular (%zu DOFs)", n);
            goto done;
        }
        x[e] = v;
    }
    s->iters++;
done:
    gsl_matrix_free(A);
    gsl_permutation_free(perm);
    gsl_vector_free(bv);
    gsl_vector_free(xv);
    return st;
}

/* Restarted GMRES on the scaled tangent: the last resort of the cascade, for a system above
** CF_LINSOLVE_DENSE_MAX_DOF free DOFs that neither the sparse nor the banded factorisation solved. */
static cf_status gmres_direction(cf_linsolve *s, const double *b, double *x, cf_error *err)
{
    const size_t n = s->n;
    gsl_spmatrix *C = s->C;
    gsl_vector *bv = gsl_vector_alloc(n), *xv = gsl_vector_calloc(n);
    size_t restart = n < CF_LINSOLVE_GMRES_RESTART ? n : CF_LINSOLVE_GMRES_RESTART;
    gsl_splinalg_itersolve *w = gsl_splinalg_itersolve_alloc(gsl_splinalg_itersolve_gmres, n,
                                                              restart);
    cf_status st = CF_OK;
    if (!bv || !xv || !w) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for GMRES");
        goto done;
    }
    for (size_t e = 0; e < n; e++)
        gsl_vector_set(bv, e, b[e] / s->D[e]);
    int status = GSL_CONTINUE;
    for (int it = 0; it < GMRES_MAX_RESTARTS && status == GSL_CONTINUE; it++) {
        status = gsl_splinalg_itersolve_iterate(C, bv, GMRES_TOL, xv, w);
        s->iters++;
    }
    /* Stagnation near rounding is accepted when the update is still accurate to a few digits:
    ** Newton corrects the rest (inexact Newton). */
    if (status != GSL_SUCCESS &&
        gsl_splinalg_itersolve_normr(w) <= GMRES_ACCEPT * gsl_blas_dnrm2(bv))
        status = GSL_SUCCESS;
    if (status != GSL_SUCCESS) {
        st = cf_error_set(err, CF_E_NOCONV,
                          "GMRES did not converge on the lattice tangent (residual %.3g)",
                          gsl_splinalg_itersolve_normr(w));
        goto done;
    }
    for (size_t e = 0; e < n; e++)
        x[e] = gsl_vector_get(xv, e) / s->D[e];
done:
    gsl_splinalg_itersolve_free(w);
    gsl_vector_free(bv);
    gsl_vector_free(xv);
    return st;
}

/* v <- D^-1 v D^-1 with D = s->D (C's pattern). */
void cf_linsolve_scale(const cf_linsolve *s, double *v)
{
    const gsl_spmatrix *C = s->C;
    for (size_t col = 0; col < s->n; col++)
        for (int k = C->p[col]; k < C->p[col + 1]; k++)
            v[k] /= s->D[C->i[k]] * s->D[col];
}

/* Assembles the matrix into C (through fill) and scales it symmetrically, A' = D^-1 A D^-1 with
** D = sqrt|diag| in s->D (a congruence: the inertia is that of A). */
static void assemble(cf_linsolve *s)
{
    const size_t n = s->n;
    gsl_spmatrix *C = s->C;
    s->fill(s->ctx, C->data);
    for (size_t e = 0; e < n; e++) {
        double d = s->diag[e] >= 0 ? C->data[s->diag[e]] : 0.0;
        s->D[e] = (d != 0 && isfinite(d)) ? sqrt(fabs(d)) : 1.0;
    }
    cf_linsolve_scale(s, C->data);
}

/* Assembles and scales the matrix, then solves A x = b: sparse Cholesky or L D L^T (unless
** banded_only), else banded LDL^T, dense LU for small systems, GMRES. */
static cf_status cascade(cf_linsolve *s, const double *b, double *x, cf_error *err)
{
    assemble(s);
    int fatal = 0;
    s->neg_pivots = -1;
    if (!s->banded_only && chol_direction(s, b, x, &fatal, err))
        return CF_OK;
    if (fatal)
        return CF_E_INTERNAL;
    if (band_direction(s, b, x))
        return CF_OK;
    if (s->n <= CF_LINSOLVE_DENSE_MAX_DOF)
        return dense_direction(s, b, x, err);
    return gmres_direction(s, b, x, err);
}

cf_status cf_linsolve_direction(cf_linsolve *s, const double *b, double *x, size_t *solves,
                                cf_error *err)
{
    s->iters = 0;
    cf_status st = cascade(s, b, x, err);
    if (solves)
        *solves += s->iters;
    return st;
}
