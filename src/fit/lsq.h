/*
** Residuals, as the fitter (fit*.c), the baselines, the viscoelastic fit and the fits through the
** lattice (lattice_fit.c, joint.c) share them: the residual weights and their floor, the quality
** of a model's values against a table, and the F-test on residual sums of squares. Private to
** the library.
*/
#ifndef CF_FIT_LSQ_H
#define CF_FIT_LSQ_H

#include <stddef.h>

#include "model/law_internal.h"
#include "io/measure.h"

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

/* Standard errors s^2 (J^T W J)^-1 of three fitted quantities from jtj = J^T W J (J: the
** model's derivatives in them at the solution) and the weighted RSS of n points, s^2 = RSS/(n - 3),
** and their correlation matrix (NAN where not determined; errors -1). Returns 1 when J^T W J is
** numerically singular (smallest eigenvalue of its unit-diagonal form below 1e-10 of the
** largest) or n <= 3, -1 when memory runs out, else 0. Every fit's errors come from here. */
int cf_lsq_covariance(double jtj[3][3], double rss, size_t n, double se[3],
                      double corr[3][3]);

/* Largest |x| of the table. */
double cf_lsq_xmax(const cf_table *t);

#endif
