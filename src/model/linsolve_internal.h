/*
** The state of a linear solver (linsolve.h), shared by linsolve.c and linsolve_krylov.c only.
*/
#ifndef CF_MODEL_LINSOLVE_INTERNAL_H
#define CF_MODEL_LINSOLVE_INTERNAL_H

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_spmatrix.h>

#include "model/linsolve.h"
#include "model/sparse_chol.h"

struct cf_linsolve {
    size_t n;                 /* unknowns */
    gsl_spmatrix *C;          /* the matrix, compressed columns, the caller's pattern; after a
                                 direction its values scaled by D (the matrix last factored) */
    int *diag;                /* unknown -> index of its diagonal entry in C->data */
    size_t band;              /* half-bandwidth of C (largest |row - col|) */
    double *D;                /* Jacobi scale of the last matrix, sqrt|diag| (n) */
    cf_linsolve_fill *fill;   /* assembles the matrix (linsolve.h) */
    void *ctx;
    int banded_only;          /* no sparse factorisation */
    gsl_matrix *AB;           /* banded LDL^T workspace, n x (band + 1); NULL until used */
    cf_sparse_chol *chol;     /* sparse factorisation of C (pattern analysed once); NULL until
                                 used */
    int indefinite;           /* cf_linsolve_indefinite */
    int chol_failed;          /* 1: the sparse factorisation could not be set up; not retried */
    int chol_ready;           /* chol holds the factors of C, scaled by D, for a chord step */
    long neg_pivots;          /* negative pivots of the last factored matrix, -1 unknown */
    size_t iters;             /* linear solves of the current direction */
    double *kval;             /* the current matrix, C's pattern, scaled by D (Krylov steps) */
    double *kbasis;           /* their Krylov basis and preconditioned basis; NULL until used */
    double *sb;               /* n: the scaled right-hand side of cf_linsolve_solve; NULL until
                                 cf_linsolve_factor */
};

/* v <- D^-1 v D^-1 with the solver's D (v in C's pattern; linsolve.c). */
void cf_linsolve_scale(const cf_linsolve *s, double *v);

#endif
