/*
** Fitting the time-dependent model (viscomodel.h) to a measured time series: the conical law for
** the elastic, instantaneous response (its three identifiable quantities rho, s/H, F_C/H^2) and a
** Prony series of N Maxwell branches on every spring (g_i >= 0, sum g_i < 1, tau_i > 0), with
** optionally a dashpot, fitted jointly to the stress along the measured strain history.
**
** How it fits:
**   A. a global search on a cheap stand-in: the static lattice curve at unit stress scale on a
**      grid of (rho, s/H), run through the Prony recursion at the measured times for every set
**      of N time constants from a logarithmic grid spanning the series; for fixed rho, s/H and
**      tau the stand-in is linear in the stress scale and in the g_i, which are solved by least
**      squares (candidates that break g_i >= 0 or sum g_i < 1 are dropped);
**   B. Levenberg-Marquardt (GSL, finite-difference Jacobian) on the model itself (the lattice
**      driven by the measured history, with its exact recursive Prony update), from the best
**      starts of A, in coordinates that keep every constraint (logit for rho and s/H inside
**      their bounds, log tau, g_i = e^a_i / (1 + sum e^a_j)); the stress scale is solved in
**      closed form at every evaluation (the stress is proportional to it, the dashpot being
**      taken relative to it);
**   C. standard errors from s^2 (J^T W J)^-1 with J the central-difference Jacobian of the model
**      in the reported quantities (rho, s/H, F_C/H^2, g_i, tau_i, eta).
** With nbranch = 0, N = 1..4 are fitted and the lowest AIC (n ln(RSS/n) + 2k) is kept.
** Deterministic: no random numbers. Thread-safe: no globals.
*/
#ifndef CF_VISCOFIT_H
#define CF_VISCOFIT_H

#include <stddef.h>

#include "conifit/error.h"
#include "fit/fit.h"
#include "model/viscomodel.h"

/* Branch counts tried when the choice is left to AIC. */
#define CF_VISCO_AIC_MAX 4
/* The default bound on the model runs of one fit (cf_visco_fit_options.max_evaluations): well
** above what the default choice takes on the published series. */
#define CF_VISCO_EVAL_MAX 200000L

/* How the relative moduli may depend on strain (viscomodel.h k). */
typedef enum cf_visco_relaxation {
    CF_RELAX_QLV = 0,    /* quasi-linear: k_i = 0 (the library's default; the command's is auto) */
    CF_RELAX_STRAIN = 1, /* g_i + k_i |strain|, linear in |strain| between the moduli at zero and
                         ** at the series' largest strain, both fitted (each >= 0, sums < 1) */
    CF_RELAX_AUTO = 2    /* both fitted; kept: determined terms first, then the lower AIC */
} cf_visco_relaxation;

typedef struct cf_visco_fit_options {
    int nbranch;            /* 1..CF_PRONY_MAX, or 0: choose 1..CF_VISCO_AIC_MAX by AIC */
    int dashpot;            /* 1: fit a dashpot beside the springs as well */
    cf_visco_relaxation relaxation; /* quasi-linear (the zero value), depending on strain, or
                                    ** both with the choice (the command's default) */
    int hold_elastic;       /* 1: rho, s/H, F_C/H^2 held at elastic[] (an earlier fit) */
    cf_ident elastic;       /* rho [-], s/H [-], F_C/H^2 [MPa] (family.h) */
    double elastic_e_tail;  /* with hold_elastic: the held spring's tail compliance F_C/(k_t H)
                            ** (viscomodel.h e_tail), - ; 0: no tail. Only held: a fitted
                            ** elastic part is the conical law (CF_E_DATA otherwise) */
    int relative;           /* 1: residuals relative to |stress| (floor 1e-3 max|stress|) */
    double rho_min;         /* smallest rho fitted (default the fitter's, 0.05) */
    /* Design limits (fit.h): when not NULL, rho, s/H and F_C/H^2 stay where a spring of one of
    ** the types in limit_types (bits 1 << CF_TELESCOPING, 1 << CF_NON_TELESCOPING) can be
    ** placed within them (cf_fit_ident_limit): the stress scale is capped at the largest such a
    ** spring carries. NULL: no cap (the spring may then be one no one could build). */
    const cf_fit_options *limits;
    unsigned limit_types;
    /* Stability: when > 0, the static lattice of stable_cells^3 cells (the weights of setup)
    ** built from the fitted spring must stay stable (no negative pivot of its tangent) up to
    ** the series' largest strain, so that every lattice `simulate` runs of it follows the fit
    ** (the one-cell lattice loses stability first: 1 is the default and the safe choice). A
    ** held spring (hold_elastic) is checked alike: CF_E_DATA when its lattice is not stable
    ** there. */
    int stable_cells;
    cf_visco_setup setup;   /* where the model is evaluated */
    /* Bound on the model runs (0: CF_VISCO_EVAL_MAX). Once reached, no further start or
    ** candidate is fitted: the best model so far is kept and evaluation_bound_reached set. A
    ** search under way finishes first, so the count may pass the bound by one start's runs. */
    long max_evaluations;
    /* 1: the Levenberg-Marquardt's Jacobian by forward differences at every step (one model run
    ** per parameter each). 0 (the default): by differences every few steps and after a refused
    ** trial, carried by Broyden's update in between; the same optimum for a fraction of the
    ** model runs. */
    int full_jacobian;
    /* 1: the stand-in's least squares (the starts of the Levenberg-Marquardt) on every point of
    ** the series. 0 (the default): in the space of the QR factor of each grid point's base
    ** (its elastic curve and responses, a few dozen columns), the same solutions to rounding at
    ** a fraction of the cost on a long series. */
    int full_standin;
} cf_visco_fit_options;

