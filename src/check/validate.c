/*
** Validation of fitted springs in the static uniaxial lattice and the fit through the lattice
** (see validate.h).
*/
#include "conifit/validate.h"

#include "conifit/viscomodel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <nlopt.h>

#include "fit/lsq.h"

/* BOBYQA stops when a step changes every variable by less than this, relative. The validation
** error is reported to 4 digits; 1e-6 in the variables is far below what changes them. */
#define XTOL_REL 1e-6
/* Lattice curves allowed to the optimiser: each is a few milliseconds on the default 3 x 3 x 3
** lattice; BOBYQA on the two remaining variables typically converges in a few dozen. */
#define MAX_CURVES 400

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

cf_validate_setup cf_validate_default(void)
{
    cf_validate_setup s;
    s.cfg = cf_msm_default();
    s.method = CF_LAW_CLOSED;
    s.table_intervals = CF_LAW_TABLE_DEFAULT;
    return s;
}

cf_status cf_validate_from_scene(const cf_scene *sc, const char *name, cf_validate_setup *s,
                                 cf_error *err)
{
    const char *what = NULL;
    if (sc->effects.inertia)
        what = "inertia";
    else if (sc->effects.eta_MPa_s != 0)
        what = "damping";
    else if (sc->effects.maxwell_E_MPa != 0)
        what = "viscosity";
    else if (sc->effects.gravity_mm_per_s2 != 0)
        what = "gravity";
    if (what)
        return cf_error_set(err, CF_E_DATA,
                            "%s: key 'effects' asks for %s: validation needs a static uniaxial "
                            "scene (no time-dependent effect)",
                            name, what);
    if (sc->kind != CF_PROTO_RAMP)
        return cf_error_set(err, CF_E_DATA,
                            "%s: key 'protocol.kind' = '%s': validation needs a static uniaxial "
                            "scene (kind 'ramp')",
                            name, sc->kind == CF_PROTO_CYCLES ? "cycles" : sc->kind == CF_PROTO_HOLD ? "hold" : "history");
    if (sc->drive != CF_DRIVE_DISPLACEMENT)
        return cf_error_set(err, CF_E_DATA,
                            "%s: key 'protocol.to_stress_kPa': validation drives the lattice by "
                            "the table's strains (use 'to_strain')",
                            name);
    s->cfg = sc->cfg;
    s->method = sc->method;
    s->table_intervals = sc->table_intervals;
    return CF_OK;
}

void cf_validation_free(cf_validation *v)
{
    if (!v)
        return;
    free(v->stress_MPa);
    v->stress_MPa = NULL;
}

/* The lattice curve of spring p at the strains of d into out (count values). */
/* The curve of spring p at the strains of d in the table's mode: the full lattice (cf_msm_uniaxial)
** when full is set and the mode is uniaxial, else the homogenised cell (cell.h), which equals the
** full lattice wherever the lattice deforms homogeneously and is the only form of the other modes.
** *by_cell (may be NULL) says which ran; law_out (may be NULL) receives the law's own curve. */
static cf_status model_curve(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                             int full, double *out, double *law_out, cf_msm_stats *stats,
                             int *by_cell, cf_error *err)
{
    cf_law law;
    cf_status st = cf_law_init(&law, p, err);
    if (st != CF_OK)
        return st;
    if (s->method == CF_LAW_TABLE && (st = cf_law_table_build(&law, s->table_intervals, err)))
        return st;
    int cell = !full || d->mode != CF_MODE_UNIAXIAL;
    if (by_cell)
        *by_cell = cell;
    if (!cell) {
        st = cf_msm_uniaxial(&law, s->method, &s->cfg, d->x, d->count, out, stats, err);
    } else {
        cf_cell c;
        if (stats)
            memset(stats, 0, sizeof *stats);
        st = cf_cell_init(&c, &law, s->method, s->cfg.lattice.weight, err);
        if (st == CF_OK)
            st = cf_cell_curve(&c, d->mode, d->x, d->count, out, err);
    }
    for (size_t i = 0; st == CF_OK && law_out && i < d->count; i++)
        law_out[i] = cf_fit_model(&law, 0, d->x[i]);
    cf_law_free(&law);
    return st;
}

