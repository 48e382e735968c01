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

#include "fit/fit.h"

/* The range of tau = n_t/n the fits search. */
#define TAIL_TAU_LO 1e-4
#define TAIL_TAU_HI 1e3

/* The fits' fourth coordinate th3 and tau = n_t/n at length scale B: log tau for a force table;
** for a stress-strain table the strain at which the cone closes, u_C/H = B (1 + tau), as a logit
** between B and 1 (a spring's whole travel is below its free length, so u_C/H < 1).
** cf_tail_coord is cf_tail_tau's inverse. */
double cf_tail_tau(int fd, double B, double th3);

/* The largest tau = n_t/n a buildable tailed spring has: its tail's coils n_t = tau n are wound
** coils like the cone's, at most n_max, and the cone has at least n_min (cf_fit_options). */
double cf_tail_tau_max(const cf_fit_options *o);
double cf_tail_coord(int fd, double B, double tau);

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

/* The tailed law contains the conical law (tail compliance 0): a tailed fit tail that ends worse
** than the conical fit plain of the same table, type and target (infeasible where plain is
** feasible, or a larger objective at the same feasibility) is replaced by plain as a tailed fit
** with no tail (e_tail 0, n_tail 0: the law is plain's), the lost one's RMSE and violated bits in
** nested_rmse and nested_violated. Returns 1 when replaced. */
int cf_tail_nest(const cf_fit_result *plain, cf_fit_result *tail);

/* A tailed fit's residuals for its profile intervals: m weighted residuals (the table's rows, or
** a subsample of a long one each standing for its share of the table) at v = (rho, B, A, tau), the
** ranges the fit searched, and what the cap on A needs (a stress-strain table's A stays below
** cf_tail_A_max; a force table's A is free). */
typedef struct cf_tail_profile {
    cf_tail_residuals res;
    void *ctx;
    size_t m;
    double ynorm;            /* the data's weighted sum of squares, a scale */
    const cf_fit_options *opt;
    cf_spring_type type;
    int fd;                  /* 1: a force table */
    double need;             /* the table's largest strain with the travel margin */
    double rho_lo, rho_hi, b_lo, b_hi;
    /* Other optima of the fit (rho, B, A, tau), each within the threshold of the best: a profile
    ** point the search from the previous point leaves above the threshold is searched again from
    ** each (a flat valley of the law in several pieces that a local search does not join). */
    const double (*alt)[4];
    int nalt;
} cf_tail_profile;

/* The profile intervals of the four quantities (rho, B, A, e_t) of a tailed fit res (filled by
** cf_tail_result, its held bits included) into res->interval* and res->e_tail_interval*, where
** the plain law's rule asks for them: a quantity on a limit, a singular Jacobian, or a standard
** error that reaches past the quantity's range (the "not determined" of the tailed law's
** report). v = (rho, B, A, tau) is the fit; rss0 the weighted RSS of p's residuals there; limit the
** weighted RSS over p's residuals a profile may reach. Deterministic; 0, or -1 when memory ran
** out (the intervals are then not computed). */
int cf_tail_intervals(const cf_tail_profile *p, const double v[4], double rss0, double limit,
                      cf_fit_result *res);

/* One point of p's profile of quantity k (0 rho, 1 B, 2 A, 3 e_t) at `value`, searched as
** cf_tail_intervals searches it (rss0 and limit as there) from x = (rho, B, A, tau), which receives
** the point reached when its RSS is within limit: the weighted RSS minimised over the other
** three. */
double cf_tail_profile_point(const cf_tail_profile *p, int k, double value, double rss0,
                             double limit, double x[4]);

/* The profile of quantity k (0 rho, 1 B, 2 A, 3 e_t) of the tailed spring fit `fit` of table data
** (fitted from the plain fit `plain`, may be NULL, as cf_fit_tail_run was given it) at `value`: the
** weighted RSS of the profile's rows minimised over the other three from the fit and, where that
** ends above the threshold, from the fit search's other optima, as cf_tail_intervals finds it;
** *limit the threshold its intervals are drawn at. NAN when out of memory. For checking an
** interval's ends. */
double cf_tail_profile_at(const cf_table *data, const cf_fit_options *opt,
                          const cf_fit_result *plain, const cf_fit_result *fit, int k,
                          double value, double *limit);

#endif
