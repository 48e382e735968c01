/*
** Sparse symmetric factorisation with inertia (see sparse_chol.h), on SuiteSparse CHOLMOD.
** CHOLMOD user guide: cholmod_analyze, cholmod_factorize, cholmod_solve; Common->supernodal
** selects supernodal LL^T or simplicial LDL^T, L->minor < n reports where a factorisation stopped.
*/
#include "model/sparse_chol.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

struct cf_sparse_chol {
    cholmod_common cm;
    cholmod_sparse A;      /* a header over the caller's arrays (lower triangle used) */
    cholmod_factor *LL;    /* supernodal (or simplicial, for small matrices) LL^T */
    cholmod_factor *LD;    /* simplicial L D L^T, analysed when first needed */
    cholmod_factor *last;  /* the factor the last successful factorisation left */
    size_t n;
    size_t lower_nnz;      /* entries of the lower triangle */
    int indefinite;        /* the last matrix was indefinite: start the next one with L D L^T */
};

static void header(cholmod_sparse *A, size_t n, int *colptr, int *rowidx, double *values)
{
    memset(A, 0, sizeof *A);
    A->nrow = A->ncol = n;
    A->nzmax = (size_t)colptr[n];
    A->p = colptr;
    A->i = rowidx;
    A->x = values;
    A->stype = -1; /* symmetric, lower triangle stored (entries above are ignored) */
    A->itype = CHOLMOD_INT;
    A->xtype = CHOLMOD_REAL;
    A->dtype = CHOLMOD_DOUBLE;
    A->sorted = 0;
    A->packed = 1;
}

cf_status cf_sparse_chol_create(cf_sparse_chol **out, size_t n, int *colptr, int *rowidx,
                                cf_error *err)
{
    *out = NULL;
    if (n == 0 || n > (size_t)1 << 30)
        return cf_error_set(err, CF_E_INTERNAL, "sparse factorisation of %zu unknowns", n);
    cf_sparse_chol *ch = calloc(1, sizeof *ch);
    if (!ch)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the sparse factorisation");
    if (!cholmod_start(&ch->cm)) {
        free(ch);
        return cf_error_set(err, CF_E_INTERNAL, "CHOLMOD could not start");
    }
    ch->cm.print = 0;            /* the library never prints */
    ch->cm.error_handler = NULL;
    ch->cm.quick_return_if_not_posdef = 1; /* stop at the first non-positive pivot */
    ch->n = n;
    for (size_t c = 0; c < n; c++)
        for (int k = colptr[c]; k < colptr[c + 1]; k++)
            if ((size_t)rowidx[k] >= c)
                ch->lower_nnz++;
    header(&ch->A, n, colptr, rowidx, NULL);
    ch->A.xtype = CHOLMOD_PATTERN; /* no values yet */
    ch->cm.supernodal = CHOLMOD_AUTO; /* supernodal where it pays (more flops per entry) */
    ch->LL = cholmod_analyze(&ch->A, &ch->cm);
    if (!ch->LL || ch->cm.status < CHOLMOD_OK) {
        const int status = ch->cm.status;
        cf_sparse_chol_free(ch);
        return cf_error_set(err, CF_E_INTERNAL,
                            "sparse analysis of the tangent failed (%zu unknowns, CHOLMOD status "
                            "%d)",
                            n, status);
    }
    ch->A.xtype = CHOLMOD_REAL;
    *out = ch;
    return CF_OK;
}

/* Counts the negative entries of D in a simplicial LDL^T factor (D(j,j) is the first entry of
** column j); returns -1 if a pivot is zero or not finite. */
static long count_negative(const cholmod_factor *L)
{
    const int *p = L->p;
    const double *x = L->x;
    long neg = 0;
    for (size_t j = 0; j < L->n; j++) {
        double d = x[p[j]];
        if (!(d != 0) || !isfinite(d))
            return -1;
        neg += d < 0;
    }
    return neg;
}

