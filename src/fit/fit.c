/*
** The fitter's driver (see fit.h): the options, the checks of data and options, the working state
** of one fit, and the fit itself, stage after stage: A (fit_stage_a.c, with the type's limits of
** fit_limits.c and the long-table polish of fit_long.c), B and C (fit_placement.c, under the
** constraints of fit_constraints.c), then the uncertainty (fit_uncertainty.c).
*/
#include "fit/fit.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_rng.h>
#include <nlopt.h>

#include "fit/clock.h"
#include "fit/fit_ctx.h"
#include "fit/lsq.h"
#include "fit/subsample.h"

/* ---- names and options ----------------------------------------------------------------------- */

const char *cf_fit_optimizer_name(cf_fit_optimizer o)
{
    switch (o) {
    case CF_OPT_SLSQP: return "slsqp";
    case CF_OPT_COBYLA: return "cobyla";
    case CF_OPT_MMA: return "mma";
    }
    return "?";
}

cf_status cf_fit_optimizer_parse(const char *name, cf_fit_optimizer *o, cf_error *err)
{
    for (int i = 0; i <= CF_OPT_MMA; i++)
        if (strcmp(name, cf_fit_optimizer_name((cf_fit_optimizer)i)) == 0) {
            *o = (cf_fit_optimizer)i;
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA, "unknown optimizer '%s' (expected slsqp, cobyla or mma)",
                        name);
}

const char *cf_fit_constraint_name(unsigned bit)
{
    switch (bit) {
    case CF_C_INDEX_MIN: return "index_min";
    case CF_C_INDEX_MAX: return "index_max";
    case CF_C_COILS: return "coils_min";
    case CF_C_DIAMETERS: return "D2_ge_D1";
    case CF_C_TRAVEL: return "travel";
    case CF_C_TYPE: return "type";
    case CF_C_BOUNDS: return "bounds";
    case CF_C_RHO_MIN: return "rho_min";
    case CF_C_COILS_MAX: return "coils_max";
    case CF_C_G_MAX: return "G_max";
    case CF_C_D2_H: return "D2_max_H";
    }
    return "?";
}

cf_fit_options cf_fit_default_options(void)
{
    cf_fit_options o;
    memset(&o, 0, sizeof o);
    /* Bounds from the spring description (spring.h); the constraints, not the bounds, shape
    ** the fit. */
    for (int k = 0; k < CF_P_COUNT; k++) {
        o.lower[k] = cf_spring_param_info(k)->lower;
        o.upper[k] = cf_spring_param_info(k)->upper;
    }
    o.upper[CF_P_N] = CF_FIT_COILS_MAX_DEFAULT;
    o.upper[CF_P_G] = CF_FIT_G_MAX_DEFAULT;
    o.rho_min = CF_FIT_RHO_MIN_DEFAULT;
    o.D2_over_H_max = CF_FIT_D2_OVER_H_MAX_DEFAULT;
    o.index_max = CF_FIT_INDEX_MAX_DEFAULT;
    o.optimizer = CF_OPT_SLSQP;
    o.xtol_rel = 1e-12;
    o.seed = 1;
    o.multistart = 8;
    o.H_preferred_mm = 10.0;
    o.subsample_above = CF_FIT_SUBSAMPLE_ABOVE;
    return o;
}

double cf_fit_model(const cf_law *law, int force_displacement, double x)
{
    if (force_displacement)
        return cf_law_force(law, CF_LAW_CLOSED, x, NULL, NULL);
    const double H = law->p.H_mm;
    return cf_law_force(law, CF_LAW_CLOSED, x * H, NULL, NULL) / (H * H);
}


/* ---- the checks and the working state -------------------------------------------------------- */

/* The smallest largest |y| (MPa or N) and |x| (strain or mm) of a table, and the range of its
** weights, that the fit's arithmetic carries: below, the squared residuals and the weighted sums
** underflow (a table of stresses below 1e-18 kPa fitted to R^2 = -5.8e15, weights of 5e-324 gave
** a verdict of nan, denormal strains an infinite solid strain). Stresses down to 2e-18 MPa were
** measured to fit as their table times 1e16 does; the limits keep three decades from that. */
#define FIT_Y_MIN 1e-15
#define FIT_X_MIN 1e-12
#define FIT_W_MIN 1e-100

