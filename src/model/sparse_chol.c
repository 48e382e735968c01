/*
** Sparse symmetric factorisation with inertia (see sparse_chol.h).
** Positive definite matrices: SuiteSparse CHOLMOD, supernodal LL^T (user guide: cholmod_analyze,
** cholmod_factorize, cholmod_solve; L->minor < n reports where a factorisation stopped).
** Indefinite ones: MUMPS, multifrontal L D L^T with 1x1 and 2x2 pivots for symmetric matrices
** (SYM = 2), whose INFOG(12) is the number of negative pivots (MUMPS user guide, 5.x: JOB = 1
** analysis, 2 factorisation, 3 solve; ICNTL(1-4) output streams; INFO(1) = -8/-9 workspace too
** small, fixed by raising ICNTL(14); -10 numerically singular).
*/
#include "model/sparse_chol.h"

#include "model/sparse_dl.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#define MUMPS_USE_COMM_WORLD (-987654) /* the sequential library's stand-in communicator */

/* Neither library may run on two threads at once in one process. MUMPS keeps state of its own
** between the calls of one job in Fortran module variables (its load balancing, DMUMPS_LOAD) shared
** by every instance: two tables fitted on two threads (`conifit fit -j 2 --validate`) crashed
** inside dmumps_load_update about one run in three. CHOLMOD's supernodal factorisation goes
** through the BLAS, and with it unlocked the same batch gave validation errors that changed in
** their last digits from run to run (seven tables, three runs, three different results; with the
** lock, the same bits every time, as with one thread). So every call into either holds one
** process-wide lock: threads still fit in parallel, their factorisations take turns. */
static pthread_mutex_t sparse_lock = PTHREAD_MUTEX_INITIALIZER;

static void mumps_call(const cf_mumps_lib *ml, DMUMPS_STRUC_C *mu)
{
    pthread_mutex_lock(&sparse_lock);
    ml->dmumps_c(mu);
    pthread_mutex_unlock(&sparse_lock);
}

struct cf_sparse_chol {
    const cf_cholmod_lib *cl; /* the libraries' functions (sparse_dl.h): CHOLMOD from the start, */
    const cf_mumps_lib *ml;   /* MUMPS from the first indefinite matrix */
    cholmod_common cm;
    cholmod_sparse A;      /* a header over the caller's arrays (lower triangle used) */
    cholmod_factor *LL;    /* supernodal LL^T */
    size_t n;
    size_t lower_nnz;      /* entries of the lower triangle */
    const int *colptr, *rowidx;
    int last;              /* 0 none, 1 CHOLMOD, 2 MUMPS holds the last successful factorisation */
    int indefinite;        /* the last matrix was indefinite: start the next one with L D L^T */
    int always_ldlt;       /* cf_sparse_chol_indefinite: every matrix is */
    /* MUMPS, set up at the first indefinite matrix */
    int mumps_on;
    int mumps_failed;      /* its analysis failed: not retried */
    DMUMPS_STRUC_C mu;
    MUMPS_INT *irn, *jcn;  /* 1-based coordinates of the lower triangle */
    double *mval;          /* its values, copied from the caller's array */
    size_t *mpos;          /* position of each in the caller's value array */
    double *rhs;           /* MUMPS solves in place */
    size_t mumps_peak;     /* bytes MUMPS reported for its factors and workspace */
};