cf_visco_fit_options cf_visco_fit_default_options(void);

/* The measured series in conifit's units: time [s], strain [-] and stress [MPa], tension
** positive (compression negative, as in the published relaxation tables). w may be NULL. */
typedef struct cf_visco_data {
    size_t count;
    const double *t_s;
    const double *x;
    const double *y;
    const double *w;
} cf_visco_data;

/* Checks that the series can be fitted: at least 6 points, finite values, time strictly
** increasing, some change of strain, and a hold (an interval of constant nonzero strain) or a
** reversal of the strain (cycles). CF_E_DATA with a message naming the point otherwise.
** is_hold (may be NULL; count values) receives 1 for a point that ends an interval of constant
** strain (the hold), 0 for the others (the ramps). */
cf_status cf_visco_data_check(const cf_visco_data *d, unsigned char *is_hold, cf_error *err);

/* The predicted response of the fitted tissue to two stated loads. */
typedef struct cf_visco_predict {
    int hysteresis_done;       /* 1 when computed; else note says why not */
    double cycle_strain;       /* strain amplitude of the load-unload cycle, table's sign, - */
    double cycle_period_s;     /* its period (load and unload at the series' ramp rate), s */
    double loop_area_MPa;      /* energy dissipated in the cycle per unit volume, MPa = MJ/m^3 */
    double loading_work_MPa;   /* work done on loading, MPa */
    int creep_done;            /* 1 when computed */
    double creep_stress_MPa;   /* held stress, table's sign (the series' final stress), MPa */
    double creep_ramp_s;       /* time to apply it, s */
    double creep_hold_s;       /* time held, s */
    double creep_strain_ramp;  /* strain at the end of the ramp, table's sign */
    double creep_strain_end;   /* strain at the end of the hold, table's sign */
    char note[CF_ERROR_MSG_LEN];
} cf_visco_predict;

/* One candidate of the choice by AIC: among candidates, those whose time-dependent quantities
** the data determine come first, then the lower AIC. */
typedef struct cf_visco_candidate {
    int fitted;            /* 0: not fitted (N not tried, or no model could be evaluated) */
    double aic;            /* n ln(RSS/n) + 2k, RSS in MPa^2 */
    int identified;        /* 1 when the series determines its time-dependent quantities (see
                              cf_visco_fit.identified) */
    int strain_terms;      /* terms whose relative modulus changes with strain (fitted k_i) */
    unsigned elastic_unresolved; /* bit CF_IDENT_* set for a fitted elastic quantity whose
                                    standard error is larger than its range (rho, s/H: 1; the
                                    stress scale: itself): the candidate is then not determined */
} cf_visco_candidate;