cf_status cf_sparse_chol_factor(cf_sparse_chol *ch, double *values, cf_chol_info *info,
                                cf_error *err)
{
    cf_chol_info local;
    cf_chol_info *in = info ? info : &local;
    memset(in, 0, sizeof *in);
    in->neg_pivots = -1;
    ch->last = NULL;
    ch->A.x = values;
    /* Successive tangents of a solve change little: after an indefinite one, skip the LL^T that
    ** would stop at its first negative pivot. */
    if (ch->indefinite)
        goto ldlt;
    cholmod_factorize(&ch->A, ch->LL, &ch->cm);
    if (ch->cm.status == CHOLMOD_OUT_OF_MEMORY)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory factoring the tangent (%zu "
                            "unknowns)", ch->n);
    if (ch->cm.status == CHOLMOD_OK && ch->LL->minor == ch->n) {
        /* A small matrix may have been analysed as simplicial L D L^T: its D has the inertia. */
        in->neg_pivots = (ch->LL->is_super || ch->LL->is_ll) ? 0 : count_negative(ch->LL);
        if (in->neg_pivots < 0) {
            in->singular = 1;
            return cf_error_set(err, CF_E_NOCONV,
                                "the lattice tangent is singular or not finite (%zu unknowns)",
                                ch->n);
        }
        in->ldlt = !(ch->LL->is_super || ch->LL->is_ll);
        in->fill = ch->lower_nnz ? (double)(ch->cm.lnz) / (double)ch->lower_nnz : 0;
        ch->last = ch->LL;
        return CF_OK;
    }
    /* Not positive definite (or a NaN): L D L^T, which keeps going past negative pivots. */
ldlt:
    in->ldlt = 1;
    if (!ch->LD) {
        const int saved = ch->cm.supernodal;
        ch->A.xtype = CHOLMOD_PATTERN;
        ch->cm.supernodal = CHOLMOD_SIMPLICIAL;
        ch->cm.final_ll = 0;
        ch->LD = cholmod_analyze(&ch->A, &ch->cm);
        ch->cm.supernodal = saved;
        ch->A.xtype = CHOLMOD_REAL;
        if (!ch->LD)
            return cf_error_set(err, CF_E_INTERNAL,
                                "out of memory analysing the indefinite tangent (%zu unknowns)",
                                ch->n);
    }
    const int saved_quick = ch->cm.quick_return_if_not_posdef;
    ch->cm.quick_return_if_not_posdef = 0;
    cholmod_factorize(&ch->A, ch->LD, &ch->cm);
    ch->cm.quick_return_if_not_posdef = saved_quick;
    if (ch->cm.status == CHOLMOD_OUT_OF_MEMORY)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory factoring the tangent (%zu "
                            "unknowns)", ch->n);
    long neg = (ch->LD->minor == ch->n && !ch->LD->is_ll) ? count_negative(ch->LD) : -1;
    in->fill = ch->lower_nnz ? (double)(ch->cm.lnz) / (double)ch->lower_nnz : 0;
    if (neg < 0) {
        in->singular = 1;
        return cf_error_set(err, CF_E_NOCONV,
                            "the lattice tangent is singular or not finite (%zu unknowns, zero "
                            "pivot at column %zu)",
                            ch->n, (size_t)ch->LD->minor);
    }
    in->neg_pivots = neg;
    ch->indefinite = neg > 0;
    ch->last = ch->LD;
    return CF_OK;
}

cf_status cf_sparse_chol_solve(cf_sparse_chol *ch, const double *b, double *x, cf_error *err)
{
    if (!ch->last)
        return cf_error_set(err, CF_E_INTERNAL, "sparse solve without a factorisation");
    cholmod_dense B;
    memset(&B, 0, sizeof B);
    B.nrow = ch->n;
    B.ncol = 1;
    B.nzmax = ch->n;
    B.d = ch->n;
    B.x = (void *)b; /* read only: CHOLMOD does not write the right-hand side */
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    cholmod_dense *X = cholmod_solve(CHOLMOD_A, ch->last, &B, &ch->cm);
    if (!X)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the sparse solve (%zu unknowns)",
                            ch->n);
    memcpy(x, X->x, ch->n * sizeof(double));
    cholmod_free_dense(&X, &ch->cm);
    return CF_OK;
}

size_t cf_sparse_chol_peak_bytes(const cf_sparse_chol *ch)
{
    return ch ? ch->cm.memory_usage : 0;
}

void cf_sparse_chol_free(cf_sparse_chol *ch)
{
    if (!ch)
        return;
    if (ch->LL)
        cholmod_free_factor(&ch->LL, &ch->cm);
    if (ch->LD)
        cholmod_free_factor(&ch->LD, &ch->cm);
    cholmod_finish(&ch->cm);
    free(ch);
}
