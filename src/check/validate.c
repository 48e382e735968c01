/*
** Validation of fitted springs in the static uniaxial lattice and the fit through the lattice
** (see validate.h).
*/
#include "conifit/validate.h"

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
                            name, sc->kind == CF_PROTO_CYCLES ? "cycles" : "hold");
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
static cf_status lattice_curve(const cf_spring *p, const cf_validate_setup *s,
                               const cf_table *d, double *out, cf_msm_stats *stats,
                               cf_error *err)
{
    cf_law law;
    cf_status st = cf_law_init(&law, p, err);
    if (st != CF_OK)
        return st;
    if (s->method == CF_LAW_TABLE && (st = cf_law_table_build(&law, s->table_intervals, err)))
        return st;
    st = cf_msm_uniaxial(&law, s->method, &s->cfg, d->x, d->count, out, stats, err);
    cf_law_free(&law);
    return st;
}

cf_status cf_validate_run(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                          cf_validation *v, cf_error *err)
{
    const double t0 = now_s();
    memset(v, 0, sizeof *v);
    v->setup = *s;
    cf_error e = {0};
    cf_status st = CF_OK;
    if (cf_table_is_force(d)) {
        st = cf_error_set(&e, CF_E_DATA,
                          "validation needs a stress-strain table; a force-displacement table is "
                          "one spring's curve and does not determine the cell size H");
    } else if (d->count == 0) {
        st = cf_error_set(&e, CF_E_DATA, "no data points to validate against");
    } else if (!(v->stress_MPa = malloc(sizeof(double) * d->count))) {
        st = cf_error_set(&e, CF_E_INTERNAL, "out of memory for %zu points", d->count);
    } else {
        cf_msm_stats stats;
        st = lattice_curve(p, s, d, v->stress_MPa, &stats, &e);
        v->solves = stats.solves;
        v->newton_iters = stats.newton_iters;
    }
    if (st != CF_OK) {
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
    v->done = 1;
    v->wall_time_s = now_s() - t0;
    return CF_OK;
}

/* ---- the fit through the lattice ------------------------------------------------------------ */

/* A spring of free length 1 mm with the identifiable quantities rho, e = s/H and A = F_C/H^2:
** non-telescoping with n = 2, d = L_min/2 and D2 = L_min/(1 - rho), so that (D2 - D1)/2 = L_min/2
** stays below n d = L_min. The lattice's nominal stress depends on nothing else. */
static cf_spring member(double rho, double e, double A)
{
    const double H = 1.0, Lmin = H * (1 - e), s = H * e, n = 2.0, dw = Lmin / n;
    const double D2 = rho < 1 ? Lmin / (1 - rho) : Lmin, D1 = rho * D2;
    const double FC = A * H * H;
    cf_spring p = {D1, D2, n, dw, cf_lsq_G_of_FC(FC, n, D1, dw, s), H};
    return p;
}

typedef struct tm_ctx {
    const cf_table *d;
    const cf_validate_setup *s;
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
    cf_spring p = member(exp(z[0]), z[1], 1.0);
    c->evals++;
    *A_out = 0;
    if (lattice_curve(&p, c->s, c->d, c->curve, NULL, NULL) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    double gy = 0, gg = 0;
    for (size_t i = 0; i < c->d->count; i++) {
        double w = c->sw[i] * c->sw[i];
        gy += w * c->curve[i] * c->d->y[i];
        gg += w * c->curve[i] * c->curve[i];
    }
    double A = gy / gg;
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

cf_status cf_validate_through_msm(const cf_table *d, const cf_fit_options *opt,
                                  const cf_validate_setup *s, cf_fit_result *res,
                                  cf_validation *v, cf_through_msm *t, cf_error *err)
{
    const double t0 = now_s();
    memset(t, 0, sizeof *t);
    if (!v->done)
        return cf_error_set(err, CF_E_DATA, "the ordinary fit could not be validated: %s",
                            v->note);
    t->rmse_before = t->rmse_after = v->rmse;
    cf_fit_identifiable(&res->params, 0, t->ident_before);
    memcpy(t->ident_after, t->ident_before, sizeof t->ident_after);
    tm_ctx c = {d, s, NULL, 0, NULL, 0};
    c.sw = malloc(sizeof(double) * d->count);
    c.curve = malloc(sizeof(double) * d->count);
    if (!c.sw || !c.curve) {
        free(c.sw);
        free(c.curve);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", d->count);
    }
    const double xmax = cf_lsq_xmax(d);
    c.ynorm = cf_lsq_weights(d, opt->relative, c.sw);
    const double *v0 = t->ident_before;
    double rho_hi = cf_lsq_rho_hi(res->type, opt->index_max);
    double lb[2] = {log(CF_LSQ_RHO_LO), xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9)};
    double ub[2] = {log(rho_hi), 1 - 1e-9};
    double z[2] = {log(v0[0]), v0[1]};
    cf_status st = CF_OK;
    if (!(lb[1] < ub[1]) || !(c.ynorm > 0)) {
        st = cf_error_set(err, CF_E_DATA,
                          "largest strain %g: no spring reaches it, nothing to optimise", xmax);
        goto out;
    }
    for (int k = 0; k < 2; k++)
        z[k] = fmin(fmax(z[k], lb[k]), ub[k]);
    nlopt_opt o = nlopt_create(NLOPT_LN_BOBYQA, 2);
    if (!o) {
        st = cf_error_set(err, CF_E_INTERNAL, "cannot create the NLopt optimiser");
        goto out;
    }
    double step[2] = {0.05, 0.02 * (ub[1] - lb[1])};
    nlopt_set_lower_bounds(o, lb);
    nlopt_set_upper_bounds(o, ub);
    nlopt_set_min_objective(o, tm_objective, &c);
    nlopt_set_initial_step(o, step);
    nlopt_set_xtol_rel(o, XTOL_REL);
    nlopt_set_maxeval(o, MAX_CURVES);
    double A0, f0 = tm_profile(&c, z, &A0), f = f0;
    double zs[2] = {z[0], z[1]};
    nlopt_result r = nlopt_optimize(o, z, &f);
    nlopt_destroy(o);
    int ok = (r > 0 || r == NLOPT_ROUNDOFF_LIMITED) && isfinite(z[0]) && isfinite(z[1]) && f < f0;
    double A = A0;
    if (ok)
        f = tm_profile(&c, z, &A);
    else
        memcpy(z, zs, sizeof zs);
    double ident[3] = {exp(z[0]), z[1], A};
    ok = ok && A > 0;
    /* Place the design parameters as the ordinary fit does and validate what is placed. */
    cf_fit_result placed;
    cf_validation pv;
    cf_error e = {0};
    if (ok && cf_fit_place(d, opt, res->type, ident, &placed, &e) == CF_OK &&
        cf_validate_run(&placed.params, s, d, &pv, &e) == CF_OK) {
        if (pv.rmse < v->rmse) {
            cf_fit_identifiable(&placed.params, 0, t->ident_after);
            placed.evaluations += res->evaluations;
            placed.wall_time_s += res->wall_time_s;
            *res = placed;
            cf_validation_free(v);
            *v = pv;
            t->improved = 1;
            t->rmse_after = v->rmse;
        } else {
            cf_validation_free(&pv);
        }
    }
    t->done = 1;
out:
    t->evaluations = c.evals;
    t->wall_time_s = now_s() - t0;
    free(c.sw);
    free(c.curve);
    return st;
}
