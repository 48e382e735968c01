/*
** A mechanical system as the Newton driver sees it (mech_newton.c), the way SUNDIALS separates its
** matrices and linear solvers from its integrators: a state of n unknowns that the system keeps,
** its residual (the energy's gradient less the loads, zero at the held components), its tangent
** written into the pattern of a linear solver (linsolve.h: sparse Cholesky or L D L^T with the
** inertia, band, dense, GMRES), and a step hook that moves the state to origin - alpha dx and
** tells whether that state is admissible (no tetrahedron inverted, no spring taken to solid).
** What the system is (a body's springs and volume term per tetrahedron or node, the probe's
** contact, an implicit step's inertia) stays behind the hooks. Private to the model layer.
*/
#ifndef CF_MODEL_MECH_H
#define CF_MODEL_MECH_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/linsolve.h"

typedef struct cf_mech_ops {
    /* The residual at the current state into r (n), zero at the held components. */
    cf_status (*residual)(void *ctx, double *r, cf_error *err);
    /* The tangent's values at the current state, in the pattern's order (held components' rows
    ** and columns zero, their diagonal 1). */
    cf_linsolve_fill *tangent;
    /* Zeroes the held components of a direction (NULL: none to zero). Factors of an earlier
    ** tangent may have been taken with other components held. */
    void (*project)(void *ctx, double *dx);
    /* Marks the current state as the origin of the next steps (before the first trial). */
    void (*save)(void *ctx);
    /* Moves the state to origin - alpha dx; returns 1 when it is admissible. alpha 0 restores
    ** the origin. */
    int (*trial)(void *ctx, const double *dx, double alpha);
} cf_mech_ops;

/* The system and its solver settings. */
typedef struct cf_mech {
    size_t n;            /* unknowns of the state */
    size_t n_aux;        /* auxiliary unknowns the linear systems hold beyond them (fields of a
                            mixed form such as nodal pressures: their right-hand side is zero,
                            their solution unused; their block must be negative definite, so that
                            the inertia of the condensed tangent is the system's less n_aux
                            negative eigenvalues, Haynsworth) */
    const cf_mech_ops *ops;
    void *ctx;
    cf_linsolve *ls;     /* made by cf_mech_create with the system's pattern and tangent */
    double tol;          /* converged when the residual's largest component is at most tol */
    double step_tol;     /* or when a full step's largest component is at most step_tol */
    int max_iter;        /* steps per call */
    double chord_rate;   /* a step from the last factors is kept while each cuts the residual to
                            this fraction of the last (0: a fresh tangent every step) */
    int max_halvings;    /* halvings of a step looking for an admissible state */
    double min_alpha;    /* a step shortened below this fails */
    /* between calls: 1 when the next step must take the tangent afresh (the caller sets it when
    ** the system changed, e.g. a contact set); the driver keeps it as it ends */
    int fresh;
} cf_mech;

/* What one call of cf_mech_newton did. */
typedef struct cf_mech_result {
    int conv;            /* 1: converged (residual within tol, or a full step within step_tol) */
    int inadmissible;    /* 1: ended because no step shorter than min_alpha was admissible */
    int iters;           /* steps taken */
    int factorizations;  /* tangents assembled and solved afresh */
    long neg_pivots;     /* negative eigenvalues of the last fresh tangent (its condensed form
                            when there are auxiliary unknowns), -1 unknown */
    double rnorm;        /* the residual's largest component at the end */
} cf_mech_result;

/* Fills m's settings with the defaults (200 steps, chord rate 1/4, 40 halvings, min_alpha
** 2^-20, fresh = 1) and makes its linear solver for n + n_aux unknowns with the pattern
** colp[n + n_aux + 1], rowi (linsolve.h: both triangles, rows increasing in a column, every
** diagonal entry; copied; the tangent writes every entry). ops and ctx must outlive m.
** CF_E_INTERNAL when memory runs out. */
cf_status cf_mech_create(cf_mech *m, size_t n, size_t n_aux, const cf_mech_ops *ops, void *ctx,
                         const int *colp, const int *rowi, cf_error *err);
void cf_mech_free(cf_mech *m);

/* Newton's method from the current state: steps from the last factors while they converge at
** chord_rate, the tangent afresh otherwise (and after a shortened step), each step halved until
** admissible. CF_OK with res->conv 0 when max_iter steps did not converge or no admissible step
** was found (res->inadmissible); an error of the linear solver (CF_E_NOCONV: singular, CF_E_INTERNAL:
** out of memory) or of the residual otherwise, the state then where the last step left it. */
/* r and dx are work vectors of n + n_aux entries. */
cf_status cf_mech_newton(cf_mech *m, double *r, double *dx, cf_mech_result *res, cf_error *err);

#endif
