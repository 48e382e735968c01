/*
** Fitting conical-spring design parameters (D1, D2, n, d, G, H) to a measured table.
**
** The law seen through a table depends on three combinations only (identifiability): the diameter
** ratio rho = D1/D2, a length scale and a load scale. For a stress-strain table (sigma = F/H^2,
** epsilon = u/H) those are the solid strain s/H and the stress scale F_C/H^2 (MPa); for a
** force-displacement table the travel s (mm) and the solid load F_C (N). The fit therefore runs in
** three stages:
**   A. the three identifiable quantities: a global search over (rho, length scale) with the load
**      scale solved in closed form (the model is linear in it), started also from the paper's
**      two-point derivation (transition and maximum point, eqs. 11-17), then Levenberg-Marquardt
**      (GSL) from the best starts; standard errors from the Jacobian (s^2 (J^T W J)^-1);
**   B. placement: NLopt picks one spring of that family that meets the design constraints,
**      honours fixed parameters and is closest (in log space) to a practical preferred design;
**   C. polish: an NLopt local optimiser (COBYLA, SLSQP or MMA) on the weighted least-squares
**      objective in the six design parameters under the nonlinear inequality constraints
**      c = D1/d in [3, index_max], n >= 2, D2 >= D1, travel > largest |u| (with a margin), and the
**      type condition (telescoping <=> (D2 - D1)/2 >= n d).
** Every reported solution is checked against the constraints here, not taken from the optimiser.
** Deterministic: the only randomness is a seeded generator in the result-local state.
** Thread-safe: no globals; each call owns its state.
*/
#ifndef CF_FIT_H
#define CF_FIT_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/family.h"
#include "model/law_internal.h"
#include "io/measure.h"

/* Arrays of design parameters below are indexed by CF_P_D1 ... CF_P_H (spring.h). */

/* Constraints are the CF_C_* bits of family.h. */

/* Default limits that keep a fitted spring one that could be wound and defended: a diameter ratio
** of at least 1/20 (below it the largest coil dwarfs the smallest and the law's nonlinear region
** is a vanishing sliver of the travel), at most 30 coils, an outer diameter of at most ten free
** lengths, and a wire no stiffer in shear than steel (G = 80 GPa). */
#define CF_FIT_RHO_MIN_DEFAULT 0.05
#define CF_FIT_COILS_MAX_DEFAULT 30.0
#define CF_FIT_D2_OVER_H_MAX_DEFAULT 10.0
#define CF_FIT_G_MAX_DEFAULT 80000.0

/* The widest limits a fit takes (cf_fit_run refuses wider ones as bad options, naming them): a
** spring index of at most 50 (handbooks stop near 25; above it a coil does not hold its shape), at
** most 1000 coils, a wire at most 1e6 MPa stiff in shear (tungsten carbide, the stiffest wire
** material, is about 2.7e5 MPa), an outer diameter of at most 1000 free lengths, and a diameter
** ratio of at least CF_IDENT_RHO_LO = 1e-3, the smallest the search reaches. Within them the fitted
** springs stay inside their limits and the limits inside the parameter bounds of spring.h. */
#define CF_FIT_INDEX_MAX_LIMIT 50.0
#define CF_FIT_COILS_MAX_LIMIT 1000.0
#define CF_FIT_G_MAX_LIMIT 1e6
#define CF_FIT_D2_OVER_H_MAX_LIMIT 1000.0
#define CF_FIT_RHO_MIN_LIMIT 1e-3

/* A fit whose law goes solid at less than this multiple of the table's largest strain is
** extrapolating close to solid just past the data (reports warn). */
#define CF_FIT_SOLID_RATIO_WARN 1.5

typedef enum cf_fit_optimizer {
    CF_OPT_SLSQP = 0,  /* NLopt SLSQP, central-difference gradients */
    CF_OPT_COBYLA = 1, /* NLopt COBYLA, derivative-free */
    CF_OPT_MMA = 2     /* NLopt MMA, central-difference gradients */
} cf_fit_optimizer;

