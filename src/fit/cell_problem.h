/*
** A fit through the lattice as a least-squares problem in the identifiable quantities: the
** target's curve at unit stress scale for (rho, s/H), the measured values and their weights. The
** fit through the lattice (lattice_fit.c) and the joint fit (joint.c) search it; its standard
** errors, correlation and profile intervals come from the same code as the ordinary fit's
** (lsq.h cf_lsq_covariance, profile.h). Private to the library.
*/
#ifndef CF_FIT_CELL_PROBLEM_H
#define CF_FIT_CELL_PROBLEM_H

#include <stddef.h>

#include <nlopt.h>

#include "fit/fit.h"

typedef struct cf_cell_problem {
    /* the target's curve at stress scale 1 for rho and s/H = B: n values into out (the rows of
    ** every table, in order); nonzero when it cannot be computed */
    int (*curve)(void *ctx, double rho, double B, double *out);
    /* NULL for the conical law's family (its design limits, cf_fit_ident_limit); else the
    ** largest stress scale at (rho, B) that a spring of the searched family carries, <= 0 where
    ** none is placed (the conical-tail law's, its tail read from ctx) */
    double (*A_max)(void *ctx, double rho, double B);
    void *ctx;
    size_t n;                  /* rows */
    const double *y;           /* measured values, n, MPa */
    const double *sw;          /* residual weights, n */
    double ynorm;              /* sum (sw y)^2 */
    const cf_fit_options *opt; /* the design limits */
    cf_spring_type type;
    double lb[2], ub[2];       /* the search box of (log rho, s/H) */
    double *g;                 /* scratch of n values */
    double A_fixed;            /* > 0: the stress scale held there (a profile); else solved */
    long evals;                /* curves computed */
    int oom;                   /* 1: an optimiser (NLopt) ran out of memory */
} cf_cell_problem;

/* Sets p up for table d: its rows, values, residual weights (lsq.h) and scratch, with the curve,
** A_max (may be NULL) and ctx given; the rest zero. CF_E_INTERNAL when memory runs out (then
** cf_cell_problem_free is still safe). */
cf_status cf_cell_problem_init(cf_cell_problem *p, const cf_table *d, const cf_fit_options *opt,
                               cf_spring_type type,
                               int (*curve)(void *ctx, double rho, double B, double *out),
                               double (*A_max)(void *ctx, double rho, double B), void *ctx,
                               cf_error *err);
void cf_cell_problem_free(cf_cell_problem *p);

/* The weighted RSS at (rho, B), the stress scale in closed form (weighted linear least squares,
** capped at the largest scale the type carries there, or p->A_max's) or p->A_fixed; *A_out receives it.
** CF_LSQ_HUGE_OBJ where no spring of the type can be placed or the curve cannot be computed. */
double cf_cell_rss(cf_cell_problem *p, double rho, double B, double *A_out);

/* One local search of the problem's space: NLopt's alg over n variables z (in and out) within
** [lb, ub] from the initial steps step, to relative step xtol or maxeval curves, minimising f
** (data its argument). Returns NLopt's result (*fz the value at z); running out of memory
** anywhere (creating the optimiser, setting it up, in the search) sets p->oom and returns
** NLOPT_OUT_OF_MEMORY. */
nlopt_result cf_cell_search(cf_cell_problem *p, nlopt_algorithm alg, unsigned n, const double *lb,
                            const double *ub, const double *step, double xtol, int maxeval,
                            nlopt_func f, void *data, double *z, double *fz);

/* The uncertainty of res->ident (the quantities the search found): standard errors and the
** correlation from a central-difference Jacobian of the curve (5 curves), held (the search box
** and the stress scale's cap), and profile intervals where the rules of profile.h ask for them,
** searched on prof (p itself, or a subsample's problem for a long table). CF_E_INTERNAL when
** memory runs out (here or in a profile's optimiser), else CF_OK. */
cf_status cf_cell_uncertainty(cf_cell_problem *p, cf_cell_problem *prof, cf_fit_result *res,
                              cf_error *err);

#endif