/* The stability limit of the full uniaxial lattice on the table's side (compression when the
** table has any), and whether the table reaches past it. A failure leaves it unchecked. */
static cf_status stability(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                           cf_validation *v, cf_error *err)
{
    double lo = 0, hi = 0;
    for (size_t i = 0; i < d->count; i++) {
        lo = fmin(lo, d->x[i]);
        hi = fmax(hi, d->x[i]);
    }
    int side = lo < 0 ? -1 : 1;
    cf_law law;
    if (cf_law_init(&law, p, NULL) != CF_OK)
        return CF_OK;
    cf_error e = {0};
    cf_status st = CF_OK;
    if ((s->method != CF_LAW_TABLE || cf_law_table_build(&law, s->table_intervals, &e) == CF_OK) &&
        (st = cf_msm_stability_limit(&law, s->method, &s->cfg, side, &v->stable_to_strain, &e)) ==
            CF_OK) {
        v->stability_checked = 1;
        double reach = side < 0 ? lo : hi;
        v->unstable_in_range = v->stable_to_strain != 0 && fabs(reach) > fabs(v->stable_to_strain);
    }
    cf_law_free(&law);
    /* a scan that could not run leaves the stability unchecked; one that ran out of memory is an
    ** error, not a finding */
    if (e.status == CF_E_INTERNAL || st == CF_E_INTERNAL)
        return cf_error_set(err, CF_E_INTERNAL, "%s", e.msg);
    return CF_OK;
}

cf_status cf_validate_run(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                          cf_validation *v, cf_error *err)
{
    const double t0 = now_s();
    memset(v, 0, sizeof *v);
    v->setup = *s;
    v->mode = d->mode;
    cf_error e = {0};
    cf_status st = CF_OK;
    double *law = NULL;
    if (cf_table_is_force(d)) {
        st = cf_error_set(&e, CF_E_DATA,
                          "validation needs a stress-strain table; a force-displacement table is "
                          "one spring's curve and does not determine the cell size H");
    } else if (d->count == 0) {
        st = cf_error_set(&e, CF_E_DATA, "no data points to validate against");
    } else if (!(v->stress_MPa = malloc(sizeof(double) * d->count)) ||
               !(law = malloc(sizeof(double) * d->count))) {
        st = cf_error_set(&e, CF_E_INTERNAL, "out of memory for %zu points", d->count);
    } else {
        cf_msm_stats stats;
        st = model_curve(p, s, d, 1, v->stress_MPa, law, &stats, &v->by_cell, &e);
        v->solves = stats.solves;
        v->newton_iters = stats.newton_iters;
    }
    if (st != CF_OK) {
        free(law);
        cf_validation_free(v);
        snprintf(v->note, sizeof v->note, "%s", e.msg);
        v->wall_time_s = now_s() - t0;
        if (err)
            *err = e;
        return st;
    }
    v->count = d->count;
    cf_lsq_quality q = cf_lsq_quality_of(d, v->stress_MPa);
    v->rmse = q.rmse;
    v->max_abs_error = q.max_abs_error;
    v->r2 = q.r2;
    double ss = 0;
    for (size_t i = 0; i < d->count; i++)
        ss += (v->stress_MPa[i] - law[i]) * (v->stress_MPa[i] - law[i]);
    /* the law's own curve is a uniaxial one: in another mode there is nothing to compare */
    v->law_rmse = d->mode == CF_MODE_UNIAXIAL ? sqrt(ss / (double)d->count) : NAN;
    free(law);
    if (!v->by_cell && (st = stability(p, s, d, v, &e)) != CF_OK) {
        cf_validation_free(v);
        snprintf(v->note, sizeof v->note, "%s", e.msg);
        v->wall_time_s = now_s() - t0;
        if (err)
            *err = e;
        return st;
    }
    v->done = 1;
    v->wall_time_s = now_s() - t0;
    return CF_OK;
}

/* ---- the fit through the lattice ------------------------------------------------------------ */


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

