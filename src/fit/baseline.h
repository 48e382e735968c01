/*
** Baseline models fitted beside the conical spring, so that a user sees when the conical law is
** the better model and when it is not: a linear spring (y = E x), a Duffing spring
** (y = k1 x + k3 x^3, the nonlinear mass-spring law the paper compares against), Fung's
** exponential (y = A (exp(B x) - 1)), and two standard hyperelastic laws of an incompressible
** solid: Yeoh's (Yeoh 1993, Rubber Chem. Technol. 66:754-771), W = sum_{i=1..3} C_i (I1 - 3)^i,
** and Ogden's with one term (Ogden 1972, Proc. R. Soc. Lond. A 326:565-584),
** W = (2 mu / alpha^2) (l1^alpha + l2^alpha + l3^alpha - 3). The first three are curves in x;
** Yeoh and Ogden are material laws, fitted in the nominal stress of the table's test mode
** (hyperelastic.h: uniaxial, simple shear, planar, equibiaxial), so that their coefficients mean
** the same on every table. Each is an unweighted least-squares fit; each reports its RMSE and
** AIC = n ln(RSS/n) + 2k, with k its number of parameters (3 for the conical law).
*/
#ifndef CF_BASELINE_H
#define CF_BASELINE_H

#include "model/cell.h"
#include "fit/fit.h"

typedef enum cf_baseline_kind {
    CF_BASE_LINEAR = 0,
    CF_BASE_DUFFING = 1,
    CF_BASE_FUNG = 2,
    CF_BASE_YEOH = 3,
    CF_BASE_OGDEN = 4,
    CF_BASE_COUNT = 5
} cf_baseline_kind;

typedef struct cf_baseline {
    cf_baseline_kind kind;
    int k;           /* number of parameters */
    int fitted;      /* 1: fitted; 0: the law has no form for this table (why says why) */
    const char *why; /* NULL when fitted, else a sentence (static storage) */
    cf_mode form;    /* Yeoh, Ogden: the test mode whose incompressible form was fitted */
    double coef[3];  /* linear: E; Duffing: k1, k3; Fung: A, B; Yeoh: C1, C2, C3; Ogden: mu,
                        alpha (y and the coefficients E, k1, k3, A, C_i, mu in the data's unit of
                        the fit, MPa or N; x: strain or mm; B per unit x; alpha dimensionless) */
    double rss;      /* sum of squared residuals, (MPa or N)^2; NaN when not fitted */
    double rmse;     /* MPa or N; NaN when not fitted */
    double aic;      /* dimensionless (with RSS in MPa^2 or N^2); NaN when not fitted */
} cf_baseline;

/* Fits all baselines to the table (weights ignored: the comparison is on plain residuals). A
** baseline the table has no form for (Yeoh and Ogden on a force-displacement table, in confined
** compression, at a stretch <= 0, or when it does not determine their coefficients) is left
** unfitted with its reason; that is not an error. CF_E_INTERNAL when an allocation fails (out is
** then incomplete). */
cf_status cf_baseline_fit_all(const cf_table *data, cf_baseline out[CF_BASE_COUNT], cf_error *err);

/* Value of a fitted baseline at x (NaN outside its law's domain, or when not fitted). */
double cf_baseline_eval(const cf_baseline *b, double x);

/* "linear", "duffing", "fung", "yeoh", "ogden". */
const char *cf_baseline_name(cf_baseline_kind kind);

/* The law as a formula in x and y, for reports: "y = E x", ..., the Yeoh and Ogden ones in the
** form of test mode m. */
const char *cf_baseline_formula(cf_baseline_kind kind, cf_mode m);

/* AIC of a model with k parameters and residual sum of squares rss over n points. A zero RSS is
** floored at rounding level, n (DBL_EPSILON ymax)^2, so that the value stays finite. */
double cf_baseline_aic(size_t n, double rss, int k, double ymax);

#endif
