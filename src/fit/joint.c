/*
** The joint fit of several tables through the lattice (see joint.h): the context, the conical and
** tailed laws' searches, the run and the public calls. The double-acting element's search is in
** joint_pair.c, the full lattice's stability and each table's verification in joint_stable.c,
** the curves they all evaluate in joint_curve.c.
*/
#include "fit/joint.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <nlopt.h>

#include "fit/baseline.h"
#include "model/cell.h"
#include "model/family.h"
#include "fit/cell_problem.h"
#include "fit/clock.h"
#include "fit/joint_ctx.h"
#include "fit/lsq.h"
#include "fit/tail.h"
#include "fit/tail_cell.h"
#include "model/mode.h"

/* BOBYQA's curves per start of the conical law's search */
#define MAX_EVALS 600

/* The tailed law's cap on the stress scale at (rho, B) and the context's tau (tail_cell.h). */
static double joint_A_max(void *ctx, double rho, double B)
{
    const jctx *c = ctx;
    return cf_tail_cell_A_max(rho, B, c->tau, c->need, c->type, c->opt);
}

/* Objective at z = (ln rho, s/H [, ln q]) with the stress scale in closed form; *A_out. */
static double profile(jctx *c, const double *z, double *A_out)
{
    if (c->fit_weights)
        cf_joint_weights_of(exp(z[2]), c->weight);
    return cf_cell_rss(&c->pr, exp(z[0]), z[1], A_out);
}

/* The conical search's objective; with the context's stab_on a point that would lower the best
** objective of the current search (stab_best) counts only when its full lattice is stable over
** the uniaxial tables (cf_joint_stable_at), as in the pair's search. */
static double objective(unsigned nz, const double *z, double *grad, void *data)
{
    (void)nz;
    (void)grad;
    jctx *c = data;
    double A;
    const double f = profile(c, z, &A);
    if (c->stab_on && f < c->stab_best) {
        if (!cf_joint_stable_at(c, exp(z[0]), z[1]))
            return CF_LSQ_HUGE_OBJ;
        c->stab_best = f;
    }
    return f;
}

/* 1 when the conical law's point z (its weights set by profile) has full lattices stable over the
** uniaxial tables. */
static int conical_stable(jctx *c, const double *z)
{
    double A;
    profile(c, z, &A);
    return cf_joint_stable_at(c, exp(z[0]), z[1]);
}

/* The searches in stable lattices, when the best point zb (objective *best) buckles: from the
** stable point nearest it on the segment to each of the (up to CONICAL_STABLE_RESTARTS) best
** stable ends, BOBYQA under the stability check; the best of them into zb and *best. None stable:
** zb stays (the verification reports the loss). */
#define CONICAL_STABLE_RESTARTS 8
#define CONICAL_STABLE_BISECT 12
static void conical_keep_stable(jctx *c, int nz, const double *lb, const double *ub,
                                double ends[][3], double *fends, int nends, double zb[3],
                                double *best, cf_joint_result *r)
{
    if (!(*best < CF_LSQ_HUGE_OBJ))
        return;
    if (conical_stable(c, zb)) {
        r->stable_ends = 1;
        return;
    }
    double sb = CF_LSQ_HUGE_OBJ, zs[3] = {0, 0, 0};
    for (int tries = 0; tries < CONICAL_STABLE_RESTARTS; tries++) {
        int pick = -1;
        for (int i = 0; i < nends; i++)
            if (fends[i] >= 0 && fends[i] < CF_LSQ_HUGE_OBJ &&
                (pick < 0 || fends[i] < fends[pick]))
                pick = i;
        if (pick < 0)
            break;
        fends[pick] = CF_LSQ_HUGE_OBJ; /* tried */
        int same = 0; /* an end the search has already restarted from (within 1e-3 of the box) */
        for (int t = 0; t < nends && !same; t++) {
            if (t == pick || fends[t] != -1.0)
                continue;
            same = 1;
            for (int j = 0; j < nz && same; j++)
                same = fabs(ends[pick][j] - ends[t][j]) <= 1e-3 * (ub[j] - lb[j]);
        }
        if (same || !conical_stable(c, ends[pick])) {
            tries--;
            continue;
        }
        fends[pick] = -1.0; /* restarted from */
        r->stable_ends++;
        r->restarts++;
        double z[3] = {0, 0, 0}, lo = 0, hi = 1, f = CF_LSQ_HUGE_OBJ;
        for (int b = 0; b < CONICAL_STABLE_BISECT; b++) {
            const double mid = 0.5 * (lo + hi);
            for (int j = 0; j < nz; j++)
                z[j] = zb[j] + mid * (ends[pick][j] - zb[j]);
            if (conical_stable(c, z))
                hi = mid;
            else
                lo = mid;
        }
        for (int j = 0; j < nz; j++)
            z[j] = zb[j] + hi * (ends[pick][j] - zb[j]);
        double step[3] = {0.1, 0.05 * (ub[1] - lb[1]), cf_joint_q_step(lb[2], ub[2], 0)};
        c->stab_on = 1;
        c->stab_best = CF_LSQ_HUGE_OBJ;
        nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)nz, lb, ub, step,
                                          XTOL_REL, MAX_EVALS, objective, c, z, &f);
        c->stab_on = 0;
        if ((res > 0 || res == NLOPT_ROUNDOFF_LIMITED || res == NLOPT_MAXEVAL_REACHED) &&
            f < sb && conical_stable(c, z)) {
            sb = f;
            memcpy(zs, z, sizeof zs);
        }
    }
    if (sb < CF_LSQ_HUGE_OBJ) {
        *best = sb;
        memcpy(zb, zs, sizeof zs);
    }
}

