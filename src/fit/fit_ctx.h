/*
** The working state of one fit and what its stages share (fit.c and the fit_*.c files of each
** stage). Private to the fit layer.
*/
#ifndef CF_FIT_FIT_CTX_H
#define CF_FIT_FIT_CTX_H

#include <stddef.h>

#include <gsl/gsl_rng.h>
#include <nlopt.h>

#include "model/family.h"
#include "fit/fit.h"

/* Constraint tolerances (constraints are in log units, i.e. relative): a constraint counts as
** violated beyond FEAS_TOL and active within ACTIVE_TOL of its limit. The optimisers see the
** constraints shifted by SAFETY so that their solutions land on the feasible side. */
#define FEAS_TOL 1e-9
#define ACTIVE_TOL 1e-6
#define SAFETY 1e-10
/* Grid of the global stage: GRID x GRID cells over (rho, length scale). */
#define GRID 28

/* Levenberg-Marquardt limits: iterations, and the stagnation rule (lm.h, cf_lm_stop). The floor
** is also the placement's stopping value (fit_placement.c). */
#define LM_MAX_ITER 300
#define LM_STALL 8
#define LM_STALL_REL 1e-9
/* ... and once the residual is at rounding level (relative residual norm 1e-13): on a noiseless
** table the sum of squares then only jitters, and no step can improve the fit. */
#define LM_FLOOR_REL 1e-26

/* Every fit's local searches stop at a statistical tolerance: once the objective falls by less
** than LONG_TOL of the residual variance s^2 = objective/(rows - 3) per step, LM_STALL_LONG steps
** in a row for Levenberg-Marquardt, one step for stage C's NLopt (not the constrained COBYLA of
** fit_limits.c, whose short steps near an active limit this would stop early: measured, 4.6 s^2
** short of the optimum on a 1e5-row table). A point whose objective lies within s^2 of the
** optimum lies within about one standard error of it; measured on the table 3e + 40e^3 (1 %
** noise), the Levenberg-Marquardt crawls along a valley of nearly equal depth that this stops
** gained 0.02 and 0.11 s^2 in 65 steps each over 1e5 rows, and the fits of 100 and 1000 rows
** moved by 1e-3 s^2 and 3e-5 of a standard error. */
#define LONG_TOL 1e-2

/* Stage A's Levenberg-Marquardt solves its steps by QR on tables of up to this many rows (the
** digits of an ill-conditioned Jacobian on a short, precise table), by the normal equations above
** (their cost is a few products over the rows; the step's digits matter less there, the optimum's
** condition J^T r = 0 is the same). */
#define LM_QR_ROWS 256
#define LM_STALL_LONG 2

/* Number of inequality constraints of the design, and the CF_C_* bit of each. */
#define NCON 8
#define CON_TRAVEL 4

/* For a stress-strain table with no fixed parameter the design limits reduce to closed-form
** limits on (rho, B = s/H, A = F_C/H^2), because H is a pure scale (family.h,
** cf_ident_region_at). REGION_SAFETY keeps solutions that far inside, so that placement finds
** them. */
#define REGION_SAFETY 1e-4

typedef cf_ident_region region;

typedef struct fit_ctx {
    const cf_table *data;
    const cf_fit_options *opt;
    cf_spring_type type;
    int fd;
    size_t n;
    double *sw;     /* sqrt(w_i)/scale_i: residual i is sw_i (model_i - y_i) */
    double *model;  /* scratch: the model at each point (same allocation as sw) */
    double *gt, *gr; /* scratch: the canonical law's derivatives in t and rho at each point */
    double xmax;    /* largest |x|: strain [-] or displacement [mm] */
    double ynorm;   /* sum of (sw_i y_i)^2: objective of the zero model */
    int travel_ok;  /* 0 when no spring can reach xmax (strain >= 1) */
    int region;     /* 1: the type's placeable set of (rho, B, A) is known in closed form
                    ** (stress-strain table, no fixed parameter; see cf_fit_region_at) */
    double inside;  /* how far inside those limits (log units) a sub-problem's points keep:
                    ** REGION_SAFETY for the searches, less for the profiles (uncertainty) */
    /* stage A bounds on (rho, length scale) */
    double rho_lo, rho_hi, b_lo, b_hi;
    long evals;
    double stat_tol; /* LONG_TOL/(rows - 3) in a fit (0: placement alone): a local search stops
                     ** once a step lowers the objective by less than this fraction of it */
    int crawl_stop;  /* 1 in a short table's strict polish of stage A: it stops at the statistical
                     ** tolerance below rho_min (cf_fit_lm_run) */
    int lm_have;     /* 1 while model, gt and gr hold the law and its derivatives at lm_at, the
                     ** position of stage A's Levenberg-Marquardt last evaluated (cf_fit_lm_run) */
    double lm_at[3];
    /* stage B/C: free parameters */
    int nfree;
    int free_idx[CF_P_COUNT];
    double base[CF_P_COUNT]; /* values of the fixed parameters */
    /* stage B targets */
    double target[3];
    double pref[3]; /* preferred log c, log n, log H */
    int oom;        /* 1 when an allocation of GSL or NLopt failed: the fit ends with an error */
} fit_ctx;