cf_status cf_sparse_chol_create(cf_sparse_chol **out, size_t n, int *colptr, int *rowidx,
                                cf_error *err)
{
    *out = NULL;
    if (n == 0 || n > (size_t)1 << 30)
        return cf_error_set(err, CF_E_INTERNAL, "sparse factorisation of %zu unknowns", n);
    cf_sparse_chol *ch = calloc(1, sizeof *ch);
    if (!ch)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the sparse factorisation");
    if (!(ch->cl = cf_cholmod_lib_get(err))) {
        free(ch);
        return CF_E_INTERNAL;
    }
    if (!ch->cl->cholmod_start(&ch->cm)) {
        free(ch);
        return cf_error_set(err, CF_E_INTERNAL, "CHOLMOD could not start");
    }
    ch->cm.print = 0; /* the library never prints */
    ch->cm.error_handler = NULL;
    ch->cm.quick_return_if_not_posdef = 1; /* stop at the first non-positive pivot */
    ch->cm.supernodal = CHOLMOD_SUPERNODAL;
    ch->n = n;
    ch->colptr = colptr;
    ch->rowidx = rowidx;
    for (size_t c = 0; c < n; c++)
        for (int k = colptr[c]; k < colptr[c + 1]; k++)
            if ((size_t)rowidx[k] >= c)
                ch->lower_nnz++;
    cholmod_sparse *A = &ch->A;
    A->nrow = A->ncol = n;
    A->nzmax = (size_t)colptr[n];
    A->p = colptr;
    A->i = rowidx;
    A->stype = -1; /* symmetric, lower triangle stored (entries above are ignored) */
    A->itype = CHOLMOD_INT;
    A->xtype = CHOLMOD_PATTERN; /* no values yet */
    A->dtype = CHOLMOD_DOUBLE;
    A->sorted = 0;
    A->packed = 1;
    ch->LL = ch->cl->cholmod_analyze(A, &ch->cm);
    if (!ch->LL || ch->cm.status < CHOLMOD_OK) {
        const int status = ch->cm.status;
        cf_sparse_chol_free(ch);
        if (status == CHOLMOD_OUT_OF_MEMORY)
            return cf_error_set(err, CF_E_INTERNAL,
                                "out of memory analysing the tangent (%zu unknowns)", n);
        return cf_error_set(err, CF_E_NOCONV,
                            "sparse analysis of the tangent failed (%zu unknowns, CHOLMOD status "
                            "%d)",
                            n, status);
    }
    A->xtype = CHOLMOD_REAL;
    *out = ch;
    return CF_OK;
}

/* Analysis of the pattern for MUMPS (once), with the values of the first indefinite matrix. */
static cf_status mumps_setup(cf_sparse_chol *ch, const double *values, cf_error *err)
{
    if (!(ch->ml = cf_mumps_lib_get(err))) {
        ch->mumps_failed = 1; /* not retried */
        return CF_E_INTERNAL;
    }
    const size_t nz = ch->lower_nnz;
    ch->irn = malloc(nz * sizeof *ch->irn);
    ch->jcn = malloc(nz * sizeof *ch->jcn);
    ch->mval = malloc(nz * sizeof *ch->mval);
    ch->mpos = malloc(nz * sizeof *ch->mpos);
    ch->rhs = malloc(ch->n * sizeof *ch->rhs);
    if (!ch->irn || !ch->jcn || !ch->mval || !ch->mpos || !ch->rhs)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the indefinite factorisation");
    size_t k = 0;
    for (size_t c = 0; c < ch->n; c++)
        for (int q = ch->colptr[c]; q < ch->colptr[c + 1]; q++)
            if ((size_t)ch->rowidx[q] >= c) {
                ch->irn[k] = (MUMPS_INT)ch->rowidx[q] + 1;
                ch->jcn[k] = (MUMPS_INT)c + 1;
                ch->mval[k] = values[q];
                ch->mpos[k++] = (size_t)q;
            }
    DMUMPS_STRUC_C *mu = &ch->mu;
    memset(mu, 0, sizeof *mu);
    mu->job = -1;
    mu->par = 1;
    mu->sym = 2; /* general symmetric: pivots may be negative or 2x2 */
    mu->comm_fortran = MUMPS_USE_COMM_WORLD;
    mumps_call(ch->ml, mu);
    if (mu->info[0] < 0)
        return cf_error_set(err, CF_E_INTERNAL, "MUMPS could not start (INFO(1) = %d)",
                            (int)mu->info[0]);
    ch->mumps_on = 1;
    mu->icntl[0] = -1; /* no error, diagnostic or global output: the library never prints */
    mu->icntl[1] = -1;
    mu->icntl[2] = -1;
    mu->icntl[3] = 0;
    mu->icntl[5] = 0;  /* no column permutation: the pattern is symmetric with a full diagonal */
    mu->icntl[6] = 7;  /* ordering chosen by the analysis */
    mu->icntl[11] = 1; /* the usual symmetric ordering, no 2x2 compression from a matching */
    mu->icntl[7] = 0;  /* no scaling: the caller's tangent is Jacobi-scaled already (measured:
                          about 10 % off the factorisations of a 12^3-cell lattice) */
    mu->n = (MUMPS_INT)ch->n;
    mu->nnz = (MUMPS_INT8)nz;
    mu->irn = ch->irn;
    mu->jcn = ch->jcn;
    mu->a = ch->mval;
    mu->job = 1;
    mumps_call(ch->ml, mu);
    if (mu->info[0] < 0) {
        ch->mumps_failed = 1;
        return cf_error_set(err, mu->info[0] == -7 ? CF_E_INTERNAL : CF_E_NOCONV,
                            "analysis of the indefinite tangent failed (%zu unknowns, MUMPS "
                            "INFO(1) = %d)",
                            ch->n, (int)mu->info[0]);
    }
    return CF_OK;
}