int cf_joint_stable(const cf_joint_result *r)
{
    for (size_t k = 0; k < r->ntables && k < CF_JOINT_MAX; k++)
        if (r->tab[k].stability_checked && !r->tab[k].stable_in_range)
            return 0;
    return 1;
}

int cf_joint_stable_at_rest(const cf_joint_result *r)
{
    for (size_t k = 0; k < r->ntables && k < CF_JOINT_MAX; k++)
        if (r->tab[k].stability_checked && r->tab[k].unstable_at_rest)
            return 0;
    return 1;
}

int cf_joint_elliptic(const cf_joint_result *r)
{
    for (size_t k = 0; k < r->ntables && k < CF_JOINT_MAX; k++)
        if (r->tab[k].elliptic_checked && !r->tab[k].elliptic_in_range)
            return 0;
    return 1;
}

/* Buildable, stable at rest and over every table's range. */
static int within_targets(const cf_joint_result *r)
{
    return r->fit.feasible && cf_joint_stable(r) && cf_joint_stable_at_rest(r);
}

int cf_joint_elliptic_wins(const cf_joint_result *r2, const cf_joint_result *r1)
{
    return within_targets(r1) && within_targets(r2) && cf_joint_elliptic(r2) &&
           !cf_joint_elliptic(r1) && r2->objective <= CF_JOINT_ELLIPTIC_SLACK * r1->objective;
}

void cf_joint_free(cf_joint_result *r)
{
    if (!r)
        return;
    for (size_t k = 0; k < CF_JOINT_MAX; k++) {
        free(r->tab[k].lattice_MPa);
        r->tab[k].lattice_MPa = NULL;
    }
}