/* Relative travel margin: the largest measured |u| must stay this fraction of the travel short of
** solid. Near solid the stiffness grows like (s - u)^(-1/2): a spring whose solid point sat on
** the last data point would have an unbounded stiffness there. 1e-6 keeps the point clearly
** inside (the law resolves s - u to rounding, ~1e-16 s) while allowing tables measured, or
** synthesised, to within a few parts in 1e5 of solid. */
#define CF_FIT_TRAVEL_MARGIN 1e-6

/* Default upper spring index. Wound springs are practical for indices of about 4 to 12; above
** that the coils tangle and buckle (the usual design handbooks give the same range). */
#define CF_FIT_INDEX_MAX_DEFAULT 12.0

/* The law kind a fit uses (src/model/law.md): the conical spring's law (three identifiable
** quantities), the conical spring with a cylindrical tail in series (four: the tail's compliance
** e_t = F_C/(k_t H) too, cf_fit_tail_run), or both with the choice by AIC (the pipeline). */
typedef enum cf_law_kind {
    CF_KIND_CONICAL = 0,
    CF_KIND_TAIL = 1,
    CF_KIND_AUTO = 2,
    CF_KIND_DOUBLE = 3 /* double-acting: a conical compression spring and a conical extension
                         ** spring sharing H (law.h, cf_law.extension; six quantities); joint fits
                         ** only (joint.h), where auto compares it too */
} cf_law_kind;

/* The volume term of a fit through the lattice (cell.h, volume_modulus_MPa): none, kappa declared
** (MPa), the small-strain nu declared (kappa from the lattice's moduli, joint.h), or kappa fitted. */
typedef enum cf_volume {
    CF_VOLUME_NONE = 0,
    CF_VOLUME_MODULUS = 1,
    CF_VOLUME_POISSON = 2,
    CF_VOLUME_FIT = 3
} cf_volume;

/* Parses "conical", "conical-tail", "auto" or "double-acting"; CF_E_DATA naming the value
** otherwise. */
cf_status cf_law_kind_parse(const char *name, cf_law_kind *f, cf_error *err);
const char *cf_law_kind_name(cf_law_kind f);

/* The most law kinds one fit compares (cf_fit_options.kinds; the conical law among them). */
#define CF_LAW_KINDS_MAX 4

typedef struct cf_fit_options {
    int fixed[CF_P_COUNT];          /* 1: held at fixed_value */
    double fixed_value[CF_P_COUNT]; /* mm, -, mm, MPa, mm as in cf_spring */
    double lower[CF_P_COUNT];       /* bounds, same units (upper n and G: CF_FIT_*_DEFAULT) */
    double upper[CF_P_COUNT];
    double index_max;               /* upper spring index, dimensionless (>= 3) */
    double rho_min;                 /* smallest diameter ratio D1/D2 (0 < rho_min < 1) */
    double D2_over_H_max;           /* largest D2/H, dimensionless (> 0) */
    int relative;                   /* 1: residuals relative to |y| (floor 1e-3 max|y|) */
    cf_fit_optimizer optimizer;     /* local optimiser of stage C */
    double xtol_rel;                /* relative tolerance on the parameters (NLopt, GSL) */
    unsigned long seed;             /* seed of the global stage */
    int multistart;                 /* number of local starts in stage A (>= 1) */
    double H_preferred_mm;          /* free length preferred by placement when H is free, mm */
    size_t subsample_above;         /* a table of more rows than this runs the global searches
                                    ** (stage A's grid and starts, the constrained grid) on a
                                    ** deterministic subsample of 1000 rows evenly along x, then
                                    ** polishes on every row; 0: never (default
                                    ** CF_FIT_SUBSAMPLE_ABOVE; the baselines use the same) */
    cf_law_kind law;              /* the law kind (default conical; the pipeline reads it) */
    /* Or the law kinds to compare by AIC, listed (their rows, lawkind.h; the conical law is
    ** always fitted first): nkinds 0 takes them from law. At most CF_LAW_KINDS_MAX. */
    const struct cf_law_row *const *kinds;
    int nkinds;
    cf_volume volume;               /* the volume term of a joint fit (default none) */
    double volume_value;            /* its declared kappa (MPa) or nu (-) */
    double anisotropy_max;          /* a joint fit's fitted weights: their Zener ratio
                                    ** 2 C44/(C11 - C12) held within [1 - a, 1 + a]; 0: the
                                    ** weights' whole box (calibration.h) */
} cf_fit_options;

