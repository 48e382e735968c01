/*
** The conical-tail law through the lattice (lattice_fit.h, cf_lattice_fit_tail): the law's four
** identifiable quantities searched through the homogenised cell as the conical law's three are
** (lattice_fit.c), then the tailed spring placed in closed form (tail.h).
**
** The cell runs the member of the family with a tail (family.h, cf_ident_member_tail) at stress
** scale 1; the scale A comes in closed form, capped at the largest a buildable tailed spring
** carries. BOBYQA searches (log rho, B, q) with the tail's share q = B tau/(1 - B) of the length
** past the cone's travel, so that the cone closes before the free length for every point of the
** box (B (1 + tau) < 1). The cone may close inside the table (the tail carries on), so B is
** bounded below by a small share of the table's largest spring strain, not by it. Standard errors
** of (rho, B, A, tau) come from the cell's central-difference Jacobian (8 curves).
*/
#include "fit/lattice_fit.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <nlopt.h>

#include "model/family.h"
#include "fit/cell_problem.h"
#include "fit/clock.h"
#include "fit/lattice_curve.h"
#include "fit/lsq.h"
#include "fit/profile.h"
#include "fit/subsample.h"
#include "fit/tail.h"
#include "fit/tail_cell.h"

#define XTOL_REL 1e-6 /* as the conical law's search (lattice_fit.c) */
#define MAX_CURVES 600
#define B_LO_SHARE 0.02 /* the cone's travel down to this share of the largest spring strain */
#define Q_LO 1e-6
#define Q_HI 0.99
/* relative step of the errors' central differences, as the conical law's through the cell
** (cell_problem.c) */
#define FD_STEP 1e-4

typedef struct lt_ctx {
    const cf_table *d;
    const cf_validate_setup *s;
    cf_cell_problem pr;
    double tau;  /* the tail of the curves asked for */
    double need; /* the largest spring strain with the travel margin */
} lt_ctx;

static double tau_of(double B, double q)
{
    return q * (1 - B) / B;
}

static int lt_curve(void *ctx, double rho, double B, double *out)
{
    const lt_ctx *c = ctx;
    const cf_ident q = {.rho = rho, .solid = B, .scale = 1.0};
    cf_spring p = cf_ident_member_tail(&q, c->tau);
    return cf_lattice_curve(&p, c->s, c->d, 0, out, NULL, NULL, NULL, NULL) != CF_OK;
}

double cf_tail_cell_A_max(double rho, double B, double tau, double need, cf_spring_type type,
                          const cf_fit_options *opt)
{
    const double room = 1 - B * (1 + tau);
    if (!(room > 0) || !(need < 1 - CF_IDENT_TAIL_SOLIDS * room))
        return 0;
    return cf_tail_A_max(rho, B, tau, type, need, opt);
}

static double lt_A_max(void *ctx, double rho, double B)
{
    const lt_ctx *c = ctx;
    return cf_tail_cell_A_max(rho, B, c->tau, c->need, c->pr.type, c->pr.opt);
}

static cf_status lt_init(lt_ctx *c, const cf_table *d, const cf_validate_setup *s,
                         const cf_fit_options *opt, cf_spring_type type, double need,
                         cf_error *err)
{
    memset(c, 0, sizeof *c);
    c->d = d;
    c->s = s;
    c->need = need;
    return cf_cell_problem_init(&c->pr, d, opt, type, lt_curve, lt_A_max, c, err);
}

static void lt_free(lt_ctx *c)
{
    cf_cell_problem_free(&c->pr);
}

void cf_tail_cell_box(const cf_fit_options *opt, cf_spring_type type, double xmax, double lb[3],
                      double ub[3])
{
    lb[0] = log(fmax(CF_IDENT_RHO_LO, opt->rho_min));
    lb[1] = B_LO_SHARE * xmax;
    lb[2] = Q_LO;
    ub[0] = log(cf_ident_rho_hi(type, opt->index_max));
    ub[1] = 1 - 1e-6;
    ub[2] = Q_HI;
}

