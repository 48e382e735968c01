/*
** Least-squares pieces shared by the fitter (fit.c), the baselines and the fits through the
** lattice (lattice_fit.c, joint.c), so that each is defined once: the residual weights and their
** floor, the quality measures, and the wire modulus
** that gives a spring its solid load. Private to the library.
*/
#ifndef CF_FIT_LSQ_H
#define CF_FIT_LSQ_H

#include <stddef.h>

#include "conifit/law.h"
#include "conifit/measure.h"

#include <gsl/gsl_multifit_nlinear.h>

/* Relative residuals divide by max(|y|, CF_LSQ_REL_FLOOR max|y|) so that the point at the origin
** (y = 0) keeps a finite weight. */
#define CF_LSQ_REL_FLOOR 1e-3
/* Objective value returned where the model cannot be evaluated (an invalid spring, a lattice
** that does not converge). */
#define CF_LSQ_HUGE_OBJ 1e30

/* Fills sw[i] = sqrt(w_i) / scale_i (scale 1, or the floored |y_i| when relative) for the count
** points of t and returns the weighted norm sum (sw_i y_i)^2. */
double cf_lsq_weights(const cf_table *t, int relative, double *sw);

/* Quality of a model's values against the table's y (unweighted). */
typedef struct cf_lsq_quality {
    double rss;           /* sum of squared residuals, (unit of y)^2 */
    double rmse;          /* sqrt(rss / count), unit of y */
    double max_abs_error; /* largest |model - y|, unit of y */
    double r2;            /* 1 - rss / sum (y - mean y)^2; 0 when y is constant */
} cf_lsq_quality;

cf_lsq_quality cf_lsq_quality_of(const cf_table *t, const double *model);

/* F(0.95; 1, dof), the 95 % quantile of the F distribution with 1 and dof degrees of freedom:
** GSL's inverse where it converges, else the square of Student's t(0.975; dof), which it equals
** (GSL 2.7's gsl_cdf_fdist_Pinv fails for some large dof, e.g. 4997 and 1e5, and returns NaN). */
double cf_lsq_f95(double dof);

/* Largest |x| of the table. */
double cf_lsq_xmax(const cf_table *t);

/* When GSL's Levenberg-Marquardt iterations stop: its own test (xtol, gtol, ftol), the iteration
** limit, and two more rules. An optimum on a bound of a logit coordinate lies at infinity, where
** the step test never fires: stop once the sum of squares has fallen by less than stall_rel of
** itself in `stall` iterations in a row, or once it is below `floor` (rounding level). */
typedef struct cf_lsq_lm_stop {
    int max_iter;
    double xtol, gtol, ftol;
    int stall;
    double stall_rel;
    double floor;
} cf_lsq_lm_stop;

/* Iterates an initialised workspace until a rule of stop fires or an iteration fails. Returns 0,
** or -1 when an iteration ran out of memory (the position is then the last good one). */
int cf_lsq_lm_iterate(gsl_multifit_nlinear_workspace *w, const cf_lsq_lm_stop *stop);

#endif
