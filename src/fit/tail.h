/*
** The conical-tail law's pieces that its fit to the spring (fit_tail.c) and its fit through the
** lattice (lattice_tail.c) share: the standard errors of the four identifiable quantities
** (rho, B = s/H, A = F_C/H^2, tau = n_t/n) from a residual function, the largest load scale a
** buildable tailed spring carries, and the closed-form placement that turns the quantities into
** a spring and fills a fit result. Private to the library.
*/
#ifndef CF_FIT_TAIL_H
#define CF_FIT_TAIL_H

#include <stddef.h>

#include <gsl/gsl_vector.h>

#include "conifit/fit.h"

/* Weighted residuals of n rows at the quantities v = (rho, B, A, tau) into f; GSL_SUCCESS, or
** GSL_EDOM where the model cannot be evaluated there. */
typedef int (*cf_tail_residuals)(void *ctx, const double v[4], gsl_vector *f);

/* Standard errors of v = (rho, B, A, tau) from the central-difference Jacobian (relative step
** h_rel) of res's n residuals: s^2 (J^T J)^-1 with s^2 = rss/(n - 4); se[k] = -1 where J^T J is singular; corr
** their correlation (NAN where not determined), *cov_Bt the covariance of B and tau. */
void cf_tail_errors(cf_tail_residuals res, void *ctx, size_t n, const double v[4], double h_rel,
                    double rss, double se[4], double corr[4][4], double *cov_Bt);

/* The largest stress scale F_C/H^2 a tailed spring of the type at (rho, B, tau) carries with
** G <= G_max, its whole travel past the strain need (a stress-strain table's largest strain with
** the margin); a tiny positive number where no spring is placed. */
double cf_tail_A_max(double rho, double B, double tau, cf_spring_type type, double need,
                     const cf_fit_options *o);

/* Fills res from the quantities v = (rho, B, A, tau) of table data (B and A in the table's kind,
** mm and N for a force table) and their errors: the identifiable quantities and e_t = tau B with
** its error, the tailed spring placed in closed form, its quality against data by its own law,
** its feasibility and the limits that hold the quantities (G_max, rho_min, the type). The
** evaluations, optimiser and time are the caller's. CF_E_INTERNAL when the placed spring has no
** law. */
cf_status cf_tail_result(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                         const double v[4], const double se[4], double corr[4][4], double cov_Bt,
                         cf_fit_result *res, cf_error *err);

#endif