void cf_tail_cell_quantities(const double z[3], double A, double v[4])
{
    v[0] = exp(z[0]);
    v[1] = z[1];
    v[2] = A;
    v[3] = tau_of(z[1], z[2]);
}

double cf_tail_cell_profile(const cf_tail_cell *tc, const double z[3], double *A)
{
    *tc->tau = tau_of(z[1], z[2]);
    const double f = cf_cell_rss(tc->pr, exp(z[0]), z[1], A);
    return f < CF_LSQ_HUGE_OBJ ? f / tc->pr->ynorm : CF_LSQ_HUGE_OBJ;
}

static double lt_objective(unsigned nz, const double *z, double *grad, void *data)
{
    (void)nz;
    (void)grad;
    double A;
    return cf_tail_cell_profile(data, z, &A);
}

int cf_tail_cell_residuals(void *ctx, const double v[4], gsl_vector *f)
{
    const cf_tail_cell *tc = ctx;
    cf_cell_problem *pr = tc->pr;
    if (!(v[1] > 0 && v[1] * (1 + v[3]) < 1 && v[0] > 0 && v[0] <= 1))
        return GSL_EDOM;
    *tc->tau = v[3];
    pr->evals++;
    if (pr->curve(pr->ctx, v[0], v[1], pr->g) != 0)
        return GSL_EDOM;
    for (size_t i = 0; i < pr->n; i++)
        gsl_vector_set(f, i, pr->sw[i] * (v[2] * pr->g[i] - pr->y[i]));
    return GSL_SUCCESS;
}

/* One BOBYQA run from z (in and out); the objective at the end. */
static double bobyqa(const cf_tail_cell *tc, double *z, const double *lb, const double *ub)
{
    double f, step[3] = {0.05, 0.02 * (ub[1] - lb[1]), 0.05};
    nlopt_result r = cf_cell_search(tc->pr, NLOPT_LN_BOBYQA, 3, lb, ub, step, XTOL_REL,
                                    MAX_CURVES, lt_objective, (void *)tc, z, &f);
    if (!(r > 0 || r == NLOPT_ROUNDOFF_LIMITED) || !isfinite(z[0]) || !isfinite(z[1]) ||
        !isfinite(z[2]))
        return CF_LSQ_HUGE_OBJ;
    return f;
}

double cf_tail_cell_search(const cf_tail_cell *tc, const cf_ident *start, const double lb[3],
                           const double ub[3], double zb[3])
{
    static const double grid_rho[3] = {0.1, 0.35, 0.7}, grid_e[2] = {0.15, 0.6};
    static const double start_q[2] = {0.01, 0.2};
    double best = CF_LSQ_HUGE_OBJ;
    for (int k = -2; k < 6; k++) {
        double z[3];
        if (k < 0) {
            z[0] = log(start->rho);
            z[1] = start->solid;
            z[2] = start_q[k + 2];
        } else {
            z[0] = log(grid_rho[k % 3]);
            z[1] = lb[1] + grid_e[k / 3] * (ub[1] - lb[1]);
            z[2] = 0.2;
        }
        for (int j = 0; j < 3; j++)
            z[j] = isfinite(z[j]) ? fmin(fmax(z[j], lb[j]), ub[j]) : 0.5 * (lb[j] + ub[j]);
        const double f = bobyqa(tc, z, lb, ub);
        if (f < best) {
            best = f;
            memcpy(zb, z, 3 * sizeof z[0]);
        }
    }
    return best;
}

