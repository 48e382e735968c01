/*
** The fit through the lattice: the identifiable quantities searched through the homogenised cell,
** then the placement of the design parameters (see lattice_fit.h).
*/
#include "fit/lattice_fit.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <nlopt.h>

#include "model/cell.h"
#include "model/family.h"
#include "fit/cell_problem.h"
#include "fit/clock.h"
#include "fit/lattice_curve.h"
#include "fit/lsq.h"
#include "fit/subsample.h"

/* BOBYQA stops when a step changes every variable by less than this, relative. The validation
** error is reported to 4 digits; 1e-6 in the variables is far below what changes them. */
#define XTOL_REL 1e-6
/* Lattice curves allowed to the optimiser: each is a few milliseconds on the default 3 x 3 x 3
** lattice; BOBYQA on the two remaining variables typically converges in a few dozen. */
#define MAX_CURVES 400

typedef struct tm_ctx {
    const cf_table *d;
    const cf_validate_setup *s;
    cf_cell_problem pr; /* the table's rows, weights and scratch */
} tm_ctx;

/* The cell's curve of the member of the family at (rho, B), stress scale 1. */
static int tm_curve(void *ctx, double rho, double B, double *out)
{
    const tm_ctx *c = ctx;
    const cf_ident q = {.rho = rho, .solid = B, .scale = 1.0};
    cf_spring p = cf_ident_member(&q);
    return cf_lattice_curve(&p, c->s, c->d, 0, out, NULL, NULL, NULL, NULL) != CF_OK;
}

/* The context of table d with its weights and scratch (freed by tm_free). */
static cf_status tm_init(tm_ctx *c, const cf_table *d, const cf_validate_setup *s,
                         const cf_fit_options *opt, cf_spring_type type, cf_error *err)
{
    memset(c, 0, sizeof *c);
    c->d = d;
    c->s = s;
    return cf_cell_problem_init(&c->pr, d, opt, type, tm_curve, NULL, c, err);
}

static void tm_free(tm_ctx *c)
{
    cf_cell_problem_free(&c->pr);
}

/* The objective at (log rho, s/H) with the stress scale solved in closed form: at a prescribed
** displacement the static equilibrium does not depend on the scale of the springs' forces (every
** force is F_C times a function of u/s), so the lattice's stress is A times its stress at A = 1
** and the best A is a weighted linear least-squares solution (cell_problem.h). *A_out receives
** it. */
static double tm_profile(tm_ctx *c, const double *z, double *A_out)
{
    c->pr.ctx = c;
    double f = cf_cell_rss(&c->pr, exp(z[0]), z[1], A_out);
    return f < CF_LSQ_HUGE_OBJ ? f / c->pr.ynorm : CF_LSQ_HUGE_OBJ;
}

static double tm_objective(unsigned nz, const double *z, double *grad, void *data)
{
    (void)nz;
    (void)grad;
    double A;
    return tm_profile(data, z, &A);
}

/* Cell RMSE (MPa) of spring p against the table; HUGE when the cell cannot run it. The cell's
** curve is left in c->pr.g. */
static double cell_rmse(const cf_spring *p, tm_ctx *c)
{
    if (cf_lattice_curve(p, c->s, c->d, 0, c->pr.g, NULL, NULL, NULL, NULL) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    return cf_lsq_quality_of(c->d, c->pr.g).rmse;
}

/* One BOBYQA run from z (in and out) within [lb, ub]; returns the objective at the end. */
static double bobyqa(tm_ctx *c, double *z, const double *lb, const double *ub)
{
    double f, step[2] = {0.05, 0.02 * (ub[1] - lb[1])};
    nlopt_result r = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, 2, lb, ub, step, XTOL_REL,
                                    MAX_CURVES, tm_objective, c, z, &f);
    if (!(r > 0 || r == NLOPT_ROUNDOFF_LIMITED) || !isfinite(z[0]) || !isfinite(z[1]))
        return CF_LSQ_HUGE_OBJ;
    return f;
}

/* The fit's headline numbers become the target's: the cell's curve of the reported spring
** against the table (c->pr.g holds it), with the single spring's own figures kept in t->law_*
** where they mean something (a uniaxial table), and the uncertainty through the cell. */
static cf_status take_target(tm_ctx *c, tm_ctx *search, cf_fit_result *res, cf_through_msm *t,
                             cf_error *err)
{
    double law[3]; /* the single spring's own RMSE, largest |error|, R^2 */
    cf_lattice_take_quality(c->d, c->pr.g, c->pr.sw, c->pr.ynorm, res, law);
    t->law_rmse = law[0];
    t->law_max_abs_error = law[1];
    t->law_r2 = law[2];
    res->ident = cf_ident_of(&res->params, 0);
    c->pr.ctx = c;
    search->pr.ctx = search;
    const long before = c->pr.evals + (search != c ? search->pr.evals : 0);
    cf_status st = cf_cell_uncertainty(&c->pr, &search->pr, res, err);
    t->uncertainty_curves = c->pr.evals + (search != c ? search->pr.evals : 0) - before;
    return st;
}