/* The conical law's search over (rho, s/H [, the weight ratio]) from a grid of starts, every
** table's curve through the cell, and the spring placed from the best; the reach bounds s/H. */
static cf_status search_conical(jctx *c, const cf_table *reach, double xmax, cf_joint_result *r,
                                cf_error *err)
{
    const cf_fit_options *opt = c->opt;
    const int nz = c->fit_weights ? 3 : 2;
    double lb[3] = {log(fmax(CF_IDENT_RHO_LO, opt->rho_min)),
                    xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9), 0};
    double ub[3] = {log(cf_ident_rho_hi(c->type, opt->index_max)), 1 - 1e-9, 0};
    cf_joint_q_box(opt, &lb[2], &ub[2]);
    if (!(lb[1] < ub[1]))
        return cf_error_set(err, CF_E_DATA, "the springs must reach a strain of %g: no spring "
                                            "does", xmax);
    memcpy(c->pr.lb, lb, sizeof c->pr.lb);
    memcpy(c->pr.ub, ub, sizeof c->pr.ub);
    double best = CF_LSQ_HUGE_OBJ, zb[3] = {0, 0, 0}, ends[18][3], fends[18];
    int nends = 0;
    c->stab_on = 0;
    const double grid_rho[3] = {0.1, 0.35, 0.7}, grid_e[3] = {0.1, 0.4, 0.8};
    const double q_iso = 0.2708 / 0.6085, grid_q[2] = {q_iso, 1.0};
    for (int gq = 0; gq < (c->fit_weights ? 2 : 1); gq++)
        for (int g = 0; g < 9; g++) {
            double z[3] = {log(grid_rho[g % 3]), lb[1] + grid_e[g / 3] * (ub[1] - lb[1]),
                           log(grid_q[gq])};
            for (int j = 0; j < nz; j++)
                z[j] = fmin(fmax(z[j], lb[j]), ub[j]);
            double step[3] = {0.1, 0.05 * (ub[1] - lb[1]), cf_joint_q_step(lb[2], ub[2], 0)},
                   f = CF_LSQ_HUGE_OBJ;
            nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)nz, lb, ub,
                                              step, XTOL_REL, MAX_EVALS, objective, c, z, &f);
            if (c->pr.oom)
                return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's "
                                                        "optimiser (NLopt)");
            if ((res > 0 || res == NLOPT_ROUNDOFF_LIMITED) && f < best) {
                best = f;
                memcpy(zb, z, sizeof zb);
            }
            if ((res > 0 || res == NLOPT_ROUNDOFF_LIMITED || res == NLOPT_MAXEVAL_REACHED) &&
                f < CF_LSQ_HUGE_OBJ && nends < 18) {
                memcpy(ends[nends], z, sizeof z);
                fends[nends++] = f;
            }
        }
    /* an optimum whose full lattice buckles inside a uniaxial table's range: the search again,
    ** kept to stable lattices, as the pair's (joint_pair.c) */
    r->starts = (c->fit_weights ? 2 : 1) * 9;
    conical_keep_stable(c, nz, lb, ub, ends, fends, nends, zb, &best, r);
    if (c->pr.oom)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's optimiser "
                                                "(NLopt)");
    double A = 0;
    if (!(best < CF_LSQ_HUGE_OBJ) || !(profile(c, zb, &A) < CF_LSQ_HUGE_OBJ) || !(A > 0))
        return cf_error_set(err, CF_E_NOCONV, "the joint fit found no lattice that runs every "
                                              "table");
    r->objective = best;
    r->ident.rho = exp(zb[0]), r->ident.solid = zb[1], r->ident.scale = A;
    cf_status st = cf_fit_place(reach, opt, c->type, &r->ident, &r->fit, err);
    if (st != CF_OK)
        return st;
    /* the uncertainty of the quantities found, the weights (fitted or not) held where they are:
    ** each table's residuals weighted as in the search */
    r->fit.ident = r->ident;
    return cf_cell_uncertainty(&c->pr, &c->pr, &r->fit, err);
}