unsigned cf_tail_cell_held(const cf_fit_options *opt, const double lb[3], const double ub[3],
                           const double zb[3], cf_spring_type type)
{
    const double tol = 1e-6;
    unsigned held = 0;
    if (zb[0] <= lb[0] + tol)
        held |= opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS;
    if (zb[0] >= ub[0] - tol)
        held |= type == CF_TELESCOPING ? CF_C_TYPE : CF_C_DIAMETERS;
    if (zb[1] <= lb[1] * (1 + tol) || zb[2] >= ub[2] * (1 - tol) || zb[2] <= lb[2] * (1 + tol))
        held |= CF_C_BOUNDS;
    return held;
}

int cf_tail_cell_intervals(const cf_tail_cell *tc, const cf_fit_options *opt,
                           cf_spring_type type, double need, const double lb[3],
                           const double ub[3], size_t rows, double rss, double ynorm,
                           const double v[4], cf_fit_result *res)
{
    /* as fitted to the spring (tail.h): the profiles on tc's rows from their own RSS at v, the
    ** threshold the whole problem's */
    gsl_vector *fv = gsl_vector_alloc(tc->pr->n);
    if (!fv)
        return -1;
    double rss0 = CF_LSQ_HUGE_OBJ;
    if (cf_tail_cell_residuals((void *)tc, v, fv) == GSL_SUCCESS) {
        rss0 = 0;
        for (size_t i = 0; i < fv->size; i++)
            rss0 += gsl_vector_get(fv, i) * gsl_vector_get(fv, i);
        rss0 = isfinite(rss0) ? rss0 : CF_LSQ_HUGE_OBJ;
    }
    gsl_vector_free(fv);
    const cf_tail_profile tp = {cf_tail_cell_residuals, (void *)tc, tc->pr->n, tc->pr->ynorm,
                                opt, type, 0, need, exp(lb[0]), exp(ub[0]), lb[1], ub[1]};
    return cf_tail_intervals(&tp, v, rss0,
                             rss0 + cf_profile_limit_np(rows, 4, rss, ynorm) - rss, res);
}

/* The search through the cell (on search's rows: a long table's subsample) from the conical
** fit plain, and its result on every row (c): the quantities, their errors and, where the errors
** say nothing, their profile intervals. */
static cf_status lt_search(lt_ctx *c, lt_ctx *search, const cf_table *d, const cf_table *reach,
                           const cf_fit_options *opt, const cf_fit_result *plain,
                           const double lb[3], const double ub[3], double need,
                           cf_fit_result *res, cf_through_msm *t, cf_error *err)
{
    cf_status st;
    double zb[3] = {0, 0, 0}, A = 0;
    const cf_tail_cell tsearch = {&search->pr, &search->tau}, tc = {&c->pr, &c->tau};
    const double best = cf_tail_cell_search(&tsearch, &plain->ident, lb, ub, zb);
    if (search->pr.oom)
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory in the lattice fit's optimiser (NLopt)");
    const double f = best < CF_LSQ_HUGE_OBJ ? cf_tail_cell_profile(&tc, zb, &A) : CF_LSQ_HUGE_OBJ;
    if (!(f < CF_LSQ_HUGE_OBJ) || !(A > 0))
        return cf_error_set(err, CF_E_DATA,
                            "%s: no conical-tail law fits the table through the lattice",
                            d->path);
    double v[4];
    cf_tail_cell_quantities(zb, A, v);
    double se[4], corr[4][4], cov_Bt;
    const long before = c->pr.evals;
    cf_tail_errors(cf_tail_cell_residuals, (void *)&tc, d->count, v, FD_STEP, f * c->pr.ynorm, se,
                   corr, &cov_Bt);
    t->uncertainty_curves = c->pr.evals - before;
    if ((st = cf_tail_result(reach, opt, plain->type, v, se, corr, cov_Bt, res, err)) != CF_OK)
        return st;
    res->held |= cf_tail_cell_held(opt, lb, ub, zb, plain->type);
    /* profile intervals where the errors say nothing, through the cell on the search's rows (a
    ** long table's subsample) against the whole table's threshold */
    const long before_p = search->pr.evals;
    const int pst = cf_tail_cell_intervals(&tsearch, opt, plain->type, need, lb, ub, d->count,
                                           f * c->pr.ynorm, c->pr.ynorm, v, res);
    t->uncertainty_curves += search->pr.evals - before_p;
    if (pst < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the profiles of %zu rows",
                            d->count);
    return CF_OK;
}