/* The fit through the lattice: the springs' reach, the starts, the search on the homogenised
** cell, the placement and the target's numbers, as marked below. Kept as one function because
** the stages share the cell's setup and the result. */
cf_status cf_lattice_fit(const cf_table *d, const cf_fit_options *opt, const cf_validate_setup *s,
                         cf_fit_result *res, cf_through_msm *t, cf_error *err)
{
    CF_GSL_GUARD;
    const double t0 = cf_clock_s();
    memset(t, 0, sizeof *t);
    t->ident_before = cf_ident_of(&res->params, 0);
    t->ident_after = t->ident_before;
    tm_ctx c, cs;
    memset(&cs, 0, sizeof cs);
    cf_table sub;
    memset(&sub, 0, sizeof sub);
    double *spring_x = malloc(sizeof(double) * (d->count ? d->count : 1));
    cf_status st = tm_init(&c, d, s, opt, res->type, err);
    if (st != CF_OK)
        goto out;
    if (!spring_x) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", d->count);
        goto out;
    }
    if (cf_table_is_force(d)) {
        st = cf_error_set(err, CF_E_DATA,
                          "the fit through the lattice needs a stress-strain table; a "
                          "force-displacement table is one spring's curve");
        goto out;
    }
    /* The springs' reach: in shear the springs strain about half the table's strain, so the
    ** bound on s/H and the placement see a copy of the table whose x is the largest spring
    ** strain at each row (the table itself for the other modes). */
    cf_table reach = cf_lattice_reach(d, spring_x);
    const double xmax = cf_lsq_xmax(&reach);
    t->rmse_before = cell_rmse(&res->params, &c);
    double rho_hi = cf_ident_rho_hi(res->type, opt->index_max);
    double lb[2] = {log(fmax(CF_IDENT_RHO_LO, opt->rho_min)),
                    xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9)};
    double ub[2] = {log(rho_hi), 1 - 1e-9};
    if (!(lb[1] < ub[1]) || !(c.pr.ynorm > 0)) {
        st = cf_error_set(err, CF_E_DATA,
                          "largest strain %g: no spring reaches it, nothing to optimise", xmax);
        goto out;
    }
    memcpy(c.pr.lb, lb, sizeof lb);
    memcpy(c.pr.ub, ub, sizeof ub);
    /* a long table is searched on its subsample */
    tm_ctx *search = &c;
    if (d->count > CF_LATTICE_FIT_FULL_ROWS) {
        if ((st = cf_subsample(d, CF_SUBSAMPLE_ROWS, &sub, err)) != CF_OK ||
            (st = tm_init(&cs, &sub, s, opt, res->type, err)) != CF_OK)
            goto out;
        memcpy(cs.pr.lb, lb, sizeof lb);
        memcpy(cs.pr.ub, ub, sizeof ub);
        search = &cs;
    }
    t->search_rows = search->d->count;
    /* Starts: the ordinary fit's quantities and a coarse grid over (rho, s/H); the cell makes a
    ** curve cost microseconds, so several local searches are cheap and the best is kept. */
    double best = CF_LSQ_HUGE_OBJ, zb[2] = {0, 0};
    const double grid_rho[3] = {0.1, 0.35, 0.7}, grid_e[2] = {0.15, 0.6};
    for (int k = -1; k < 6; k++) {
        double z[2];
        if (k < 0) {
            z[0] = log(t->ident_before.rho);
            z[1] = t->ident_before.solid;
        } else {
            z[0] = log(grid_rho[k % 3]);
            z[1] = lb[1] + grid_e[k / 3] * (ub[1] - lb[1]);
        }
        for (int j = 0; j < 2; j++)
            z[j] = fmin(fmax(z[j], lb[j]), ub[j]);
        double f = bobyqa(search, z, lb, ub);
        if (f < best) {
            best = f;
            zb[0] = z[0], zb[1] = z[1];
        }
    }
    if (search->pr.oom) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory in the lattice fit's optimiser "
                                              "(NLopt)");
        goto out;
    }
    double A = 0;
    int ok = best < CF_LSQ_HUGE_OBJ && tm_profile(&c, zb, &A) < CF_LSQ_HUGE_OBJ && A > 0;
    const cf_ident ident = {.rho = exp(zb[0]), .solid = zb[1], .scale = A};
    /* Place the design parameters as the ordinary fit does; keep them when the cell fits better. */
    cf_fit_result placed;
    cf_error e = {0};
    double after = CF_LSQ_HUGE_OBJ;
    cf_status pst = ok ? cf_fit_place(&reach, opt, res->type, &ident, &placed, &e) : CF_E_DATA;
    if (pst == CF_E_INTERNAL) {
        st = cf_error_set(err, CF_E_INTERNAL, "%s", e.msg);
        goto out;
    }
    if (pst == CF_OK)
        after = cell_rmse(&placed.params, &c);
    if (after < t->rmse_before) {
        t->ident_after = cf_ident_of(&placed.params, 0);
        placed.evaluations += res->evaluations;
        placed.wall_time_s += res->wall_time_s;
        *res = placed;
        t->improved = 1;
    }
    t->cell_rmse = t->improved ? after : t->rmse_before;
    /* the target's numbers: the cell's curve of the reported spring */
    if (cell_rmse(&res->params, &c) < CF_LSQ_HUGE_OBJ)
        st = take_target(&c, search, res, t, err);
    t->done = st == CF_OK;
out:
    if (!t->done)
        snprintf(t->note, sizeof t->note, "%s",
                 err && err->msg[0] ? err->msg : "the search found no spring to place");
    t->evaluations = c.pr.evals + cs.pr.evals;
    tm_free(&cs);
    tm_free(&c);
    cf_table_free(&sub);
    t->wall_time_s = cf_clock_s() - t0;
    free(spring_x);
    return st;
}
