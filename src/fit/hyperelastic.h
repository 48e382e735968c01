/*
** The nominal stress of two standard laws of an incompressible solid, in the homogeneous
** deformation of each test mode of a stress-strain table (cell.h; x is the table's engineering
** strain, or the amount of shear; stretch lambda = 1 + x):
**   uniaxial     F = diag(lambda, lambda^-1/2, lambda^-1/2)    I1 = lambda^2 + 2/lambda
**   planar       F = diag(lambda, 1, 1/lambda) (pure shear)    I1 = lambda^2 + 1 + lambda^-2
**   equibiaxial  F = diag(lambda, lambda, lambda^-2)           I1 = 2 lambda^2 + lambda^-4
**   shear        simple shear of amount x                      I1 = 3 + x^2
** Yeoh (Yeoh 1993), W = C1 (I1 - 3) + C2 (I1 - 3)^2 + C3 (I1 - 3)^3, gives P = s W'(I1) with
** s = 2 (lambda - lambda^-2), 2 (lambda - lambda^-3), 2 (lambda - lambda^-5) and 2 x; linear in
** the C_i. Ogden with one term (Ogden 1972), W = (2 mu / alpha^2) sum_j (l_j^alpha - 1), gives
**   uniaxial     P = (2 mu / alpha) (lambda^(alpha - 1) - lambda^(-alpha/2 - 1))
**   planar       P = (2 mu / alpha) (lambda^(alpha - 1) - lambda^(-alpha - 1))
**   equibiaxial  P = (2 mu / alpha) (lambda^(alpha - 1) - lambda^(-2 alpha - 1))
**   shear        P = (2 mu / alpha) sinh(alpha a) / cosh(a),  a = asinh(x/2) the log of the
**                principal stretch;
** linear in mu for a fixed alpha. In planar and simple shear the stress is even in alpha (the
** sign of alpha is not seen: a fit reports it positive). In every mode mu is the shear modulus at zero strain, and so is
** 2 C1. Every form is written without cancellation at small strain (I1 - 3 factored, expm1).
** Confined compression holds the lateral stretches, which an incompressible solid cannot follow:
** neither law has a form there. Private to the library.
*/
#ifndef CF_FIT_HYPERELASTIC_H
#define CF_FIT_HYPERELASTIC_H

#include "model/cell.h"
#include "io/measure.h"

/* NULL when both laws have a form for every row of t; else why not, as a sentence (a
** force-displacement table, confined compression, a stretch <= 0, no strained row). */
const char *cf_hyper_unfit(const cf_table *t);

/* 1 when x lies in the domain of mode m's form (a positive stretch; any amount of shear). */
int cf_hyper_in_domain(cf_mode m, double x);

/* Yeoh's stress per unit C1, C2, C3 at x in mode m: P = C1 g[0] + C2 g[1] + C3 g[2]. */
void cf_yeoh_basis(cf_mode m, double x, double g[3]);

/* The log of the stretch that loads the specimen at x (log1p(x); asinh(x/2) in shear): the
** variable of Ogden's forms below. */
double cf_ogden_log_stretch(cf_mode m, double x);

/* Ogden's stress per unit mu at log stretch L (cf_ogden_log_stretch) in mode m, for exponent
** alpha (its limit at alpha = 0). Inf or NaN where the power overflows. */
double cf_ogden_basis(cf_mode m, double L, double alpha);

#endif
