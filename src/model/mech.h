/*
** A mechanical system as the Newton driver sees it (mech_newton.c), the way SUNDIALS separates its
** matrices and linear solvers from its integrators: a state of n unknowns that the system keeps,
** its residual (zero at the held components), its tangent written into the pattern of a linear
** solver (linsolve.h: sparse Cholesky or L D L^T with the inertia, band, dense, GMRES), and a step
** hook that moves the state along a Newton direction and tells whether the state it leads to is
** admissible (no tetrahedron inverted, no spring taken to solid). What the system is (a body's
** springs and volume term per tetrahedron or node, the probe's contact, an implicit step's
** inertia; the cubic lattice's springs, volume term and hourglass control, its quasi-static
** dashpots) stays behind the hooks; how the driver iterates (steps on kept factors, Krylov steps,
** a fresh tangent, the step's acceptance) is in the system's settings. Private to the model layer.
*/
#ifndef CF_MODEL_MECH_H
#define CF_MODEL_MECH_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/linsolve.h"

typedef struct cf_mech_ops {
    /* The residual at the current state into r (n), zero at the held components. */
    cf_status (*residual)(void *ctx, double *r, cf_error *err);
    /* The tangent's values at the state of the last residual, in the pattern's order (held
    ** components' rows and columns zero, their diagonal 1). The direction dx solves
    ** tangent dx = r. */
    cf_linsolve_fill *tangent;
    /* Zeroes the held components of a direction (NULL: none to zero). Factors of an earlier
    ** tangent may have been taken with other components held. */
    void (*project)(void *ctx, double *dx);
    /* Marks the current state as the origin of the next steps (before the first trial). */
    void (*save)(void *ctx);
    /* Moves the state from the origin by alpha times Newton's step along dx (origin - alpha dx
    ** when r is the energy's gradient and the tangent its Hessian, origin + alpha dx when r is
    ** the out-of-balance force and the tangent minus its derivative); returns 1 when that state
    ** is admissible. alpha 0 restores the origin. A system whose admissibility comes from its
    ** forces (the lattice: every spring short of solid) may evaluate its residual here; the
    ** residual hook that follows at the same state then returns it without evaluating again. */
    int (*trial)(void *ctx, const double *dx, double alpha);
    /* The tolerance at the state of the last residual (NULL: m->tol everywhere): the residual's
    ** largest component at which that state is converged; *may_end (preset 1) set to 0 when the
    ** state may not end the iteration whatever its residual (a spring within rounding of solid). */
    double (*tolerance)(void *ctx, int *may_end);
    /* A direction dx for r from factors the system keeps itself, corrected as it knows how (the
    ** haptic loop: the contact-free tangent's factors, its contact set by Woodbury's identity);
    ** NULL: the driver's chord step on its linear solver's last factors. Called only when the
    ** settings say chord_only. An error ends the call. */
    cf_status (*chord)(void *ctx, const double *r, double *dx, cf_error *err);
} cf_mech_ops;