typedef struct cf_visco_fit {
    cf_visco_params p;                  /* the fitted model (stress scale in MPa, eta in MPa s) */
    cf_ident ident_se;                  /* standard errors of rho, s/H, F_C/H^2; -1: not
                                           determined (or held) */
    double se_g[CF_PRONY_MAX];          /* standard errors of g_i, -1 when not determined */
    double se_tau_s[CF_PRONY_MAX];      /* of tau_i, s */
    double se_eta_MPa_s;                /* of the dashpot, MPa s (-1 without one) */
    double se_k[CF_PRONY_MAX];          /* of k_i (relaxation growing with strain), -1 when not
                                           fitted or not determined */
    double se_g_max[CF_PRONY_MAX];      /* of g_i + k_i x_max, the relative modulus at the
                                           series' largest strain x_max (se_g[i] for a term
                                           constant in strain), -1 when not determined */
    int strain_relaxation;              /* 1 when k_i were fitted */
    unsigned strain_mask;               /* bit i set when term i's k_i was fitted (with
                                           strain_relaxation; the others' are held at 0) */
    int dashpot;                        /* 1 when a dashpot was fitted */
    int held_elastic;                   /* 1 when the elastic quantities were held */
    int rho_at_limit;                   /* 1 when rho sits on its lower limit (rho_min): set by
                                           the limit, its standard error undetermined */
    int at_stability_limit;             /* 1 when s/H sits on the smallest value that keeps the
                                           lattice stable over the series */
    int at_design_limit;                /* 1 when F_C/H^2 sits on the largest value a spring
                                           within the design limits carries */
    double stable_to_strain;            /* where the elastic lattice of stable_cells^3 cells of
                                           the fitted or held spring loses stability, table's
                                           sign;
                                           0 when stable to 0.995 of solid or not checked */
    int chosen_by_aic;                  /* 1 when N or the relaxation was chosen by AIC */
    int identified;                     /* 1 when the data determine every time-dependent
                                           quantity of the model: each tau_i, each term's
                                           modulus at the largest strain, each fitted k_i and
                                           the dashpot is larger than its standard error,
                                           and no fitted elastic quantity has an error larger
                                           than its range (elastic_unresolved) */
    unsigned elastic_unresolved;        /* the kept candidate's elastic quantities that fail
                                           (cf_visco_candidate) */
    cf_visco_candidate by_n[CF_VISCO_AIC_MAX][2]; /* when chosen by AIC: the candidates of
                                                     N = 1..4 terms, quasi-linear [0] and
                                                     depending on strain [1] */
    size_t count, n_ramp, n_hold;       /* points in all, on ramps, in holds */
    double rss;                         /* unweighted sum of squared residuals, MPa^2 */
    double rmse, rmse_ramp, rmse_hold;  /* MPa; rmse_ramp/hold are -1 with no such point */
    double max_abs_error;               /* MPa */
    double r2;                          /* coefficient of determination, - */
    double aic;                         /* n ln(RSS/n) + 2k, RSS in MPa^2 */
    int k;                              /* fitted parameters */
    double x_max;                       /* the series' largest |strain|, - */
    double E_inst_MPa;                  /* small-strain instantaneous modulus of the lattice, MPa */
    double E_eq_MPa;                    /* small-strain equilibrium modulus, g_inf E_inst, MPa */
    double *model_MPa;                  /* the model at every point (owned), MPa */
    unsigned char *is_hold;             /* 1 for a point of a hold (owned) */
    cf_visco_predict pred;
    long evaluations;                   /* model curves computed */
    int evaluation_bound_reached;       /* 1 when the fit stopped at its bound on model runs
                                           (options.max_evaluations) with candidates or starts
                                           left unfitted */
    double wall_time_s;
} cf_visco_fit;

/* Fits the series. CF_E_DATA for a series cf_visco_data_check refuses or impossible options
** (message names them), CF_E_NOCONV when no start could be evaluated, CF_E_INTERNAL when memory
** runs out. res->model_MPa and res->is_hold are allocated; free with cf_visco_fit_free. */
cf_status cf_visco_fit_run(const cf_visco_data *d, const cf_visco_fit_options *o,
                           cf_visco_fit *res, cf_error *err);

void cf_visco_fit_free(cf_visco_fit *r);

/* The predicted hysteresis loop and creep of a fitted model for the series d (see
** cf_visco_predict); called by cf_visco_fit_run. */
void cf_visco_predictions(const cf_visco_params *p, const cf_visco_setup *s,
                          const cf_visco_data *d, cf_visco_predict *out);

#endif