/* The conical-tail law's search through the cell (tail_cell.h), the weights held at the conical
** law's fit plain, from its quantities; the tailed spring placed in closed form (tail.h) with the
** errors of its four quantities from the joint residuals, and their profile intervals where the
** errors say nothing. */
static cf_status search_tail(jctx *c, const cf_table *reach, double xmax,
                             const cf_joint_result *plain, cf_joint_result *r, cf_error *err)
{
    c->tail = 1;
    c->fit_weights = 0;
    c->need = xmax * (1 + CF_FIT_TRAVEL_MARGIN);
    c->pr.A_max = joint_A_max;
    if (!(c->need < 1))
        return cf_error_set(err, CF_E_DATA, "the springs must reach a strain of %g: no spring "
                                            "does", xmax);
    double lb[3], ub[3], zb[3] = {0, 0, 0}, A = 0;
    cf_tail_cell_box(c->opt, c->type, xmax, lb, ub);
    const cf_tail_cell tc = {&c->pr, &c->tau};
    const double best = cf_tail_cell_search(&tc, &plain->ident, lb, ub, zb);
    if (c->pr.oom)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's optimiser "
                                                "(NLopt)");
    const double f = best < CF_LSQ_HUGE_OBJ ? cf_tail_cell_profile(&tc, zb, &A) : CF_LSQ_HUGE_OBJ;
    if (!(f < CF_LSQ_HUGE_OBJ) || !(A > 0))
        return cf_error_set(err, CF_E_NOCONV, "the joint fit found no conical-tail law that runs "
                                              "every table");
    double v[4], se[4], corr[4][4], cov_Bt;
    cf_tail_cell_quantities(zb, A, v);
    r->objective = f * c->pr.ynorm;
    cf_tail_errors(cf_tail_cell_residuals, (void *)&tc, c->pr.n, v, TAIL_FD_STEP, r->objective,
                   se, corr, &cov_Bt);
    cf_status st = cf_tail_result(reach, c->opt, c->type, v, se, corr, cov_Bt, &r->fit, err);
    if (st != CF_OK)
        return st;
    r->fit.held |= cf_tail_cell_held(c->opt, lb, ub, zb, c->type);
    /* profile intervals where the errors say nothing, as for one table, on every table's rows */
    if (cf_tail_cell_intervals(&tc, c->opt, c->type, c->need, lb, ub, c->pr.n, r->objective,
                               c->pr.ynorm, v, &r->fit) < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the profiles of %zu rows",
                            c->pr.n);
    r->ident = r->fit.ident;
    return CF_OK;
}