/* The system and its solver settings. A direction comes from one of three stages: a fresh
** tangent (assembled, factored through the linear solver's cascade, its inertia noted), a chord
** step on the factors of the last one, or a Krylov step (GMRES on the current tangent,
** preconditioned by those factors, only as accurate as the iteration needs). A step from kept
** factors that is refused, that finds no acceptable state or that is judged slow hands the next
** direction to the next stage (chord, then Krylov when use_krylov, then a fresh tangent). */
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
    double tol;          /* converged when the residual's largest component is at most tol
                            (ops->tolerance, when given, says it state by state) */
    double step_tol;     /* or when a full step's largest component is at most step_tol (0: not
                            a test) */
    int max_iter;        /* directions per call (a final state is still tested) */
    double chord_rate;   /* a step from kept factors is kept while each cuts the residual to
                            this fraction of the last at full length (0: a fresh tangent every
                            step) */
    int use_krylov;      /* 1: chord steps that stall give way to Krylov steps before a fresh
                            tangent */
    int judge_fresh;     /* 1: every step is judged: one from a fresh tangent is held to
                            chord_rate as well (missed: the next tangent fresh too), and a
                            shortened step takes the next tangent afresh even where the state it
                            reached converged (the next call starts there); 0: the factors of a
                            fresh tangent are always tried, and a step on kept factors is judged
                            only when the iteration goes on */
    double decrease;     /* 0: a step is accepted at the first admissible state; > 0: where the
                            residual there (evaluated at each trial) is also below
                            (1 - decrease alpha) of the origin's, */
    int accept_after;    /* or, after this many halvings of a fresh tangent's step, wherever it
                            is admissible and finite */
    int max_halvings;    /* halvings of a fresh tangent's step looking for an acceptable state */
    int reuse_halvings;  /* halvings of a step from kept factors before it is given up */
    double min_alpha;    /* a step shortened below this fails */
    int chord_only;      /* 1: every direction from kept factors (ops->chord when given), none
                            judged, no tangent taken afresh: the factors the caller made stand
                            for the tangent of the whole call; a step with no admissible state
                            ends the call (res->inadmissible, the state at its origin) */
    int last_unevaluated;/* 1: a fixed iteration count: the state the max_iter-th direction leads
                            to is not evaluated (the caller reads there what it needs: the haptic
                            loop's force from the body's side); res->rnorm then the residual's
                            before that step */
    /* Between calls, the stage of the next direction: fresh 1 when it must take the tangent
    ** afresh (the caller sets it when the system changed, e.g. a contact set), krylov 1 when
    ** chord steps stalled on the kept factors; the driver keeps them as it ends. */
    int fresh;
    int krylov;
} cf_mech;

/* What one call of cf_mech_newton (or cf_mech_inertia) did. */
typedef struct cf_mech_result {
    int conv;            /* 1: converged (residual within tolerance, or a full step within
                            step_tol) */
    int inadmissible;    /* 1: ended because a fresh tangent's step (any step under chord_only)
                            found no acceptable state */
    int iters;           /* directions sought (one refused by stale factors counts too) */
    int reused;          /* of them, directions from kept factors (chord and Krylov steps) */
    int tangents;        /* fresh tangents assembled and solved */
    int factorizations;  /* of them, solved */
    size_t linear_solves;/* the linear solver's solves of the fresh tangents (linsolve.h) */
    long neg_pivots;     /* negative eigenvalues of the last fresh tangent (its condensed form
                            when there are auxiliary unknowns), -1 unknown */
    long neg_pivots_max; /* the most of any fresh tangent, -1 none known */
    int indefinite;      /* fresh tangents with negative eigenvalues */
    double rnorm;        /* the largest component of the last residual evaluated */
} cf_mech_result;

/* Fills m's settings with the defaults (200 steps, chord rate 1/4 on fresh tangents' steps too,
** no Krylov stage, a step accepted where admissible, 40 halvings, min_alpha 2^-20, fresh = 1)
** and makes its linear solver for n + n_aux unknowns with the pattern colp[n + n_aux + 1], rowi
** (linsolve.h: both triangles, rows increasing in a column, every diagonal entry; copied; the
** tangent writes every entry; banded_only as there). ops and ctx must outlive m.
** CF_E_INTERNAL when memory runs out. */
cf_status cf_mech_create(cf_mech *m, size_t n, size_t n_aux, const cf_mech_ops *ops, void *ctx,
                         const int *colp, const int *rowi, int banded_only, cf_error *err);
void cf_mech_free(cf_mech *m);

/* Newton's method from the current state: each direction from the stage m->fresh and m->krylov
** name (see cf_mech), each step halved until acceptable. CF_OK with res->conv 0 when max_iter
** directions did not converge or a fresh tangent's step found no acceptable state
** (res->inadmissible; the state then at that step's origin); an error of the linear solver
** (CF_E_NOCONV: singular, CF_E_INTERNAL: out of memory) or of the residual otherwise, the state
** then where the last step left it. r and dx are work vectors of n + n_aux entries; at the end r
** holds the last residual evaluated. */
cf_status cf_mech_newton(cf_mech *m, double *r, double *dx, cf_mech_result *res, cf_error *err);

/* The tangent at the state of the last residual assembled and solved afresh for r (a stability
** check: its inertia in res->neg_pivots, the direction in dx, which moves nothing). The stage of
** the next Newton direction is left as it was. */
cf_status cf_mech_inertia(cf_mech *m, const double *r, double *dx, cf_mech_result *res,
                          cf_error *err);

#endif
