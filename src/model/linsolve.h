/*
** The linear solves of Newton's method on the lattice (linsolve.c). Private to the model layer.
*/
#ifndef CF_MODEL_LINSOLVE_H
#define CF_MODEL_LINSOLVE_H

#include "conifit/error.h"

struct solver; /* the solvers' workspace (msm_internal.h) */

/* Assembles the tangent at the state of the last residual and solves it for the Newton update
** s->dx, noting the tangent's inertia in the statistics. */
cf_status cf_linsolve_direction(struct solver *s, cf_error *err);

/* The update from the sparse factors of an earlier tangent (a chord step). Returns 1 when s->dx
** holds it; sets *fatal for an out-of-memory that no fallback would survive. */
int cf_linsolve_chord(struct solver *s, int *fatal, cf_error *err);

#endif