static cf_status check_data(const cf_table *d, cf_error *err)
{
    if (d->count < 4)
        return cf_error_set(err, CF_E_DATA, "%zu data points: a fit needs at least 4", d->count);
    double ymax = 0, xmax = 0, wmax = 0;
    size_t iy = 0, ix = 0;
    for (size_t i = 0; i < d->count; i++) {
        if (!isfinite(d->x[i]) || !isfinite(d->y[i]))
            return cf_error_set(err, CF_E_DATA, "data point %zu is not finite (%g, %g)", i + 1,
                                d->x[i], d->y[i]);
        if (d->w && !(d->w[i] > 0 && isfinite(d->w[i])))
            return cf_error_set(err, CF_E_DATA, "weight of data point %zu is %g (must be > 0)",
                                i + 1, d->w[i]);
        if (fabs(d->y[i]) > ymax)
            ymax = fabs(d->y[iy = i]);
        if (fabs(d->x[i]) > xmax)
            xmax = fabs(d->x[ix = i]);
        wmax = d->w ? fmax(wmax, d->w[i]) : 1;
    }
    if (!(ymax > 0) || !(xmax > 0))
        return cf_error_set(err, CF_E_DATA, "every %s value is zero: nothing to fit",
                            !(ymax > 0) ? "y" : "x");
    const double to_file = d->y_to_file > 0 ? d->y_to_file : 1;
    if (ymax < FIT_Y_MIN)
        return cf_error_set(err, CF_E_DATA,
                            "the largest |%s| is %g %s (data point %zu), below %g %s: the fit's "
                            "sums of squares underflow; give the column in a smaller unit",
                            d->y_column[0] ? d->y_column : "y", ymax * to_file, d->y_unit, iy + 1,
                            FIT_Y_MIN * to_file, d->y_unit);
    if (xmax < FIT_X_MIN)
        return cf_error_set(err, CF_E_DATA,
                            "the largest |%s| is %g (data point %zu), below %g: nothing a spring "
                            "could be fitted to",
                            d->x_column[0] ? d->x_column : "x", xmax, ix + 1, FIT_X_MIN);
    for (size_t i = 0; d->w && i < d->count; i++)
        if (d->w[i] < FIT_W_MIN * wmax || d->w[i] < FIT_W_MIN)
            return cf_error_set(err, CF_E_DATA,
                                "weight of data point %zu is %g: weights below %g, or below %g "
                                "of the largest (%g), underflow in the weighted sums",
                                i + 1, d->w[i], FIT_W_MIN, FIT_W_MIN, wmax);
    return CF_OK;
}