/* A joint fit, stage after stage: check the tables, the springs' common reach, the search of the
** law (search_conical; search_tail when plain, the conical law's joint fit, is given), then each
** table in the lattice of the placed spring (verify_tables). Kept as one function because the
** stages share the tables' weights, the reach and the result being filled; each stage is marked
** below. */
static cf_status joint_run(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                           const cf_validate_setup *lat, cf_spring_type type,
                           const cf_joint_result *plain, int pair_mode, cf_joint_result *r,
                           cf_error *err)
{
    const double t0 = cf_clock_s();
    memset(r, 0, sizeof *r);
    if (n < 1 || n > CF_JOINT_MAX)
        return cf_error_set(err, CF_E_DATA, "a joint fit takes 1 to %d tables, not %zu",
                            CF_JOINT_MAX, n);
    for (size_t k = 0; k < n; k++)
        if (cf_table_is_force(tables[k]))
            return cf_error_set(err, CF_E_DATA,
                                "%s: a joint fit needs stress-strain tables; a force-displacement "
                                "table's lengths are its own, not strains one lattice shares",
                                tables[k]->path);
    jctx c;
    memset(&c, 0, sizeof c);
    c.t = tables;
    c.n = n;
    c.opt = opt;
    c.lat = lat;
    c.type = type;
    c.fit_weights = lat->cfg.lattice.calibration == CF_CAL_FITTED;
    memcpy(c.weight, plain ? plain->weight : lat->cfg.lattice.weight, sizeof c.weight);
    cf_status st = CF_OK;
    size_t total = 0;
    for (size_t k = 0; k < n; k++)
        total += tables[k]->count;
    double *reach_x = malloc(total * sizeof(double)), *reach_y = malloc(total * sizeof(double));
    double *all_sw = malloc(total * sizeof(double));
    c.pr = (cf_cell_problem){.curve = cf_joint_curve, .ctx = &c, .n = total, .y = reach_y,
                             .sw = all_sw, .opt = opt, .type = type,
                             .g = malloc(total * sizeof(double))};
    if (!reach_x || !reach_y || !all_sw || !c.pr.g) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory");
        goto out;
    }
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        const cf_table *t = tables[k];
        c.sw[k] = malloc(t->count * sizeof(double));
        c.curve[k] = malloc(t->count * sizeof(double));
        r->tab[k].lattice_MPa = malloc(t->count * sizeof(double));
        if (!c.sw[k] || !c.curve[k] || !r->tab[k].lattice_MPa) {
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory");
            goto out;
        }
        if (cf_joint_table_weights(t, &r->tab[k].scale_MPa, c.sw[k]) != 0) {
            st = cf_error_set(err, CF_E_DATA, "%s: every stress is zero", t->path);
            goto out;
        }
        r->tab[k].mode = t->mode;
        r->tab[k].points = t->count;
        for (size_t i = 0; i < t->count; i++) {
            all_sw[m] = c.sw[k][i];
            c.pr.ynorm += (all_sw[m] * t->y[i]) * (all_sw[m] * t->y[i]);
            reach_x[m] = copysign(cf_cell_spring_strain(t->mode, t->x[i]), t->x[i]);
            reach_y[m++] = t->y[i];
        }
    }
    r->ntables = n;
    /* the springs' reach over every table bounds s/H and is what the placement must honour */
    cf_table reach = *tables[0];
    reach.count = total;
    reach.x = reach_x;
    reach.y = reach_y;
    reach.w = NULL;
    reach.t = NULL;
    const double xmax = cf_lsq_xmax(&reach);
    /* the search and the placement */
    c.pair = pair_mode >= 1;
    c.tail = pair_mode == 2; /* the pair's compression spring with a tail */
    c.need = xmax * (1 + CF_FIT_TRAVEL_MARGIN);
    if (pair_mode >= 0) {
        memcpy(c.weight, lat->cfg.lattice.weight, sizeof c.weight);
        if (plain && !c.fit_weights)
            memcpy(c.weight, plain->weight, sizeof c.weight);
        st = cf_joint_search_pair(&c, &reach, xmax, plain, r, err);
    } else {
        st = plain ? search_tail(&c, &reach, xmax, plain, r, err)
                   : search_conical(&c, &reach, xmax, r, err);
    }
    if (st != CF_OK)
        goto out;
    memcpy(r->weight, c.weight, sizeof r->weight);
    r->calibration = lat->cfg.lattice.calibration;
    r->anisotropy_max = r->calibration == CF_CAL_FITTED ? opt->anisotropy_max : 0;
    if (!r->nparams)
        r->nparams = r->fit.tail ? 4 : 3;
    r->aic = cf_baseline_aic(total, r->objective, r->nparams, 1.0);
    /* each table in the lattice of the placed spring */
    st = cf_joint_verify_tables(&c, r, err);
out:
    for (size_t k = 0; k < n && k < CF_JOINT_MAX; k++) {
        free(c.sw[k]);
        free(c.curve[k]);
    }
    free(reach_x);
    free(reach_y);
    free(all_sw);
    free(c.pr.g);
    r->evaluations = c.pr.evals;
    r->wall_time_s = cf_clock_s() - t0;
    if (st != CF_OK)
        cf_joint_free(r);
    return st;
}

cf_status cf_joint_fit(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                       const cf_validate_setup *lat, cf_spring_type type, cf_joint_result *r,
                       cf_error *err)
{
    CF_GSL_GUARD;
    return joint_run(tables, n, opt, lat, type, NULL, -1, r, err);
}