/* Tables up to this many rows are searched on every row; a longer one on its subsample of as many
** rows (subsample.h), so that the searches cost the same at every length above it and a table
** just past it costs no more than a longer one. */
#define CF_FIT_SUBSAMPLE_ABOVE 1000

cf_fit_options cf_fit_default_options(void);

/* The table to fit is a cf_table (measure.h) in conifit's units: strain [-] and stress [MPa], or
** displacement [mm] and force [N]; its w may be NULL (all weights 1). It is only read. */

typedef struct cf_fit_result {
    cf_spring_type type;
    cf_spring params;      /* the reported spring */
    cf_law law;            /* derived quantities of params (no table) */
    const struct cf_law_row *kind; /* the law kind fitted (lawkind.h): the names, units and
                           ** number kind->nq of the quantities below */
    /* The identifiable quantities q[0 .. kind->nq - 1] (lawkind.h names them); for the conical
    ** kinds the first three are the cone's family (family.h: rho [-]; solid strain s/H [-] or
    ** travel s [mm]; F_C/H^2 [MPa] or F_C [N]), which ident names, and the tailed kind's fourth
    ** is its tail compliance. q_se: their standard errors, same units; -1 when not determined. */
    union {
        cf_ident ident;
        double q[CF_Q_MAX];
    };
    union {
        cf_ident ident_se;
        double q_se[CF_Q_MAX];
    };
    /* Profile-likelihood interval of each identifiable quantity (95 %, F-test on the residual
    ** sum of squares), computed when the quantity sits on a bound or limit of the type, or the
    ** Jacobian is rank-deficient (then q_se is -1); interval_ok[k] = 0 when not computed. */
    int interval_ok[CF_Q_MAX];
    double interval[CF_Q_MAX][2];
    unsigned interval_end[CF_Q_MAX][2]; /* CF_C_* bit of the bound an end reached (0: the
                                        ** threshold) */
    unsigned interval_why[CF_Q_MAX];    /* CF_C_* bits of the bounds the quantity sits on;
                                        ** with CF_FIT_RANK_DEFICIENT when the Jacobian is */
    double corr[CF_Q_MAX][CF_Q_MAX];    /* correlation of the quantities; NAN where not
                                        ** determined */
    unsigned held;         /* CF_C_* bits of the limits that hold the identifiable quantities
                           ** away from the optimum of the law over every spring (the type's
                           ** geometry and the design bounds, rho_min, the travel) */
    double solid_ratio;    /* solid_table_strain over the table's largest |strain|
                           ** (|displacement|): how far the law is from solid at the data */
    double solid_table_strain; /* the table strain (magnitude, on the table's loading side) at
                           ** which the first spring reaches solid in the table's mode: the solid
                           ** strain (travel) itself in uniaxial and for force tables; in the
                           ** cell's other modes set by the pipeline (cf_cell_solid_strain) */
    double rss;            /* unweighted sum of squared residuals, (MPa or N)^2 */
    double rmse;           /* root mean square residual, MPa or N */
    double max_abs_error;  /* largest |residual|, MPa or N */
    double r2;             /* coefficient of determination, dimensionless */
    double objective;      /* weighted (relative) objective minimised: the weighted RSS */
    double objective_zero; /* the same for the zero model (the data's weighted sum of squares) */
    int feasible;          /* 1 when every constraint holds at params (checked here) */
    unsigned active;       /* CF_C_* bits of constraints at their limit (within 1e-6) */
    unsigned violated;     /* CF_C_* bits of violated constraints */
    const char *optimizer; /* name of the stage-C optimiser */
    int tail;              /* 1: a fit of the conical-tail law (params has a tail) */
    long evaluations;      /* evaluations of the model over the table (or its subsample), all
                           ** stages */
    long evaluations_full; /* those over every row of the table (the rest ran on the subsample
                           ** of a long table: cf_fit_options.subsample_above) */
    double wall_time_s;    /* s */
    /* A conical-tail fit that is the conical optimum it contains (tail 1, n_tail 0; fit_tail.c):
    ** the tailed spring its search ended on lost to it, with this RMSE (0: the search found none)
    ** and these violated CF_C_* bits (0: it was feasible but fitted worse). */
    double nested_rmse;
    unsigned nested_violated;
} cf_fit_result;

