/*
** The linear solves of Newton's method on the lattice (linsolve.c) and the size limits of their
** cascade. Private to the model layer; the limits are read by the cost estimate of a scene
** (io/budget.c), so that the estimate follows the solvers.
*/
#ifndef CF_MODEL_LINSOLVE_H
#define CF_MODEL_LINSOLVE_H

#include "conifit/error.h"

/* A node couples with itself and at most 26 neighbours (a 3 x 3 x 3 block of nodes): a column of
** the tangent holds at most 3 CF_LINSOLVE_MAX_ADJ entries. */
#define CF_LINSOLVE_MAX_ADJ 27
/* The banded LDL^T is tried only when its band fits in this many doubles, */
#define CF_LINSOLVE_BAND_MAX_ENTRIES 5e7
/* dense LU only up to this many free DOFs (a 7x7x7 lattice has about 1500), */
#define CF_LINSOLVE_DENSE_MAX_DOF 1200
/* and GMRES restarts after this many basis vectors (fewer when there are fewer DOFs). */
#define CF_LINSOLVE_GMRES_RESTART 150

struct solver; /* the solvers' workspace (msm_internal.h) */

/* Assembles the tangent at the state of the last residual and solves it for the Newton update
** s->dx, noting the tangent's inertia in the statistics. */
cf_status cf_linsolve_direction(struct solver *s, cf_error *err);

/* The update from the sparse factors of an earlier tangent (a chord step). Returns 1 when s->dx
** holds it; sets *fatal for an out-of-memory that no fallback would survive. */
int cf_linsolve_chord(struct solver *s, int *fatal, cf_error *err);

/* The tangent at the state of the last residual into v (the pattern of s->C, which must exist),
** scaled by the s->D of the last factorisation rather than its own diagonal: the matrix whose
** solve the factors of s->chol precondition (linsolve_krylov.c). */
void cf_linsolve_tangent_scaled(struct solver *s, double *v);

/* The update s->dx from the current tangent, by GMRES preconditioned with the sparse factors of
** an earlier one (s->chol, s->D). `need` is the reduction of the residual that would end Newton's
** iteration (tolerance over residual, below 1): the linear residual is brought to a tenth of it
** (kept between 1e-10 and 0.1 of the right-hand side: an inexact Newton step); after 16 GMRES
** steps short of that, a linear residual within `need` or 0.1, whichever is larger (at most 0.5),
** is still returned, a shorter step for the caller to judge. Returns 1 when s->dx holds it, 0 when
** the factors are too stale for even that (the caller refactors); sets *fatal for an
** out-of-memory that no fallback would survive. */
int cf_linsolve_krylov(struct solver *s, double need, int *fatal, cf_error *err);

#endif