/* Whether the tables determine a double-acting element's two springs; CF_E_DATA naming the spring
** they leave free, and why, otherwise. A table in a mode with a loaded axis (uniaxial, planar,
** equibiaxial, confined) strains the springs along that axis directly, on its rows' side: a row
** of positive strain lengthens them (the extension spring works), a negative one shortens them
** (the compression spring). The other side is strained only through the lattice's lateral
** response, a fraction of the table's strain, where that spring's law is still nearly linear:
** its shape (rho, s/H) is left free. A simple-shear table lengthens one diagonal of each cell as
** it shortens the other by nearly as much, so its curve fixes about the sum of the two laws:
** beside a table that determines one side it determines the other; alone, neither (measured on
** the brain cortex's shear table: the pair lowers the RMSE 0.0080 -> 0.0058 kPa with every
** quantity of both springs in the Jacobian's null space, by a compression spring of almost no
** stiffness, small-strain E 0.008 kPa in compression against 4.0 in tension, that no row
** tests). */
cf_status cf_joint_pair_determined(const cf_table *const *tables, size_t n, cf_error *err)
{
    int stretch = 0, shorten = 0, shear = 0;
    for (size_t k = 0; k < n; k++) {
        const cf_table *t = tables[k];
        const cf_mode_row *row = cf_mode_row_of(t->mode);
        if (row && row->shear_i >= 0) {
            shear = 1;
            continue;
        }
        for (size_t i = 0; i < t->count; i++) {
            stretch |= t->x[i] > 0;
            shorten |= t->x[i] < 0;
        }
    }
    if ((stretch && shorten) || (shear && (stretch || shorten)))
        return CF_OK;
    char which[96];
    if (n == 1)
        snprintf(which, sizeof which, "the table");
    else
        snprintf(which, sizeof which, "the %zu tables", n);
    if (shear && !stretch && !shorten)
        return cf_error_set(err, CF_E_DATA,
                            "%s: a double-acting element's two springs are not determined by "
                            "simple shear alone: shearing lengthens one diagonal of each cell as "
                            "it shortens the other by nearly as much, so the curve fixes about "
                            "the sum of the two springs' laws, not each; fit it with a tension or "
                            "compression table too (--joint), or fit a single-sided law",
                            tables[0]->path);
    const int ext = !stretch; /* the side no row strains directly */
    return cf_error_set(err, CF_E_DATA,
                        "%s%s: a double-acting element's %s spring is not determined by %s: no "
                        "row %s the lattice along a loaded axis, so the lattice's springs %s only "
                        "through its lateral response, a fraction of the strain, where that "
                        "spring's law is nearly linear and its shape (rho, s/H) free; fit it with "
                        "a %s or simple-shear table too (--joint), or fit a single-sided law",
                        tables[0]->path, n > 1 ? " and the other tables" : "",
                        ext ? "extension" : "compression", which,
                        ext ? "stretches" : "compresses", ext ? "lengthen" : "shorten",
                        ext ? "tension" : "compression");
}

/* 1 when the fit a ranks above b: a lattice stable at rest, a buildable spring, a lattice stable
** over every table's range, then the lower objective, in that order. */
static int ranks_above(const cf_joint_result *a, const cf_joint_result *b)
{
    const int ra = cf_joint_stable_at_rest(a), rb = cf_joint_stable_at_rest(b);
    if (ra != rb)
        return ra;
    if ((a->fit.feasible != 0) != (b->fit.feasible != 0))
        return a->fit.feasible != 0;
    if (cf_joint_stable(a) != cf_joint_stable(b))
        return cf_joint_stable(a);
    return a->objective * (1 + 1e-9) < b->objective;
}

/* A deep copy of r into *to (its per-table curves its own). CF_E_INTERNAL when memory runs out. */
static cf_status copy_result(const cf_joint_result *r, cf_joint_result *to, cf_error *err)
{
    *to = *r;
    for (size_t k = 0; k < CF_JOINT_MAX; k++)
        to->tab[k].lattice_MPa = NULL;
    for (size_t k = 0; k < r->ntables && k < CF_JOINT_MAX; k++) {
        const size_t m = r->tab[k].points;
        if (!r->tab[k].lattice_MPa)
            continue;
        to->tab[k].lattice_MPa = malloc(m * sizeof(double));
        if (!to->tab[k].lattice_MPa) {
            cf_joint_free(to);
            return cf_error_set(err, CF_E_INTERNAL, "out of memory");
        }
        memcpy(to->tab[k].lattice_MPa, r->tab[k].lattice_MPa, m * sizeof(double));
    }
    return CF_OK;
}

