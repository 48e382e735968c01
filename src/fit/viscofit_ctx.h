/*
** The viscoelastic fit's working state and what its parts share (viscofit.c and the viscofit_*.c
** files). Private to the fit layer.
*/
#ifndef CF_FIT_VISCOFIT_CTX_H
#define CF_FIT_VISCOFIT_CTX_H

#include <stddef.h>

#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include "fit/viscofit.h"
#include "fit/viscolimits.h"

/* Bounds of rho and of the solid strain (the largest strain must stay CF_FIT_TRAVEL_MARGIN
** short of solid, as in the elastic fit). */
#define RHO_HI (1 - 1e-6)
#define E_HI 0.999
/* Relative residual floor (--relative), as in the elastic fit. */
#define REL_FLOOR 1e-3
/* Grid of the stand-in search: rho, s/H, time constants. */
#define GRID_RHO 9
#define GRID_E 9
#define GRID_TAU 12
/* Starts of the Levenberg-Marquardt stage per branch count, and its limits. */
#define LM_STARTS 2
#define LM_STARTS_STRAIN 6
#define LM_MAX_ITER 150
#define LM_STALL 6
#define LM_STALL_REL 1e-10
#define LM_FLOOR_REL 1e-28
/* g_i = e^a_i / (1 + sum e^a_j): a_i is kept above this (g_i ~ 1e-13, a branch switched off). */
#define A_LO -30.0
/* Accepted steps of the Levenberg-Marquardt between two Jacobians by finite differences: in
** between, Broyden's rank-one update from the step taken (options.full_jacobian: every step). */
#define LM_JAC_REUSE 4
/* A start of the Levenberg-Marquardt that has to beat an earlier start's sum of squares S is
** abandoned once it is above LM_BEAT_FACTOR S and fell by less than LM_BEAT_REL of itself over
** LM_BEAT_ITER iterations (cf_lm_stop.ceiling): it is converging to an optimum that loses. */
#define LM_BEAT_FACTOR 2.0
#define LM_BEAT_ITER 3
#define LM_BEAT_REL 1e-3
/* Relative step of the central differences for the standard errors. */
#define SE_STEP 1e-5

typedef struct ctx {
    const cf_visco_data *d;
    const cf_visco_fit_options *o;
    size_t n;
    int nb;             /* branches */
    int free_el;        /* 1: rho and s/H are fitted (and the scale profiled) */
    int dash;           /* 1: dashpot fitted */
    int gs;             /* 1: growth of the relative moduli with strain (k_i) fitted */
    unsigned smask;     /* with gs: bit i set when term i's k_i is fitted (else held at 0) */
    size_t np;          /* LM parameters */
    double *sw;         /* residual weights */
    double ynorm;       /* weighted sum of y^2 */
    double ymax, xmax;
    double xlo, xhi;    /* most compressive (<= 0) and most tensile (>= 0) strain */
    double e_lo;        /* lower bound of s/H (the travel margin; stability: see lim) */
    double rho_lo;      /* lower bound of rho (the fitter's rho_min) */
    cf_visco_limits lim;/* design cap of the scale and stability bound of s/H */
    double *m;          /* model curve scratch (n) */
    cf_visco_series series;
    long evals;
    struct lm_jac *jac; /* the Levenberg-Marquardt's Jacobian updates (viscofit_state.c) */
    long max_evals;     /* the bound on evals (options.max_evaluations or the default) */
    int bound_hit;      /* 1 once evals reached max_evals with work left */
    int oom;            /* 1 when an allocation failed in a solver or a model curve: the fit
                        ** ends with an error instead of going on without that start or point */
} ctx;

/* A start of the Levenberg-Marquardt: the model and its objective. */
typedef struct start {
    double obj;
    cf_visco_params p;
} start;

/* The functions one part calls in another, each documented at its definition, by file. */

/* viscofit_state.c */
double cf_viscofit_solid_lo(const ctx *c, double rho);
int cf_viscofit_strain_term(const ctx *c, int i);
int cf_viscofit_strain_terms(const ctx *c);
cf_visco_params cf_viscofit_unpack(const ctx *c, const double *z);
void cf_viscofit_pack(const ctx *c, const cf_visco_params *p, double *z);
int cf_viscofit_curve(ctx *c, const cf_visco_params *p);
double cf_viscofit_profile_scale(const ctx *c, double rho, double B);
double cf_viscofit_lm_run(ctx *c, double *z, double beat);

/* viscofit_jac.c */
struct lm_jac *cf_viscofit_jac_alloc(size_t n, size_t p, gsl_multifit_nlinear_fdf *fdf,
                                     double h_df);
void cf_viscofit_jac_free(struct lm_jac *j);
void cf_viscofit_jac_record(struct lm_jac *j, const double *x, const double *f);
int cf_viscofit_jac_df(const gsl_vector *x, void *data, gsl_matrix *J);

/* viscofit_standin.c */
int cf_viscofit_stand_in(ctx *c, start *best, int nbest);

/* viscofit_se.c */
void cf_viscofit_standard_errors(ctx *c, const cf_visco_params *p,
                                 const int held[CF_IDENT_COUNT], double s2, cf_visco_fit *res);

#endif