/* Extra bit in interval_why: the Jacobian of the three quantities is (numerically) singular. */
#define CF_FIT_RANK_DEFICIENT (1u << 31)

/* Fits one spring type. CF_E_DATA for a table that cannot be fitted (fewer than 4 points, a
** non-finite value, all y zero, a non-positive weight) or contradictory options (message names
** them); CF_E_INTERNAL when memory runs out. A fit whose constraints cannot all be met (e.g. a
** strain >= 1, which no spring reaches) is returned with feasible = 0 and the violated bits. */
cf_status cf_fit_run(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                     cf_fit_result *res, cf_error *err);

/* What the fits of the two types of one table share. For a stress-strain table with no fixed
** parameter both types search the same range of the three identifiable quantities, so stage A's
** optimum over every spring (its grid, Levenberg-Marquardt and polish) is the same for both; the
** first fit keeps it here and the second starts from it. Zero it before the first fit of a
** table; it holds no allocation. */
typedef struct cf_fit_shared {
    int have;              /* 1 once a fit has kept its stage A here */
    const cf_table *data;  /* the table and the options it was found with */
    cf_fit_options opt;
    double v[3];           /* stage A's optimum (rho, B, A) */
    long evals_full;       /* the evaluations it took over every row, and over the subsample */
    long evals_sub;
} cf_fit_shared;

/* cf_fit_run, with stage A taken from shared when it was found there for the same table and
** options, and kept there otherwise (shared may be NULL: cf_fit_run). The result is the one
** cf_fit_run gives, bit for bit, its evaluations included (the shared stage A's count in both
** fits); only wall_time_s is the call's own. */
cf_status cf_fit_run_shared(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                            cf_fit_shared *shared, cf_fit_result *res, cf_error *err);

/* Fits the conical-tail law (one type): its four identifiable quantities by a grid and
** Levenberg-Marquardt, their standard errors, and a spring of the type placed in closed form at
** the preferred free length (src/fit/fit_tail.c). plain (may be NULL) is the plain law's fit of the
** same table and type, a start; the tailed law contains it (tail compliance 0), so a tailed fit
** that ends worse than plain (infeasible where plain is feasible, or a larger objective) or finds
** nothing is returned as plain with no tail (tail 1, e_tail 0, n_tail 0). Fixed parameters are
** not honoured (the CLI refuses them). A spring that cannot meet the limits is returned with
** feasible = 0 and the violated bits. */
cf_status cf_fit_tail_run(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                          const cf_fit_result *plain, cf_fit_result *res, cf_error *err);

/* Stage B alone: places one spring of the given type whose identifiable quantities are ident
** (family.h; of the table's kind, as cf_fit_result.ident), exactly as
** cf_fit_run places its spring before the polish, and fills res (quality against data, feasibility;
** ident_se = -1, optimizer "placement"). Used by the fit through the lattice (validate.h). */
cf_status cf_fit_place(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                       const cf_ident *ident, cf_fit_result *res, cf_error *err);