/* Nested laws never lose: the law a pair search fits (pair 0 the volume term, 1 the pair, 2 the
** pair with a tailed compression spring) contains plain's (kappa 0; two equal springs; a tail of
** no coils) when plain has the same volume treatment (for pair 0: none, the term fitted). When
** the search found nothing (st not CF_OK) or plain ranks above what it found (ranks_above),
** the result is plain's optimum in the form of the law asked for, with the same lattice, curves
** and stability, and nested_objective what the search ended on. */
static cf_status nest_pair(const cf_joint_result *plain, int pair, const cf_fit_options *opt,
                           cf_status st, cf_joint_result *r, cf_error *err)
{
    const int contained =
        plain && (pair == 0   ? plain->volume == CF_VOLUME_NONE && opt->volume == CF_VOLUME_FIT
                  : pair == 1 ? !plain->pair && plain->volume == opt->volume
                              : plain->pair == 1 && !plain->fit.tail &&
                                    plain->volume == opt->volume);
    if (!contained || !(plain->objective >= 0) || !isfinite(plain->objective))
        return st;
    const int found = st == CF_OK;
    if (found && !ranks_above(plain, r))
        return CF_OK;
    cf_joint_result nest;
    cf_status cs = copy_result(plain, &nest, err);
    if (cs != CF_OK) {
        if (found)
            cf_joint_free(r);
        return cs;
    }
    nest.nested_objective = found && isfinite(r->objective) ? r->objective : 0;
    nest.fit.nested_rmse = found && isfinite(r->fit.rmse) ? r->fit.rmse : 0;
    nest.fit.nested_violated = found && !r->fit.feasible ? r->fit.violated | r->ext.violated : 0;
    if (pair == 0) { /* the term at kappa 0 */
        nest.volume = CF_VOLUME_FIT;
        nest.volume_modulus_MPa = 0;
        nest.volume_modulus_se = -1;
        nest.nparams = (plain->nparams ? plain->nparams : 3) + 1;
    } else if (pair == 1) { /* two equal springs */
        nest.pair = 1;
        nest.ext = plain->fit;
        nest.ext.ident = plain->ident;
        nest.nparams = 6 + (opt->volume == CF_VOLUME_FIT);
    } else { /* the compression spring's tail of no coils */
        nest.fit.tail = 1;
        nest.fit.q[CF_Q_TAIL] = 0;
        nest.fit.q_se[CF_Q_TAIL] = 0;
        nest.fit.interval_ok[CF_Q_TAIL] = 0;
        nest.fit.params.n_tail = 0;
        nest.fit.params.H_tail_mm = 0;
        nest.nparams = plain->nparams + 1;
    }
    size_t total = 0;
    for (size_t k = 0; k < nest.ntables; k++)
        total += nest.tab[k].points;
    nest.aic = cf_baseline_aic(total, nest.objective, nest.nparams, 1.0);
    if (!(nest.E_compression_MPa > 0)) { /* the single-sided lattice's small-strain moduli */
        jctx m;
        memset(&m, 0, sizeof m);
        memcpy(m.weight, nest.weight, sizeof m.weight);
        m.pair = nest.pair;
        const double v[PQ_COUNT] = {nest.ident.rho,  nest.ident.solid, nest.ident.scale,
                                    nest.ident.rho,  nest.ident.solid, nest.ident.scale,
                                    nest.volume_modulus_MPa, 0};
        cf_joint_small_strain_moduli(&m, v, &nest);
    }
    if (found) {
        nest.evaluations = r->evaluations;
        nest.wall_time_s = r->wall_time_s;
        nest.starts = r->starts, nest.stable_ends = r->stable_ends, nest.restarts = r->restarts;
        nest.projected = r->projected;
        cf_joint_free(r);
    }
    *r = nest;
    if (err)
        memset(err, 0, sizeof *err);
    return CF_OK;
}