typedef struct start {
    double obj, rho, B;
} start;

/* A point of stage A's grid over (rho, B) and the reduced model's fit there with the load scale in
** closed form: its RSS at the optimal scale A (rss; syy at A = 1e-300 where that scale is not
** positive) and sgg, the sum of the weighted model's squares, so that the RSS at any other scale
** A' is rss + (A' - A)^2 sgg without a pass over the rows (the constrained stage clamps the scale
** to the type's largest). done = 0: not evaluated yet. */
typedef struct grid_point {
    double rho, B, rss, A, sgg;
    int done;
} grid_point;

/* A result of stage A's Levenberg-Marquardt runs (at most 1 + multistart of them are kept). */
typedef struct start4 {
    double obj, v[3];
} start4;
#define STAGE_A_RUNS 64

/* A sub-problem over (log rho, B) with one quantity held (fixed = 0 rho, 1 B, 2 A; -1 none) and
** the type's limits as constraints: the constrained fit (fixed = -1) and the profiles. */
typedef struct sub {
    fit_ctx *c;
    int fixed;
    double t;
    double step; /* > 0: COBYLA's first step, relative to each variable's range (0: NLopt's) */
} sub;

typedef double (*zfun)(fit_ctx *c, const double *z, int which);

/* Solid length of a spring of the given type (the type being fitted, not the one its geometry
** has; the type constraint makes the two agree). */
static inline double lmin_of(const double *p, cf_spring_type type)
{
    return type == CF_TELESCOPING ? p[CF_P_D] : p[CF_P_N] * p[CF_P_D];
}

static inline void to_array(const cf_spring *s, double *p)
{
    p[CF_P_D1] = s->D1_mm;
    p[CF_P_D2] = s->D2_mm;
    p[CF_P_N] = s->n;
    p[CF_P_D] = s->d_mm;
    p[CF_P_G] = s->G_MPa;
    p[CF_P_H] = s->H_mm;
}

static inline cf_spring from_array(const double *p)
{
    cf_spring s = {p[CF_P_D1], p[CF_P_D2], p[CF_P_N], p[CF_P_D], p[CF_P_G], p[CF_P_H]};
    return s;
}

/* The functions one stage calls in another, each documented at its definition, by file. */

/* fit_stage_a.c */
gsl_rng *cf_fit_seeded_rng(unsigned long seed, unsigned long stream);
double cf_fit_jitter(gsl_rng *r);
double cf_fit_lm_run(fit_ctx *c, double rho0, double B0, double A0, double out[3]);
int cf_fit_cmp_start4(const void *a, const void *b);
int cf_fit_cmp_start(const void *a, const void *b);
void cf_fit_grid_points(fit_ctx *c, grid_point pts[GRID * GRID]);
void cf_fit_grid_value(fit_ctx *c, grid_point *p);
double cf_fit_stage_a(fit_ctx *c, double best3[3], start4 *found, int *nfound,
                      grid_point *pts);
int cf_fit_stage_a_errors(fit_ctx *c, const double v[3], double se[3], double corr[3][3]);

/* fit_constraints.c */
void cf_fit_constraint_values(const double *p, cf_spring_type type, double xmax, int fd,
                              const cf_fit_options *opt, double g[NCON]);
int cf_fit_check_at(const fit_ctx *c, const cf_spring *sp, unsigned *active, unsigned *violated);

/* fit_placement.c */
void cf_fit_full_params(const fit_ctx *c, const double *z, double *p);
double cf_fit_objective6(fit_ctx *c, const double *p);
double cf_fit_z_objective(fit_ctx *c, const double *z, int which);
nlopt_algorithm cf_fit_algorithm_of(cf_fit_optimizer o);
void cf_fit_nl_run(fit_ctx *c, nlopt_algorithm alg, zfun obj, int equalities, double *z,
                   int maxeval);
void cf_fit_stage_b(fit_ctx *c, const double v[3], double *p, double *z);

/* fit_limits.c */
region cf_fit_region_at(const fit_ctx *c, double rho, double B);
double cf_fit_rss_at(fit_ctx *c, double rho, double B, double A_fixed, double A_max,
                     double *A_out);
void cf_fit_sub_point(const sub *q, const double *x, double *rho, double *B);
double cf_fit_sub_f0(const sub *q, const double *x);
double cf_fit_sub_g0(const sub *q, const double *x);
int cf_fit_sub_empty(const sub *q);
double cf_fit_sub_solve(fit_ctx *c, sub *q, double *x, nlopt_algorithm alg);
int cf_fit_stage_a_constrained(fit_ctx *c, double v[3], grid_point *pts);
unsigned cf_fit_held_at(const fit_ctx *c, const double v[3]);
int cf_fit_region_member(fit_ctx *c, const double v[3], double *p);

/* fit_long.c */
void cf_fit_stage_a_polish(fit_ctx *c, start4 *found, int nfound, double v[3]);
void cf_fit_stage_a_constrained_polish(fit_ctx *c, double v[3]);

/* fit_uncertainty.c */
void cf_fit_uncertainty(fit_ctx *c, fit_ctx *g, cf_fit_result *res, unsigned held_a);

#endif
