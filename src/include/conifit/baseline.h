/*
** Baseline models fitted beside the conical spring, so that a user sees when the conical law is
** the better model and when it is not: a linear spring (y = E x), a Duffing spring
** (y = k1 x + k3 x^3, the nonlinear mass-spring law the paper compares against) and Fung's
** exponential (y = A (exp(B x) - 1)). Each is an unweighted least-squares fit; each reports its
** RMSE and AIC = n ln(RSS/n) + 2k, with k its number of parameters (3 for the conical law).
*/
#ifndef CF_BASELINE_H
#define CF_BASELINE_H

#include "conifit/fit.h"

typedef enum cf_baseline_kind {
    CF_BASE_LINEAR = 0,
    CF_BASE_DUFFING = 1,
    CF_BASE_FUNG = 2,
    CF_BASE_COUNT = 3
} cf_baseline_kind;

typedef struct cf_baseline {
    cf_baseline_kind kind;
    int k;           /* number of parameters */
    double coef[2];  /* linear: E; Duffing: k1, k3; Fung: A, B (y in the data's own unit of the
                        fit: MPa or N; x: strain or mm) */
    double rss;      /* sum of squared residuals, (MPa or N)^2 */
    double rmse;     /* MPa or N */
    double aic;      /* dimensionless (with RSS in MPa^2 or N^2) */
} cf_baseline;

/* Fits all baselines to the table (weights ignored: the comparison is on plain residuals).
** CF_E_INTERNAL when an allocation of GSL fails (out is then incomplete). */
cf_status cf_baseline_fit_all(const cf_table *data, cf_baseline out[CF_BASE_COUNT], cf_error *err);

/* Value of a fitted baseline at x. */
double cf_baseline_eval(const cf_baseline *b, double x);

/* "linear", "duffing", "fung". */
const char *cf_baseline_name(cf_baseline_kind kind);

/* AIC of a model with k parameters and residual sum of squares rss over n points. A zero RSS is
** floored at rounding level, n (DBL_EPSILON ymax)^2, so that the value stays finite. */
double cf_baseline_aic(size_t n, double rss, int k, double ymax);

#endif