/* L D L^T by MUMPS; fills the inertia. */
static cf_status mumps_factor(cf_sparse_chol *ch, const double *values, cf_chol_info *in,
                              cf_error *err)
{
    cf_status st;
    if (ch->mumps_failed)
        return cf_error_set(err, CF_E_NOCONV, "no indefinite factorisation for this pattern");
    if (!ch->mumps_on && (st = mumps_setup(ch, values, err)) != CF_OK)
        return st;
    for (size_t k = 0; k < ch->lower_nnz; k++)
        ch->mval[k] = values[ch->mpos[k]];
    DMUMPS_STRUC_C *mu = &ch->mu;
    for (int attempt = 0; attempt < 4; attempt++) {
        mu->job = 2;
        mumps_call(ch->ml, mu);
        if (mu->info[0] != -8 && mu->info[0] != -9)
            break;
        mu->icntl[13] = mu->icntl[13] > 0 ? 2 * mu->icntl[13] : 40; /* more workspace, % */
    }
    /* INFOG(22): megabytes MUMPS used in the factorisation */
    const size_t mb = mu->infog[21] > 0 ? (size_t)mu->infog[21] : 0;
    if (mb << 20 > ch->mumps_peak)
        ch->mumps_peak = mb << 20;
    if (mu->info[0] == -10 || mu->info[0] == -6) {
        in->singular = 1;
        return cf_error_set(err, CF_E_NOCONV, "the lattice tangent is singular (%zu unknowns)",
                            ch->n);
    }
    if (mu->info[0] == -13 || mu->info[0] == -8 || mu->info[0] == -9)
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory factoring the indefinite tangent (%zu unknowns)", ch->n);
    if (mu->info[0] < 0)
        return cf_error_set(err, CF_E_NOCONV,
                            "factorisation of the indefinite tangent failed (%zu unknowns, MUMPS "
                            "INFO(1) = %d)",
                            ch->n, (int)mu->info[0]);
    in->neg_pivots = (long)mu->infog[11];
    in->fill = ch->lower_nnz ? (double)mu->infog[28] / (double)ch->lower_nnz : 0;
    ch->last = 2;
    return CF_OK;
}

