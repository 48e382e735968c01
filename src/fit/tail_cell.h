/*
** The conical-tail law's search through the homogenised cell, shared by the fit of one table
** through the lattice and the joint fit of several (lattice_tail.c, joint.c): BOBYQA over
** (log rho, B = s/H, q) with the tail's share q = B tau/(1 - B) of the length past the cone's
** travel, the stress scale in closed form capped at what a buildable tailed spring carries.
** The problem's curve and cap read the tail tau from *tau, which the search sets before every
** curve. Private to the library; defined in lattice_tail.c.
*/
#ifndef CF_FIT_TAIL_CELL_H
#define CF_FIT_TAIL_CELL_H

#include <gsl/gsl_vector.h>

#include "model/family.h"
#include "fit/fit.h"
#include "fit/cell_problem.h"

typedef struct cf_tail_cell {
    cf_cell_problem *pr; /* its curve and A_max read *tau */
    double *tau;
} cf_tail_cell;

/* The search box of (log rho, B, q) for springs of the type reaching spring strain xmax. */
void cf_tail_cell_box(const cf_fit_options *opt, cf_spring_type type, double xmax, double lb[3],
                      double ub[3]);

/* The cap on the stress scale at (rho, B, tau) for the problem's A_max: 0 where the member's
** whole travel does not pass the strain need (the largest spring strain with the margin). */
double cf_tail_cell_A_max(double rho, double B, double tau, double need, cf_spring_type type,
                          const cf_fit_options *opt);

/* The weighted RSS over ynorm at z = (log rho, B, q), the scale in closed form into *A. */
double cf_tail_cell_profile(const cf_tail_cell *tc, const double z[3], double *A);

/* BOBYQA from the conical law's quantities start (two tails) and a coarse grid; the best z into
** zb, its objective returned (CF_LSQ_HUGE_OBJ when no start converged). */
double cf_tail_cell_search(const cf_tail_cell *tc, const cf_ident *start, const double lb[3],
                           const double ub[3], double zb[3]);

/* The quantities v = (rho, B, A, tau) at z and the scale A. */
void cf_tail_cell_quantities(const double z[3], double A, double v[4]);

/* The weighted residuals of the problem at v = (rho, B, A, tau) (tail.h, cf_tail_residuals;
** ctx a cf_tail_cell). */
int cf_tail_cell_residuals(void *ctx, const double v[4], gsl_vector *f);

/* The profile intervals of the tailed fit res at v = (rho, B, A, tau) where its errors say
** nothing (tail.h, cf_tail_intervals), profiled on tc's rows (a long table's subsample, or the
** problem itself) within the search box lb, ub, against the threshold of the whole problem's
** rows, weighted RSS at v and ynorm. 0, or -1 when memory ran out. */
int cf_tail_cell_intervals(const cf_tail_cell *tc, const cf_fit_options *opt,
                           cf_spring_type type, double need, const double lb[3],
                           const double ub[3], size_t rows, double rss, double ynorm,
                           const double v[4], cf_fit_result *res);

/* The flags of the box bounds zb sits on (the ones cf_tail_result does not see). */
unsigned cf_tail_cell_held(const cf_fit_options *opt, const double lb[3], const double ub[3],
                           const double zb[3], cf_spring_type type);

#endif
