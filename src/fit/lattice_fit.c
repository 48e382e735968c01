/*
** The fit through the lattice: the identifiable quantities searched through the homogenised cell,
** then the placement of the design parameters (see lattice_fit.h).
*/
#include "conifit/lattice_fit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <nlopt.h>

#include "conifit/cell.h"
#include "conifit/family.h"
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
    const cf_fit_options *opt;
    cf_spring_type type;
    double *sw;     /* residual weights */
    double ynorm;   /* weighted sum of y^2 */
    double *curve;  /* scratch, count values */
    long evals;
} tm_ctx;

/* The context of the searches on a long table: its subsample (into *sub) with its own weights
** and scratch. */
static cf_status search_ctx(const tm_ctx *c, cf_table *sub, tm_ctx *cs, cf_error *err)
{
    cf_status st = cf_subsample(c->d, CF_SUBSAMPLE_ROWS, sub, err);
    if (st != CF_OK)
        return st;
    cs->d = sub;
    cs->sw = malloc(sizeof(double) * sub->count);
    cs->curve = malloc(sizeof(double) * sub->count);
    if (!cs->sw || !cs->curve)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", sub->count);
    cs->ynorm = cf_lsq_weights(sub, c->opt->relative, cs->sw);
    return CF_OK;
}

/* The objective at (log rho, s/H) with the stress scale solved in closed form: at a prescribed
** displacement the static equilibrium does not depend on the scale of the springs' forces (every
** force is F_C times a function of u/s), so the lattice's stress is A times its stress at A = 1
** and the best A is a weighted linear least-squares solution. *A_out receives it. */
static double tm_profile(tm_ctx *c, const double *z, double *A_out)
{
    const cf_ident q = {.rho = exp(z[0]), .solid = z[1], .scale = 1.0};
    cf_spring p = cf_ident_member(&q);
    c->evals++;
    *A_out = 0;
    /* the fitter's design limits in this space: where no spring can be placed, or the scale a
    ** placeable spring carries at most */
    double A_max;
    if (cf_fit_ident_limit(c->opt, c->type, exp(z[0]), z[1], &A_max) > 0)
        return CF_LSQ_HUGE_OBJ;
    if (cf_lattice_curve(&p, c->s, c->d, 0, c->curve, NULL, NULL, NULL, NULL) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    double gy = 0, gg = 0;
    for (size_t i = 0; i < c->d->count; i++) {
        double w = c->sw[i] * c->sw[i];
        gy += w * c->curve[i] * c->d->y[i];
        gg += w * c->curve[i] * c->curve[i];
    }
    double A = fmin(gy / gg, A_max);
    if (!(A > 0) || !isfinite(A))
        return CF_LSQ_HUGE_OBJ;
    double sum = 0;
    for (size_t i = 0; i < c->d->count; i++) {
        double r = c->sw[i] * (A * c->curve[i] - c->d->y[i]);
        sum += r * r;
    }
    *A_out = A;
    return isfinite(sum) ? sum / c->ynorm : CF_LSQ_HUGE_OBJ;
}

static double tm_objective(unsigned nz, const double *z, double *grad, void *data)
{
    (void)nz;
    (void)grad;
    double A;
    return tm_profile(data, z, &A);
}

/* Cell RMSE (MPa) of spring p against the table; HUGE when the cell cannot run it. */
static double cell_rmse(const cf_spring *p, tm_ctx *c)
{
    if (cf_lattice_curve(p, c->s, c->d, 0, c->curve, NULL, NULL, NULL, NULL) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    return cf_lsq_quality_of(c->d, c->curve).rmse;
}

/* One BOBYQA run from z (in and out) within [lb, ub]; returns the objective at the end. */
static double bobyqa(tm_ctx *c, double *z, const double *lb, const double *ub)
{
    double f = CF_LSQ_HUGE_OBJ;
    nlopt_opt o = nlopt_create(NLOPT_LN_BOBYQA, 2);
    if (!o)
        return f;
    double step[2] = {0.05, 0.02 * (ub[1] - lb[1])};
    nlopt_set_lower_bounds(o, lb);
    nlopt_set_upper_bounds(o, ub);
    nlopt_set_min_objective(o, tm_objective, c);
    nlopt_set_initial_step(o, step);
    nlopt_set_xtol_rel(o, XTOL_REL);
    nlopt_set_maxeval(o, MAX_CURVES);
    nlopt_result r = nlopt_optimize(o, z, &f);
    nlopt_destroy(o);
    if (!(r > 0 || r == NLOPT_ROUNDOFF_LIMITED) || !isfinite(z[0]) || !isfinite(z[1]))
        return CF_LSQ_HUGE_OBJ;
    return f;
}

/* The fit through the lattice: the springs' reach, the starts, the search on the homogenised
** cell and the placement, as marked below. Kept as one function because the stages share the
** cell's setup and the result. */
cf_status cf_lattice_fit(const cf_table *d, const cf_fit_options *opt, const cf_validate_setup *s,
                         cf_fit_result *res, cf_through_msm *t, cf_error *err)
{
    const double t0 = cf_clock_s();
    memset(t, 0, sizeof *t);
    t->ident_before = cf_ident_of(&res->params, 0);
    t->ident_after = t->ident_before;
    tm_ctx c = {d, s, opt, res->type, NULL, 0, NULL, 0}, cs = {NULL, s, opt, res->type, NULL, 0,
                                                               NULL, 0};
    cf_table sub;
    memset(&sub, 0, sizeof sub);
    c.sw = malloc(sizeof(double) * (d->count ? d->count : 1));
    c.curve = malloc(sizeof(double) * (d->count ? d->count : 1));
    double *spring_x = malloc(sizeof(double) * (d->count ? d->count : 1));
    cf_status st = CF_OK;
    if (!c.sw || !c.curve || !spring_x) {
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
    cf_table reach = *d;
    reach.x = spring_x;
    for (size_t i = 0; i < d->count; i++)
        spring_x[i] = copysign(cf_cell_spring_strain(d->mode, d->x[i]), d->x[i]);
    const double xmax = cf_lsq_xmax(&reach);
    c.ynorm = cf_lsq_weights(d, opt->relative, c.sw);
    t->rmse_before = cell_rmse(&res->params, &c);
    double rho_hi = cf_ident_rho_hi(res->type, opt->index_max);
    double lb[2] = {log(fmax(CF_IDENT_RHO_LO, opt->rho_min)),
                    xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9)};
    double ub[2] = {log(rho_hi), 1 - 1e-9};
    if (!(lb[1] < ub[1]) || !(c.ynorm > 0)) {
        st = cf_error_set(err, CF_E_DATA,
                          "largest strain %g: no spring reaches it, nothing to optimise", xmax);
        goto out;
    }
    /* a long table is searched on its subsample */
    tm_ctx *search = &c;
    if (d->count > CF_LATTICE_FIT_FULL_ROWS) {
        if ((st = search_ctx(&c, &sub, &cs, err)) != CF_OK)
            goto out;
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
    double A = 0;
    int ok = best < CF_LSQ_HUGE_OBJ && tm_profile(&c, zb, &A) < CF_LSQ_HUGE_OBJ && A > 0;
    const cf_ident ident = {.rho = exp(zb[0]), .solid = zb[1], .scale = A};
    /* Place the design parameters as the ordinary fit does; keep them when the cell fits better. */
    cf_fit_result placed;
    cf_error e = {0};
    double after = CF_LSQ_HUGE_OBJ;
    if (ok && cf_fit_place(&reach, opt, res->type, &ident, &placed, &e) == CF_OK)
        after = cell_rmse(&placed.params, &c);
    if (after < t->rmse_before) {
        t->ident_after = cf_ident_of(&placed.params, 0);
        placed.evaluations += res->evaluations;
        placed.wall_time_s += res->wall_time_s;
        *res = placed;
        t->improved = 1;
    }
    t->cell_rmse = t->improved ? after : t->rmse_before;
    t->done = 1;
out:
    if (!t->done)
        snprintf(t->note, sizeof t->note, "%s",
                 err && err->msg[0] ? err->msg : "the search found no spring to place");
    t->evaluations = c.evals + cs.evals;
    free(cs.sw);
    free(cs.curve);
    cf_table_free(&sub);
    t->wall_time_s = cf_clock_s() - t0;
    free(c.sw);
    free(c.curve);
    free(spring_x);
    return st;
}