cf_status cf_sparse_chol_factor(cf_sparse_chol *ch, double *values, cf_chol_info *info,
                                cf_error *err)
{
    cf_chol_info local;
    cf_chol_info *in = info ? info : &local;
    memset(in, 0, sizeof *in);
    in->neg_pivots = -1;
    ch->last = 0;
    for (size_t k = 0; k < (size_t)ch->colptr[ch->n]; k++)
        if (!isfinite(values[k]))
            return cf_error_set(err, CF_E_NOCONV, "the lattice tangent is not finite (%zu "
                                "unknowns)", ch->n);
    /* Successive tangents of a solve change little: after an indefinite one, go straight to the
    ** L D L^T instead of an LL^T that would stop at its first negative pivot. */
    if (!ch->indefinite) {
        ch->A.x = values;
        pthread_mutex_lock(&sparse_lock);
        ch->cl->cholmod_factorize(&ch->A, ch->LL, &ch->cm);
        pthread_mutex_unlock(&sparse_lock);
        if (ch->cm.status == CHOLMOD_OUT_OF_MEMORY)
            return cf_error_set(err, CF_E_INTERNAL,
                                "out of memory factoring the tangent (%zu unknowns)", ch->n);
        if (ch->cm.status == CHOLMOD_OK && ch->LL->minor == ch->n) {
            in->neg_pivots = 0;
            in->fill = ch->lower_nnz ? ch->cm.lnz / (double)ch->lower_nnz : 0;
            ch->last = 1;
            return CF_OK;
        }
    }
    /* not positive definite: L D L^T, which keeps going past negative pivots */
    in->ldlt = 1;
    cf_status st = mumps_factor(ch, values, in, err);
    if (st == CF_OK)
        ch->indefinite = in->neg_pivots > 0 || ch->always_ldlt;
    return st;
}

void cf_sparse_chol_indefinite(cf_sparse_chol *ch)
{
    ch->indefinite = 1;
    ch->always_ldlt = 1;
}

cf_status cf_sparse_chol_solve(cf_sparse_chol *ch, const double *b, double *x, cf_error *err)
{
    if (ch->last == 2) {
        memcpy(ch->rhs, b, ch->n * sizeof(double));
        ch->mu.rhs = ch->rhs;
        ch->mu.nrhs = 1;
        ch->mu.lrhs = (MUMPS_INT)ch->n;
        ch->mu.job = 3;
        mumps_call(ch->ml, &ch->mu);
        if (ch->mu.info[0] < 0)
            return cf_error_set(err, CF_E_INTERNAL, "the indefinite solve failed (MUMPS INFO(1) "
                                "= %d)", (int)ch->mu.info[0]);
        memcpy(x, ch->rhs, ch->n * sizeof(double));
        return CF_OK;
    }
    if (ch->last != 1)
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
    pthread_mutex_lock(&sparse_lock);
    cholmod_dense *X = ch->cl->cholmod_solve(CHOLMOD_A, ch->LL, &B, &ch->cm);
    pthread_mutex_unlock(&sparse_lock);
    if (!X)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the sparse solve (%zu unknowns)",
                            ch->n);
    memcpy(x, X->x, ch->n * sizeof(double));
    ch->cl->cholmod_free_dense(&X, &ch->cm);
    return CF_OK;
}

size_t cf_sparse_chol_peak_bytes(const cf_sparse_chol *ch)
{
    if (!ch)
        return 0;
    return ch->cm.memory_usage > ch->mumps_peak ? ch->cm.memory_usage : ch->mumps_peak;
}

void cf_sparse_chol_free(cf_sparse_chol *ch)
{
    if (!ch)
        return;
    if (ch->LL)
        ch->cl->cholmod_free_factor(&ch->LL, &ch->cm);
    ch->cl->cholmod_finish(&ch->cm);
    if (ch->mumps_on) {
        ch->mu.job = -2;
        mumps_call(ch->ml, &ch->mu);
    }
    free(ch->irn);
    free(ch->jcn);
    free(ch->mval);
    free(ch->mpos);
    free(ch->rhs);
    free(ch);
}
