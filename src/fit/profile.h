/*
** Profile-likelihood intervals of the three identifiable quantities, over any residual function:
** the ordinary fit (fit_uncertainty.c) and the fits through the lattice (lattice_fit.c, joint.c)
** give their own profile, the interval's rules are here. Private to the library.
*/
#ifndef CF_FIT_PROFILE_H
#define CF_FIT_PROFILE_H

#include <stddef.h>

#include "fit/fit.h"

/* A fit's profile. The other two quantities of a profile of k travel in x: (log rho, B)
** without the one profiled (both when k is the stress scale), or, where start is given, what
** start puts there (at most CF_PROFILE_X values: the tailed law's four quantities). */
#define CF_PROFILE_X CF_Q_MAX
typedef struct cf_profile {
    void *ctx;
    double lo[CF_PROFILE_X], hi[CF_PROFILE_X]; /* range of each quantity, log units */
    /* CF_C_* bit of the limit at each end of that range */
    unsigned lo_bit[CF_PROFILE_X], hi_bit[CF_PROFILE_X];
    /* the weighted RSS minimised over the other quantities with quantity k at exp(u), from x;
    ** x moves to the minimiser when that RSS is within limit */
    double (*at)(void *ctx, int k, double u, double limit, double *x);
    /* the CF_C_* bit of the limit that closes where the profile of k has no admissible point */
    unsigned (*closed)(void *ctx, int k, double u, const double *x);
    /* with_rss0 = 1: rss0 is the RSS at the fitted value, and the ends are searched on the
    ** square root of the profile's rise above it (nearly linear in u), not on the RSS itself */
    int with_rss0;
    double rss0;
    /* NULL, or the start x of a profile of k from the fitted quantities v (a fit whose other
    ** quantities are not (log rho, B): the tailed law's) */
    void (*start)(void *ctx, int k, const double *v, double *x);
} cf_profile;

/* The weighted RSS a profile may reach: rss plus F(0.95; 1, n - 3) times the residual variance
** (floored at rounding level of ynorm, the data's weighted sum of squares). */
double cf_profile_limit(size_t n, double rss, double ynorm);

/* The same for a law of np quantities: F(0.95; 1, n - np) (the tailed law has four). */
double cf_profile_limit_np(size_t n, int np, double rss, double ynorm);

/* The profile interval of quantity k of v (v holds every quantity the profile's at reads) into
** out[2], with the CF_C_* bit of the limit each end reached (0: the threshold) in end[2]; se is
** its standard error (<= 0: none), which sets the first step. cf_profile_intervals runs it for
** each of the three quantities of a fit. */
void cf_profile_interval(const cf_profile *p, int k, const double *v, double limit, double se,
                         double out[2], unsigned end[2]);

/* The profile interval of every quantity of v into res (interval, interval_end, interval_ok;
** interval_why = why), each end searched outward from v in log steps that start at half the
** standard error (res->ident_se) or 1 % and double, then bisected. */
void cf_profile_intervals(const cf_profile *p, const double v[3], double limit, unsigned why,
                          cf_fit_result *res);

/* Whether the intervals are needed: a quantity without a standard error, held on a limit
** (why != 0), or whose Wald interval crosses the range [lo, hi] (linear units). */
int cf_profile_needed(const cf_fit_result *res, const double lo[3], const double hi[3],
                      unsigned why);

/* Puts the correlation of the cone's three quantities (cf_lsq_covariance's) in res->corr. */
void cf_fit_corr3(cf_fit_result *res, double corr[3][3]);

#endif