static cf_status check_options(const cf_fit_options *o, cf_error *err)
{
    if (!(o->index_max >= 3 && o->index_max <= CF_FIT_INDEX_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA,
                            "index_max = %g: the largest spring index must lie in [3, %g]",
                            o->index_max, CF_FIT_INDEX_MAX_LIMIT);
    if (!(o->rho_min >= CF_FIT_RHO_MIN_LIMIT))
        return cf_error_set(err, CF_E_DATA, "rho_min = %g: at least %g", o->rho_min,
                            CF_FIT_RHO_MIN_LIMIT);
    if (!(o->upper[CF_P_N] <= CF_FIT_COILS_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA, "upper bound of n = %g: at most %g coils",
                            o->upper[CF_P_N], CF_FIT_COILS_MAX_LIMIT);
    if (!(o->upper[CF_P_G] <= CF_FIT_G_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA, "upper bound of G = %g MPa: at most %g MPa",
                            o->upper[CF_P_G], CF_FIT_G_MAX_LIMIT);
    if (!(o->D2_over_H_max <= CF_FIT_D2_OVER_H_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA, "D2/H limit = %g: at most %g", o->D2_over_H_max,
                            CF_FIT_D2_OVER_H_MAX_LIMIT);
    for (int k = 0; k < CF_P_COUNT; k++) {
        if (!(o->lower[k] > 0 && o->lower[k] <= o->upper[k] && isfinite(o->upper[k])))
            return cf_error_set(err, CF_E_DATA, "bounds of %s: %g .. %g are not 0 < lo <= hi",
                                cf_spring_param_info(k)->name, o->lower[k], o->upper[k]);
        if (o->fixed[k] && !(o->fixed_value[k] > 0 && isfinite(o->fixed_value[k])))
            return cf_error_set(err, CF_E_DATA, "fixed %s = %g must be a positive number",
                                cf_spring_param_info(k)->name, o->fixed_value[k]);
    }
    if (!(o->rho_min > 0 && o->rho_min < 1))
        return cf_error_set(err, CF_E_DATA,
                            "rho_min = %g: the smallest diameter ratio D1/D2 must lie in (0, 1)",
                            o->rho_min);
    if (!(o->D2_over_H_max > 0) || !isfinite(o->D2_over_H_max))
        return cf_error_set(err, CF_E_DATA, "D2/H limit = %g must be a positive number",
                            o->D2_over_H_max);
    if (o->upper[CF_P_N] < 2)
        return cf_error_set(err, CF_E_DATA, "upper bound of n = %g: a conical spring needs n >= 2",
                            o->upper[CF_P_N]);
    if (o->fixed[CF_P_N] && o->fixed_value[CF_P_N] < 2)
        return cf_error_set(err, CF_E_DATA, "fixed n = %g: a conical spring needs n >= 2",
                            o->fixed_value[CF_P_N]);
    if (o->multistart < 1)
        return cf_error_set(err, CF_E_DATA, "multistart = %d must be >= 1", o->multistart);
    return CF_OK;
}

static void summarise(fit_ctx *c, const double *p, cf_fit_result *res)
{
    res->params = from_array(p);
    cf_law_init(&res->law, &res->params, NULL);
    res->ident = cf_ident_of_type(&res->params, c->type, c->fd);
    cf_fit_model_many(&res->law, c->fd, c->n, c->data->x, c->model);
    cf_lsq_quality q = cf_lsq_quality_of(c->data, c->model);
    res->rss = q.rss;
    res->rmse = q.rmse;
    res->max_abs_error = q.max_abs_error;
    res->r2 = q.r2;
    res->objective = cf_fit_objective6(c, p) * c->ynorm;
    res->feasible = cf_fit_check_at(c, &res->params, &res->active, &res->violated);
    res->objective_zero = c->ynorm;
    res->solid_table_strain = res->ident.solid;
    res->solid_ratio = c->xmax > 0 ? res->ident.solid / c->xmax : INFINITY;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            res->corr[a][b] = NAN;
}

/* Checks data and options and prepares the context shared by every stage (c->sw is malloc'd). */
static cf_status ctx_setup(fit_ctx *c, const cf_table *data, const cf_fit_options *opt,
                           cf_spring_type type, cf_error *err)
{
    memset(c, 0, sizeof *c);
    cf_status st = check_data(data, err);
    if (st != CF_OK || (st = check_options(opt, err)) != CF_OK)
        return st;
    c->data = data;
    c->opt = opt;
    c->type = type;
    c->inside = REGION_SAFETY;
    c->fd = cf_table_is_force(data);
    c->n = data->count;
    /* one block: the residual weights, then the model's values at the points (summarise, and
    ** scratch for the stages) and the canonical law's two derivatives (stage A's Jacobian) */
    c->sw = malloc(4 * sizeof(double) * c->n);
    if (!c->sw)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", c->n);
    c->model = c->sw + c->n;
    c->gt = c->model + c->n;
    c->gr = c->gt + c->n;
    c->ynorm = cf_lsq_weights(data, opt->relative, c->sw);
    c->xmax = cf_lsq_xmax(data);
    int nfixed = 0;
    for (int k = 0; k < CF_P_COUNT; k++)
        nfixed += opt->fixed[k] != 0;
    c->region = !c->fd && nfixed == 0;
    /* Stage A bounds. Both types search the same range of rho when the type's own limits are
    ** known in closed form (they are then imposed as constraints, cf_fit_region_at), so that both
    ** report the same quantities wherever neither type's limits bind; rho_min is one of those
    ** limits and stage A searches a little below it, so that an optimum on rho_min lies inside its
    ** range. Otherwise (family.h, cf_ident_rho_hi) telescoping stops at
    ** rho <= index_max/(index_max + 4). */
    c->rho_lo = fmax(CF_IDENT_RHO_LO, opt->rho_min * (c->region ? 0.9 : 1 - CF_IDENT_RHO_MIN_TOL));
    c->rho_hi = c->region ? 1.0 : cf_ident_rho_hi(type, opt->index_max);
    if (c->rho_hi <= c->rho_lo * (1 + 1e-9))
        return cf_error_set(err, CF_E_DATA,
                            "rho_min = %g leaves no diameter ratio a %s spring can have (at most "
                            "%g with index_max = %g)",
                            opt->rho_min, cf_spring_type_name(type), c->rho_hi, opt->index_max);
    double need = c->xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9);
    if (c->fd) {
        c->travel_ok = 1;
        c->b_lo = need;
        c->b_hi = 1e3 * need;
    } else {
        c->travel_ok = need < 1 - 1e-9;
        c->b_lo = c->travel_ok ? need : 1e-6;
        c->b_hi = 1 - 1e-9;
    }
    for (int k = 0; k < CF_P_COUNT; k++) {
        if (opt->fixed[k])
            c->base[k] = opt->fixed_value[k];
        else
            c->free_idx[c->nfree++] = k;
    }
    c->pref[0] = log(sqrt(3.0 * opt->index_max));
    c->pref[1] = log(4.0);
    c->pref[2] = log(opt->fixed[CF_P_H] ? opt->fixed_value[CF_P_H] : opt->H_preferred_mm);
    return CF_OK;
}

static void ctx_free(fit_ctx *c)
{
    free(c->sw);
}

/* ---- the fit --------------------------------------------------------------------------------- */

cf_status cf_fit_place(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                       const cf_ident *ident, cf_fit_result *res, cf_error *err)
{
    const double t0 = cf_clock_s();
    fit_ctx c;
    cf_status st = ctx_setup(&c, data, opt, type, err);
    if (st != CF_OK) {
        ctx_free(&c);
        return st;
    }
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        if (!(ident->v[k] > 0) || !isfinite(ident->v[k])) {
            ctx_free(&c);
            return cf_error_set(err, CF_E_DATA, "identifiable quantity %d = %g must be positive",
                                k, ident->v[k]);
        }
    double p[CF_P_COUNT], z[CF_P_COUNT];
    cf_fit_stage_b(&c, ident->v, p, z);
    memset(res, 0, sizeof *res);
    res->type = type;
    summarise(&c, p, res);
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        res->ident_se.v[k] = -1;
    res->optimizer = "placement";
    res->evaluations = res->evaluations_full = c.evals;
    const int oom = c.oom;
    ctx_free(&c);
    if (oom)
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory in the %s placement's solver (NLopt)",
                            cf_spring_type_name(type));
    res->wall_time_s = cf_clock_s() - t0;
    return CF_OK;
}

/* The fit of one spring type: stage A (the identifiable quantities), B (placement of a spring),
** C (polish on the real objective) and the errors, as marked below. Kept as one function because
** the stages hand the same working point, subsample and result along; A, B and the errors are
** calls of their own, C's loop over starts keeps the best candidate inline. */
cf_status cf_fit_run(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                     cf_fit_result *res, cf_error *err)
{
    CF_GSL_GUARD;
    return cf_fit_run_shared(data, opt, type, NULL, res, err);
}

/* Whether two option sets give the same stage A (every field but the stage-C optimiser and the
** law kind, which stage A does not read, compared one by one: no padding bytes). */
/* A force table that the law meets only in its first region (every |x| at or below the
** transition) determines the initial stiffness alone, which depends on (rho, B, A) only through
** A/B at a given rho: the travel and the solid load slide together along a valley of one sum of
** squares that reaches the travel's bound of a thousand times the data, and where a search stops
** in it is an accident of its tolerance (on a linear clot table one search ended at a travel of
** 7.6 mm, another at 4.2 m, whose spring was as long). A stress-strain table's valley ends at a
** solid strain of 1, where the spring still has the preferred length, and is left to the search.
** The fit takes the valley's compact end: the
** transition at the table's largest |x|, or further where the solid would otherwise come closer
** to the data than the reports accept (CF_FIT_SOLID_RATIO_WARN). The law is the same on every
** row (checked: the sum of squares may not rise beyond rounding) and the spring the shortest of
** the family that stays linear over the table. Kept only inside the type's closed-form region
** when it has one. */
static void compact_first_region(fit_ctx *c, double v[3])
{
    if (!c->fd || !(c->xmax > 0) || !(v[0] > 0 && v[0] <= 1))
        return;
    const double uT = v[1] * cf_ident_canon_transition(v[0]); /* the transition in the table's x */
    if (!(c->xmax < uT))
        return;
    const double lam =
        fmax(fmax(c->xmax / uT, CF_FIT_SOLID_RATIO_WARN * c->xmax / v[1]), c->b_lo / v[1]);
    if (!(lam < 1))
        return;
    const double w[3] = {v[0], lam * v[1], lam * v[2]};
    if (c->region) {
        region r = cf_fit_region_at(c, w[0], w[1]);
        if (r.margin > 0 || w[2] > r.A_max)
            return;
    }
    double a;
    const double f0 = cf_fit_rss_at(c, v[0], v[1], v[2], INFINITY, &a);
    const double f1 = cf_fit_rss_at(c, w[0], w[1], w[2], INFINITY, &a);
    if (f1 < CF_LSQ_HUGE_OBJ && f1 <= f0 * (1 + 1e-9))
        memcpy(v, w, sizeof w);
}

static int same_stage_a_options(const cf_fit_options *a, const cf_fit_options *b)
{
    for (int k = 0; k < CF_P_COUNT; k++)
        if (a->fixed[k] != b->fixed[k] || a->fixed_value[k] != b->fixed_value[k] ||
            a->lower[k] != b->lower[k] || a->upper[k] != b->upper[k])
            return 0;
    return a->index_max == b->index_max && a->rho_min == b->rho_min &&
           a->D2_over_H_max == b->D2_over_H_max && a->relative == b->relative &&
           a->xtol_rel == b->xtol_rel && a->seed == b->seed && a->multistart == b->multistart &&
           a->H_preferred_mm == b->H_preferred_mm && a->subsample_above == b->subsample_above;
}

/* Stage A: the identifiable quantities v, over every spring (a long table's starts on its
** subsample g, polished on every row c; a short table's best polished to the strict rule), or
** the other type's stage A of the same table where both search the same range (shared). pts
** holds the grid when this fit ran it (*pts_ok). */
static void stage_a(fit_ctx *c, fit_ctx *sc, fit_ctx *g, int long_table, const cf_table *data,
                    const cf_fit_options *opt, cf_fit_shared *shared, double v[3],
                    grid_point *pts, int *pts_ok)
{
    start4 found[STAGE_A_RUNS];
    int nfound = 0;
    /* both types' stage A searches the same range where their limits are known in closed form
    ** (c->region): the same optimum, which the second fit of a table takes from the first */
    const int share = shared && c->region;
    const long evals0 = c->evals, sub_evals0 = sc->evals;
    if (share && shared->have && shared->data == data && same_stage_a_options(&shared->opt, opt)) {
        memcpy(v, shared->v, 3 * sizeof *v);
        /* the fit rests on those evaluations as much as the first: they count in both */
        c->evals += shared->evals_full;
        sc->evals += shared->evals_sub;
    } else {
        if (long_table)
            sc->stat_tol = LONG_TOL / (double)(sc->n - 3);
        cf_fit_stage_a(g, v, long_table ? found : NULL, &nfound, pts);
        *pts_ok = 1;
        sc->stat_tol = 0;
        if (long_table) {
            cf_fit_stage_a_polish(c, found, nfound, v);
        } else {
            /* the starts stopped at the statistical tolerance; the best is polished to the
            ** strict rule, so that a short table's fit is its optimum to rounding */
            double w[3];
            const double tol = c->stat_tol;
            c->stat_tol = 0;
            c->crawl_stop = 1;
            if (cf_fit_lm_run(c, v[0], v[1], v[2], w) < CF_LSQ_HUGE_OBJ)
                memcpy(v, w, sizeof w);
            c->crawl_stop = 0;
            c->stat_tol = tol;
        }
    }
    if (share && !shared->have && !c->oom && !sc->oom) {
        shared->have = 1;
        shared->data = data;
        shared->opt = *opt;
        memcpy(shared->v, v, 3 * sizeof *v);
        shared->evals_full = c->evals - evals0;
        shared->evals_sub = sc->evals - sub_evals0;
    }
}

/* Stage A under the type's limits when its optimum v lies outside them: the limits that held it
** (0: none). */
static unsigned stage_a_limits(fit_ctx *c, fit_ctx *g, int long_table, double v[3],
                               grid_point *pts)
{
    unsigned held_a = 0;
    if (c->region) {
        region r = cf_fit_region_at(c, v[0], v[1]);
        int out = r.margin > 0, over = v[2] > r.A_max / (1 - REGION_SAFETY);
        if (out || over) {
            held_a = (out ? r.lo_bit | r.hi_bit : 0u) | (over ? (unsigned)CF_C_G_MAX : 0u);
            if (cf_fit_stage_a_constrained(g, v, pts)) {
                if (long_table)
                    cf_fit_stage_a_constrained_polish(c, v);
                held_a |= cf_fit_held_at(c, v);
            }
        }
    }
    return held_a;
}

/* The best spring so far: its parameters, objective and feasibility. */
typedef struct best6 {
    double p[CF_P_COUNT];
    double obj;
    int feas;
} best6;

/* Takes q (feasibility feas, objective o) when it beats b: feasible first, then lower. */
static void best_take(best6 *b, const double *q, int feas, double o)
{
    if ((feas && !b->feas) || (feas == b->feas && o < b->obj)) {
        b->obj = o;
        b->feas = feas;
        memcpy(b->p, q, sizeof b->p);
    }
}

/* Stage C: local polish on the real objective from stage B's placement z; with fixed parameters
** the family may be out of reach, so then also from seeded starts around the placement. A long
** table polishes its starts on the subsample and the best of them on every row; without fixed
** parameters on a stress-strain table (c->region) the six parameters reach the model only
** through the three quantities that stage A fitted on every row, so the polish there can move the
** objective by rounding only (1e-14 of it on the shipped tables) and a long table skips its full
** pass. */
static void stage_c(fit_ctx *c, fit_ctx *g, int long_table, unsigned held_a,
                    const cf_fit_options *opt, const double *z, best6 *best)
{
    if (!long_table)
        c->stat_tol = 0; /* stage C on a short table: to the optimiser's own tolerances */
    gsl_rng *rng = cf_fit_seeded_rng(opt->seed, 2);
    c->oom |= !rng;
    int starts = 1;
    for (int k = 0; k < CF_P_COUNT; k++)
        if (opt->fixed[k])
            starts = opt->multistart;
    const nlopt_algorithm alg = cf_fit_algorithm_of(opt->optimizer);
    unsigned act, vio;
    cf_spring sp;
    double cand_z[CF_P_COUNT];
    best6 cand = {{0}, CF_LSQ_HUGE_OBJ, 0};
    int have_cand = 0;
    for (int s = 0; s < starts; s++) {
        double zz[CF_P_COUNT];
        for (int k = 0; k < c->nfree; k++)
            zz[k] = z[k] + (s == 0 ? 0.0 : 0.5 * (cf_fit_jitter(rng) - 0.5));
        cf_fit_nl_run(g, alg, cf_fit_z_objective, 0, zz, 3000);
        double q[CF_P_COUNT];
        cf_fit_full_params(c, zz, q);
        sp = from_array(q);
        int feas = cf_fit_check_at(c, &sp, &act, &vio);
        double o = cf_fit_objective6(g, q);
        if (long_table) {
            if (!have_cand || (feas && !cand.feas) || (feas == cand.feas && o < cand.obj)) {
                have_cand = 1;
                cand.obj = o;
                cand.feas = feas;
                memcpy(cand_z, zz, sizeof zz);
            }
        } else {
            best_take(best, q, feas, o);
        }
    }
    gsl_rng_free(rng);
    if (have_cand) {
        if (!c->region || held_a)
            cf_fit_nl_run(c, alg, cf_fit_z_objective, 0, cand_z, 3000);
        double q[CF_P_COUNT];
        cf_fit_full_params(c, cand_z, q);
        sp = from_array(q);
        int feas = cf_fit_check_at(c, &sp, &act, &vio);
        best_take(best, q, feas, cf_fit_objective6(c, q));
    }
}

cf_status cf_fit_run_shared(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                            cf_fit_shared *shared, cf_fit_result *res, cf_error *err)
{
    CF_GSL_GUARD;
    const double t0 = cf_clock_s();
    memset(res, 0, sizeof *res);
    fit_ctx c, sc;
    memset(&sc, 0, sizeof sc);
    cf_table subt;
    memset(&subt, 0, sizeof subt);
    cf_status st = ctx_setup(&c, data, opt, type, err);
    /* A long table: the global searches see its subsample (g), the polish every row (c). */
    const int long_table = st == CF_OK && opt->subsample_above > 0 && c.n > opt->subsample_above;
    if (long_table && (st = cf_subsample(data, CF_SUBSAMPLE_ROWS, &subt, err)) == CF_OK)
        st = ctx_setup(&sc, &subt, opt, type, err);
    if (st != CF_OK) {
        ctx_free(&c);
        ctx_free(&sc);
        cf_table_free(&subt);
        return st;
    }
    fit_ctx *g = long_table ? &sc : &c;
    /* the local searches on the table's own rows stop at the statistical tolerance (fit_ctx.h);
    ** so do a long table's stage A starts on its subsample (each is polished on every row next;
    ** strict starts there cost 0.6 s of the 0.9 s fit of a 1001-row table and gave the same fit),
    ** while its constrained search on the subsample keeps the strict rule (with the tolerance the
    ** subsample's optimum moved enough to end 0.07 s^2 short on a ridge of a limit) */
    c.stat_tol = LONG_TOL / (double)(c.n - 3); /* c.n >= 4 (check_data) */
    double v[3] = {0.5, 0.5 * (c.b_lo + c.b_hi), 1.0};
    grid_point pts[GRID * GRID]; /* stage A's grid, when this fit runs it */
    int pts_ok = 0;
    stage_a(&c, &sc, g, long_table, data, opt, shared, v, pts, &pts_ok);
    compact_first_region(&c, v);
    /* the limits that keep the type from stage A's optimum */
    const unsigned held_a = stage_a_limits(&c, g, long_table, v, pts_ok ? pts : NULL);
    /* Stage B: place a spring of the family. */
    double p[CF_P_COUNT], z[CF_P_COUNT];
    cf_fit_stage_b(&c, v, p, z);
    best6 best;
    best.obj = cf_fit_objective6(&c, p);
    memcpy(best.p, p, sizeof p);
    unsigned act, vio;
    cf_spring sp = from_array(p);
    best.feas = cf_fit_check_at(&c, &sp, &act, &vio);
    stage_c(&c, g, long_table, held_a, opt, z, &best);
    res->type = type;
    summarise(&c, best.p, res);
    /* Errors, correlation and, where the data leave a quantity open, its profile interval: at
    ** the reported spring's quantities. */
    cf_fit_uncertainty(&c, g, res, held_a);
    res->optimizer = cf_fit_optimizer_name(opt->optimizer);
    res->evaluations = c.evals + sc.evals;
    res->evaluations_full = c.evals;
    const int oom = c.oom || sc.oom;
    ctx_free(&c);
    ctx_free(&sc);
    cf_table_free(&subt);
    res->wall_time_s = cf_clock_s() - t0;
    if (oom) /* a stage ran short: its result is not the fit's */
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory in the %s fit's solvers (GSL, NLopt)",
                            cf_spring_type_name(type));
    return CF_OK;
}

cf_fit_verdict cf_fit_compare(const cf_fit_result *a, const cf_fit_result *b, size_t points)
{
    CF_GSL_GUARD;
    cf_fit_verdict v = {0, -1, NAN, NAN, 0};
    const cf_fit_result *f[2] = {a, b};
    if (a->feasible && b->feasible)
        v.better = b->objective < a->objective ? 1 : 0;
    else if (a->feasible || b->feasible)
        v.better = a->feasible ? 0 : 1;
    else
        return v;
    const cf_fit_result *w = f[1 - v.better], *g = f[v.better];
    if (!w->feasible) { /* no contest: the other type has no spring inside its limits */
        v.held = w->violated;
        return v;
    }
    double dof = points > 3 ? (double)points - 3 : 1;
    double s2 = fmax(g->objective / dof, 1e-24 * g->objective_zero / (double)points);
    v.delta_rss = w->objective - g->objective;
    v.threshold = cf_lsq_f95(dof) * s2;
    v.tie = v.delta_rss <= v.threshold;
    v.held = w->held & ~g->held;
    if (!v.held)
        v.held = w->held;
    return v;
}