/* The verdict between two fits of one table (the two spring types). Both types are constrained
** subsets of one three-parameter law, so the worse one is judged as the better one's law under an
** extra constraint: an F-test with 1 and N - 3 degrees of freedom at 95 % on the weighted residual
** sum of squares, s^2 = RSS_better/(N - 3) floored at rounding level (1e-12 of the data's scale).
** tie = 1 when the difference is below the threshold; better = index (0 or 1) of the fit with
** the lower objective among the feasible ones (-1 if none); held = the worse fit's held bits. */
typedef struct cf_fit_verdict {
    int tie;
    int better;
    double delta_rss;   /* weighted RSS of the worse minus the better (weighted units) */
    double threshold;   /* F(0.95; 1, N - 3) s^2 */
    unsigned held;      /* what held the worse fit back (CF_C_* bits) */
} cf_fit_verdict;

cf_fit_verdict cf_fit_compare(const cf_fit_result *a, const cf_fit_result *b, size_t points);

/* Evaluates the model (stress in MPa, or force in N) of spring p at x. */
double cf_fit_model(const cf_law *law, int force_displacement, double x);

/* cf_fit_model at count points x into out (which may not alias x), vectorised (the lanes of
** cf_law_force_many): equal to it within a few ulps. */
void cf_fit_model_many(const cf_law *law, int force_displacement, size_t count, const double *x,
                       double *out);

/* Checks the constraints of options/type/data at p: fills *active and *violated (CF_C_* bits) and
** returns 1 when feasible. */
int cf_fit_check(const cf_spring *p, cf_spring_type type, const cf_table *data,
                 const cf_fit_options *opt, unsigned *active, unsigned *violated);

/* The type's design limits in the space of the identifiable quantities of a stress-strain table,
** at rho and B = s/H: returns a margin (log units, <= 0 where a spring of the type can be placed
** within the limits of opt) and in *A_max the largest stress scale F_C/H^2 (MPa) it can carry
** there (family.h, cf_ident_region_at, under the limits of opt). With a fixed parameter no closed
** form exists: margin -1, *A_max = INFINITY. *bits (may be NULL) receives the CF_C_* bits of the
** two limits whose edge bounds the region there (as cf_ident_region_at's lo_bit | hi_bit). Used by the fits through the
** lattice and the viscoelastic fit, which search the same space. */
double cf_fit_ident_limit(const cf_fit_options *opt, cf_spring_type type, double rho, double B,
                          double *A_max, unsigned *bits);

/* Name of a constraint bit ("index_min", ...), and of an optimiser ("slsqp", ...). */
const char *cf_fit_constraint_name(unsigned bit);

/* The command-line flag that widens constraint bit (a sentence for the limits no flag widens). */
const char *cf_fit_constraint_flag(unsigned bit);

/* The same for a table of the kind given (force_displacement 1: its sentences speak of
** displacements, not strains). */
const char *cf_fit_constraint_flag_for(unsigned bit, int force_displacement);

/* o with the design limits among bits (CF_C_INDEX_MAX, CF_C_RHO_MIN, CF_C_COILS_MAX, CF_C_G_MAX,
** CF_C_D2_H) widened to the widest their flags accept (CF_FIT_*_LIMIT); returns the bits widened
** (0: none could be: the fit is as free as the flags allow). */
unsigned cf_fit_relax(const cf_fit_options *o, unsigned bits, cf_fit_options *out);

/* What the design limits that hold a fit cost: its RMSE against that of the same fit with
** those limits widened (cf_fit_relax). */
typedef struct cf_limit_cost {
    int checked;           /* 1: the widened fit ran */
    unsigned limits;       /* CF_C_* bits widened */
    double rmse;           /* the fit's RMSE, MPa or N */
    double rmse_free;      /* the widened fit's, MPa or N */
} cf_limit_cost;

/* A limit whose cost is above this share of the widened fit's RMSE is warned about. */
#define CF_LIMIT_COST_WARN 0.05
const char *cf_fit_optimizer_name(cf_fit_optimizer o);
cf_status cf_fit_optimizer_parse(const char *name, cf_fit_optimizer *o, cf_error *err);

#endif
