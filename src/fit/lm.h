/*
** The Levenberg-Marquardt of the fits (GSL's trust-region solver): its set-up, its stopping rule,
** and the logit map that turns a bounded quantity into a free coordinate for it. Private to the
** fit layer.
*/
#ifndef CF_FIT_LM_H
#define CF_FIT_LM_H

#include <gsl/gsl_multifit_nlinear.h>

/* ln(p/(1 - p)), p clamped to [1e-15, 1 - 1e-15] so that a bound maps to a finite coordinate. */
double cf_logit(double p);

/* 1/(1 + exp(-t)), the inverse of cf_logit. */
double cf_logistic(double t);

/* GSL's default parameters with the Levenberg-Marquardt step and More's scaling of the
** parameters; a fit adjusts the rest (difference type, step) before cf_lm_start. */
gsl_multifit_nlinear_parameters cf_lm_parameters(void);

/* A workspace for fdf (its n residuals and p parameters) under fp, initialised at x0 (p values,
** read). NULL when it cannot be allocated; else *init receives the status of the initialisation
** (GSL_SUCCESS, GSL_ENOMEM, or the status of fdf's first evaluation). */
gsl_multifit_nlinear_workspace *cf_lm_start(const gsl_multifit_nlinear_parameters *fp,
                                            gsl_multifit_nlinear_fdf *fdf, double *x0,
                                            int *init);

/* When the iterations stop: GSL's own test (xtol, gtol, ftol), the iteration limit, and two more
** rules. An optimum on a bound of a logit coordinate lies at infinity, where the step test never
** fires: stop once the sum of squares has fallen by less than stall_rel of itself in `stall`
** iterations in a row, or once it is below `floor` (rounding level). A run that only has to beat
** another (one of several starts) also stops once its sum of squares is above `ceiling` (> 0) and
** has fallen by less than ceiling_rel of itself over the last ceiling_iter iterations (at most
** CF_LM_CEILING_ITER_MAX): it is settling into an optimum it cannot win with. Zero: no ceiling. */
#define CF_LM_CEILING_ITER_MAX 8
typedef struct cf_lm_stop {
    int max_iter;
    double xtol, gtol, ftol;
    int stall;
    double stall_rel;
    double floor;
    double ceiling;
    int ceiling_iter;
    double ceiling_rel;
    /* A run whose result is not kept where it lands outside limits that hold every spring (the
    ** caller then fits again under them) also stops once outside(x, outside_arg) is 1 at its
    ** position and its sum of squares has fallen by less than outside_rel of itself in
    ** outside_stall iterations in a row. NULL: no such rule. */
    int (*outside)(const gsl_vector *x, void *arg);
    void *outside_arg;
    double outside_rel;
    int outside_stall;
} cf_lm_stop;

/* Iterates an initialised workspace until a rule of stop fires or an iteration fails. Returns 0,
** or -1 when an iteration ran out of memory (the position is then the last good one). */
int cf_lm_iterate(gsl_multifit_nlinear_workspace *w, const cf_lm_stop *stop);

/* Levenberg-Marquardt with central differences on the n residuals f (GSL's signature, params
** its argument) of p parameters from x (moved to where the run ends), stopped by stop. Returns the
** sum of squares there; INFINITY when the workspace cannot start or its first evaluation fails
** (x unchanged) or when the sum at the end is not finite. */
double cf_lm_minimise(int (*f)(const gsl_vector *x, void *params, gsl_vector *r), void *params,
                      size_t n, size_t p, double *x, const cf_lm_stop *stop);

#endif