cf_status cf_lattice_fit_tail(const cf_table *d, const cf_fit_options *opt,
                              const cf_validate_setup *s, const cf_fit_result *plain,
                              cf_fit_result *res, cf_through_msm *t, cf_error *err)
{
    CF_GSL_GUARD;
    const double t0 = cf_clock_s();
    memset(res, 0, sizeof *res);
    memset(t, 0, sizeof *t);
    t->ident_before = plain->ident;
    t->rmse_before = plain->rmse;
    if (cf_table_is_force(d))
        return cf_error_set(err, CF_E_DATA,
                            "the fit through the lattice needs a stress-strain table");
    if (d->count < 6)
        return cf_error_set(err, CF_E_DATA,
                            "the conical-tail law needs at least 6 rows (the table has %zu)",
                            d->count);
    lt_ctx c, cs;
    memset(&c, 0, sizeof c);
    memset(&cs, 0, sizeof cs);
    cf_table sub;
    memset(&sub, 0, sizeof sub);
    double *spring_x = malloc(sizeof(double) * d->count);
    if (!spring_x)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", d->count);
    const cf_table reach = cf_lattice_reach(d, spring_x);
    const double xmax = cf_lsq_xmax(&reach), need = xmax * (1 + CF_FIT_TRAVEL_MARGIN);
    double lb[3], ub[3];
    cf_tail_cell_box(opt, plain->type, xmax, lb, ub);
    cf_status st = lt_init(&c, d, s, opt, plain->type, need, err);
    if (st != CF_OK)
        goto out;
    if (!(need < 1) || !(c.pr.ynorm > 0)) {
        st = cf_error_set(err, CF_E_DATA,
                          "largest strain %g: no spring reaches it, nothing to optimise", xmax);
        goto out;
    }
    lt_ctx *search = &c;
    if (d->count > CF_LATTICE_FIT_FULL_ROWS) {
        if ((st = cf_subsample(d, CF_SUBSAMPLE_ROWS, &sub, err)) != CF_OK ||
            (st = lt_init(&cs, &sub, s, opt, plain->type, need, err)) != CF_OK)
            goto out;
        search = &cs;
    }
    t->search_rows = search->d->count;
    if ((st = lt_search(&c, search, d, &reach, opt, plain, lb, ub, need, res, t, err)) != CF_OK)
        goto out;
    /* the target's numbers: the cell's curve of the placed spring */
    if ((st = cf_lattice_curve(&res->params, s, d, 0, c.pr.g, NULL, NULL, NULL, err)) != CF_OK)
        goto out;
    double law[3]; /* the single spring's own RMSE, largest |error|, R^2 */
    cf_lattice_take_quality(d, c.pr.g, c.pr.sw, c.pr.ynorm, res, law);
    t->law_rmse = law[0];
    t->law_max_abs_error = law[1];
    t->law_r2 = law[2];
    t->ident_after = res->ident;
    t->cell_rmse = res->rmse;
    t->improved = 1;
    t->done = 1;
    res->optimizer = "bobyqa";
out:
    if (!t->done)
        snprintf(t->note, sizeof t->note, "%s",
                 err && err->msg[0] ? err->msg : "the search found no spring to place");
    t->evaluations = c.pr.evals + cs.pr.evals;
    res->evaluations = t->evaluations;
    res->evaluations_full = c.pr.evals;
    lt_free(&cs);
    lt_free(&c);
    cf_table_free(&sub);
    free(spring_x);
    t->wall_time_s = cf_clock_s() - t0;
    res->wall_time_s = t->wall_time_s;
    return st;
}