/* The objective at (log rho, s/H) with the stress scale solved in closed form: at a prescribed
** displacement the static equilibrium does not depend on the scale of the springs' forces (every
** force is F_C times a function of u/s), so the lattice's stress is A times its stress at A = 1
** and the best A is a weighted linear least-squares solution. *A_out receives it. */
static double tm_profile(tm_ctx *c, const double *z, double *A_out)
{
    cf_spring p = cf_spring_member(exp(z[0]), z[1], 1.0);
    c->evals++;
    *A_out = 0;
    /* the fitter's design limits in this space: where no spring can be placed, or the scale a
    ** placeable spring carries at most */
    double A_max;
    if (cf_fit_ident_limit(c->opt, c->type, exp(z[0]), z[1], &A_max) > 0)
        return CF_LSQ_HUGE_OBJ;
    if (model_curve(&p, c->s, c->d, 0, c->curve, NULL, NULL, NULL, NULL) != CF_OK)
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
    if (model_curve(p, c->s, c->d, 0, c->curve, NULL, NULL, NULL, NULL) != CF_OK)
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
** cell, the placement and the verification in the full lattice, as marked below. Kept as one
** function (~100 lines) because the stages share the cell's setup and the result. */
cf_status cf_validate_through_msm(const cf_table *d, const cf_fit_options *opt,
                                  const cf_validate_setup *s, cf_fit_result *res,
                                  cf_validation *v, cf_through_msm *t, cf_error *err)
{
    const double t0 = now_s();
    memset(t, 0, sizeof *t);
    cf_validation_free(v);
    memset(v, 0, sizeof *v);
    cf_fit_identifiable(&res->params, 0, t->ident_before);
    memcpy(t->ident_after, t->ident_before, sizeof t->ident_after);
    tm_ctx c = {d, s, opt, res->type, NULL, 0, NULL, 0};
    c.sw = malloc(sizeof(double) * (d->count ? d->count : 1));
    c.curve = malloc(sizeof(double) * (d->count ? d->count : 1));
    double *cell = malloc(sizeof(double) * (d->count ? d->count : 1));
    double *spring_x = malloc(sizeof(double) * (d->count ? d->count : 1));
    cf_status st = CF_OK;
    if (!c.sw || !c.curve || !cell || !spring_x) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", d->count);
        goto out;
    }
    if (cf_table_is_force(d)) {
        st = cf_validate_run(&res->params, s, d, v, err); /* records the reason it is skipped */
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
    double rho_hi = cf_lsq_rho_hi(res->type, opt->index_max);
    double lb[2] = {log(fmax(CF_LSQ_RHO_LO, opt->rho_min)),
                    xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9)};
    double ub[2] = {log(rho_hi), 1 - 1e-9};
    if (!(lb[1] < ub[1]) || !(c.ynorm > 0)) {
        st = cf_error_set(err, CF_E_DATA,
                          "largest strain %g: no spring reaches it, nothing to optimise", xmax);
        goto out;
    }
    /* Starts: the ordinary fit's quantities and a coarse grid over (rho, s/H); the cell makes a
    ** curve cost microseconds, so several local searches are cheap and the best is kept. */
    double best = CF_LSQ_HUGE_OBJ, zb[2] = {0, 0};
    const double grid_rho[3] = {0.1, 0.35, 0.7}, grid_e[2] = {0.15, 0.6};
    for (int k = -1; k < 6; k++) {
        double z[2];
        if (k < 0) {
            z[0] = log(t->ident_before[0]);
            z[1] = t->ident_before[1];
        } else {
            z[0] = log(grid_rho[k % 3]);
            z[1] = lb[1] + grid_e[k / 3] * (ub[1] - lb[1]);
        }
        for (int j = 0; j < 2; j++)
            z[j] = fmin(fmax(z[j], lb[j]), ub[j]);
        double f = bobyqa(&c, z, lb, ub);
        if (f < best) {
            best = f;
            zb[0] = z[0], zb[1] = z[1];
        }
    }
    double A = 0;
    int ok = best < CF_LSQ_HUGE_OBJ && tm_profile(&c, zb, &A) < CF_LSQ_HUGE_OBJ && A > 0;
    double ident[3] = {exp(zb[0]), zb[1], A};
    /* Place the design parameters as the ordinary fit does; keep them when the cell fits better. */
    cf_fit_result placed;
    cf_error e = {0};
    double after = CF_LSQ_HUGE_OBJ;
    if (ok && cf_fit_place(&reach, opt, res->type, ident, &placed, &e) == CF_OK)
        after = cell_rmse(&placed.params, &c);
    if (after < t->rmse_before) {
        cf_fit_identifiable(&placed.params, 0, t->ident_after);
        placed.evaluations += res->evaluations;
        placed.wall_time_s += res->wall_time_s;
        *res = placed;
        t->improved = 1;
    }
    t->cell_rmse = t->improved ? after : t->rmse_before;
    /* Verification: the reported spring once in the validation lattice, against the cell. */
    if (model_curve(&res->params, s, d, 0, cell, NULL, NULL, NULL, NULL) == CF_OK &&
        cf_validate_run(&res->params, s, d, v, &e) == CF_OK) {
        t->rmse_after = v->rmse;
        for (size_t i = 0; i < d->count; i++)
            t->verify_max_abs = fmax(t->verify_max_abs, fabs(v->stress_MPa[i] - cell[i]));
        t->verified = !v->by_cell;
    } else if (!v->done) {
        cf_validate_run(&res->params, s, d, v, NULL);
    }
    t->done = 1;
out:
    t->evaluations = c.evals;
    t->wall_time_s = now_s() - t0;
    free(c.sw);
    free(c.curve);
    free(cell);
    free(spring_x);
    return st;
}