cf_status cf_joint_fit_pair(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                            const cf_validate_setup *lat, cf_spring_type type, int pair,
                            const cf_joint_result *plain, cf_joint_result *r, cf_error *err)
{
    CF_GSL_GUARD;
    if (pair < 0 || pair > 2)
        return cf_error_set(err, CF_E_DATA, "pair %d: 0 (single-sided), 1 (double-acting) or 2 "
                                            "(double-acting, the compression spring tailed)",
                            pair);
    if (pair && n >= 1) {
        cf_status st = cf_joint_pair_determined(tables, n, err);
        if (st != CF_OK)
            return st;
    }
    if (opt->volume == CF_VOLUME_POISSON && pair)
        return cf_error_set(err, CF_E_DATA,
                            "--poisson %g: a double-acting element's lattice has one small-strain "
                            "nu in compression and another in tension; declare kappa "
                            "(--volume-modulus) or fit it (--volume fit)",
                            opt->volume_value);
    if (opt->volume == CF_VOLUME_POISSON) {
        const double *w = plain ? plain->weight : lat->cfg.lattice.weight;
        const double nu0 = cf_cubic_moduli_of(w).nu;
        if (!(opt->volume_value >= nu0 * (1 - 1e-12)) || !(opt->volume_value < 0.5))
            return cf_error_set(err, CF_E_DATA,
                                "--poisson %g: the lattice's springs alone give nu = %.4g along "
                                "an axis and the volume term only raises it (up to 0.5)",
                                opt->volume_value, nu0);
    }
    cf_status st = joint_run(tables, n, opt, lat, type, plain, pair, r, err);
    if (st == CF_E_INTERNAL)
        return st;
    return nest_pair(plain, pair, opt, st, r, err);
}

cf_status cf_joint_fit_tail(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                            const cf_validate_setup *lat, const cf_joint_result *plain,
                            cf_joint_result *r, cf_error *err)
{
    CF_GSL_GUARD;
    cf_status st = joint_run(tables, n, opt, lat, plain->fit.type, plain, -1, r, err);
    if (st == CF_E_INTERNAL || !(plain->objective >= 0) || !isfinite(plain->objective))
        return st;
    /* the tailed law contains the conical law (tail compliance 0): a search that finds nothing,
    ** ends infeasible where plain is feasible, or ends with a larger weighted objective at the
    ** same feasibility gives plain with no tail (cf_tail_nest for one table) */
    const int found = st == CF_OK;
    if (found && !(plain->fit.feasible && !r->fit.feasible) &&
        !(plain->fit.feasible == r->fit.feasible &&
          !(r->objective <= plain->objective * (1 + 1e-9))))
        return CF_OK;
    cf_joint_result nest = *plain;
    for (size_t k = 0; k < CF_JOINT_MAX; k++)
        nest.tab[k].lattice_MPa = NULL;
    for (size_t k = 0; k < plain->ntables; k++) {
        const size_t m = plain->tab[k].points;
        if (!plain->tab[k].lattice_MPa)
            continue;
        nest.tab[k].lattice_MPa = malloc(m * sizeof(double));
        if (!nest.tab[k].lattice_MPa) {
            cf_joint_free(&nest);
            if (found)
                cf_joint_free(r);
            return cf_error_set(err, CF_E_INTERNAL, "out of memory");
        }
        memcpy(nest.tab[k].lattice_MPa, plain->tab[k].lattice_MPa, m * sizeof(double));
    }
    cf_fit_result *f = &nest.fit;
    f->nested_rmse = found && isfinite(r->fit.rmse) ? r->fit.rmse : 0;
    f->nested_violated = found && !r->fit.feasible ? r->fit.violated : 0;
    nest.nested_objective = found && isfinite(r->objective) ? r->objective : 0;
    f->tail = 1;
    f->q[CF_Q_TAIL] = 0;
    f->q_se[CF_Q_TAIL] = 0;
    f->interval_ok[CF_Q_TAIL] = 0;
    f->params.n_tail = 0;
    f->params.H_tail_mm = 0;
    /* the search's cost is the tailed fit's own */
    nest.evaluations = found ? r->evaluations : 0;
    nest.wall_time_s = found ? r->wall_time_s : 0;
    if (found)
        cf_joint_free(r);
    *r = nest;
    if (err)
        memset(err, 0, sizeof *err);
    return CF_OK;
}
