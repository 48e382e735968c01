/*
** Validation of fitted springs in the static uniaxial lattice (see validate.h).
*/
#include "check/validate.h"
#include "model/mode.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/cell_stability.h"
#include "fit/clock.h"
#include "fit/lattice_curve.h"
#include "fit/lsq.h"

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
    if (sc->nfibres > 0)
        return cf_error_set(err, CF_E_DATA,
                            "%s: key 'fibres': %zu fibre group%s; validation runs the fitted "
                            "spring's own lattice in uniaxial compression, without fibres",
                            name, sc->nfibres, sc->nfibres == 1 ? "" : "s");
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

/* The table's reach on the side the stability is checked (compression when it has any). */
static double table_reach(const cf_table *d)
{
    double lo = 0, hi = 0;
    for (size_t i = 0; i < d->count; i++) {
        lo = fmin(lo, d->x[i]);
        hi = fmax(hi, d->x[i]);
    }
    return lo < 0 ? lo : hi;
}

/* The law of spring p built for evaluator s->method: 1 when built. Otherwise the stability stays
** unchecked, the reason in v->stability_note, and *st is CF_E_INTERNAL (err set) when memory ran
** out, else CF_OK. */
static int law_for(const cf_spring *p, const cf_validate_setup *s, cf_law *law, cf_validation *v,
                   cf_status *st, cf_error *err)
{
    cf_error e = {0};
    *st = CF_OK;
    if (cf_law_init(law, p, &e) == CF_OK) {
        if (s->method != CF_LAW_TABLE || cf_law_table_build(law, s->table_intervals, &e) == CF_OK)
            return 1;
        cf_law_free(law);
    }
    snprintf(v->stability_note, sizeof v->stability_note, "the law could not be built: %.400s",
             e.msg[0] ? e.msg : "spring refused");
    if (e.status == CF_E_INTERNAL)
        *st = cf_error_set(err, CF_E_INTERNAL, "%s", e.msg);
    return 0;
}

/* The stability limit of the full uniaxial lattice on the table's side, clipped to the table's
** reach. A failure leaves it unchecked (the reason in v->stability_note). */
static cf_status lattice_stability(const cf_spring *p, const cf_validate_setup *s,
                                   const cf_table *d, cf_validation *v, cf_error *err)
{
    const double reach = table_reach(d);
    cf_law law;
    cf_error e = {0};
    cf_status st = CF_OK;
    double limit = 0;
    if (!law_for(p, s, &law, v, &st, err))
        return st;
    st = cf_msm_stability_limit(&law, s->method, &s->cfg, reach < 0 ? -1 : 1, &limit, &e);
    cf_law_free(&law);
    if (st == CF_OK) {
        v->stability_checked = 1;
        v->unstable_in_range = limit != 0 && fabs(reach) > fabs(limit);
        v->stable_to_strain = v->unstable_in_range ? limit : reach;
        return CF_OK;
    }
    snprintf(v->stability_note, sizeof v->stability_note, "the lattice's stability scan failed: %.400s",
             e.msg[0] ? e.msg : "no reason given");
    /* a scan that ran out of memory is an error, not a finding */
    if (e.status == CF_E_INTERNAL || st == CF_E_INTERNAL)
        return cf_error_set(err, CF_E_INTERNAL, "%s", e.msg);
    return CF_OK;
}

/* The stability of the homogenised cell along the table's mode up to its reach: the smallest
** eigenvalue of the cell's incremental stiffness (cell_stability.h). */
static cf_status cell_stability(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                                cf_validation *v, cf_error *err)
{
    const double reach = table_reach(d);
    cf_law law;
    cf_cell c;
    cf_error e = {0};
    cf_status st = CF_OK;
    if (!law_for(p, s, &law, v, &st, err))
        return st;
    st = cf_cell_init(&c, &law, s->method, s->cfg.lattice.weight, &e);
    int lost = 0;
    double limit = reach;
    if (st == CF_OK)
        st = cf_cell_stable_to(&c, d->mode, reach, &limit, &lost, &e);
    cf_law_free(&law);
    if (st == CF_OK) {
        v->cell_stability_checked = 1;
        v->cell_stable_to_strain = limit;
        v->cell_unstable_in_range = lost;
        return CF_OK;
    }
    snprintf(v->stability_note, sizeof v->stability_note, "the cell's stability scan failed: %.400s",
             e.msg[0] ? e.msg : "no reason given");
    return st == CF_E_INTERNAL ? cf_error_set(err, CF_E_INTERNAL, "%s", e.msg) : CF_OK;
}

/* Stability in the table's mode: the full lattice's scan in uniaxial, the cell's tangent in
** every mode; the headline (stable_to_strain) is the lattice's where it ran, else the cell's. */
static cf_status stability(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                           cf_validation *v, cf_error *err)
{
    cf_status st = cell_stability(p, s, d, v, err);
    if (st != CF_OK)
        return st;
    if (!v->by_cell)
        return lattice_stability(p, s, d, v, err);
    v->stability_checked = v->cell_stability_checked;
    v->stable_to_strain = v->cell_stable_to_strain;
    v->unstable_in_range = v->cell_unstable_in_range;
    return CF_OK;
}

cf_status cf_validate_run(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                          cf_validation *v, cf_error *err)
{
    CF_GSL_GUARD;
    const double t0 = cf_clock_s();
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
        st = cf_lattice_curve(p, s, d, 1, v->stress_MPa, law, &stats, &v->by_cell, &e);
        v->solves = stats.solves;
        v->newton_iters = stats.newton_iters;
    }
    if (st != CF_OK) {
        free(law);
        cf_validation_free(v);
        snprintf(v->note, sizeof v->note, "%s", e.msg);
        v->wall_time_s = cf_clock_s() - t0;
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
    v->law_rmse = cf_mode_row_of(d->mode)->spring_curve ? sqrt(ss / (double)d->count) : NAN;
    free(law);
    if ((st = stability(p, s, d, v, &e)) != CF_OK) {
        cf_validation_free(v);
        snprintf(v->note, sizeof v->note, "%s", e.msg);
        v->wall_time_s = cf_clock_s() - t0;
        if (err)
            *err = e;
        return st;
    }
    v->done = 1;
    v->wall_time_s = cf_clock_s() - t0;
    return CF_OK;
}

cf_status cf_validate_lattice_fit(const cf_table *d, const cf_validate_setup *s,
                                  const cf_fit_result *res, cf_validation *v, cf_through_msm *t,
                                  cf_error *err)
{
    CF_GSL_GUARD;
    const double t0 = cf_clock_s();
    cf_validation_free(v);
    memset(v, 0, sizeof *v);
    if (cf_table_is_force(d))
        return cf_validate_run(&res->params, s, d, v, err); /* records the reason it is skipped */
    if (!t->done) {
        snprintf(v->note, sizeof v->note, "the fit through the lattice did not run: %.440s",
                 t->note[0] ? t->note : "no reason recorded");
        return CF_OK;
    }
    double *cell = malloc(sizeof(double) * (d->count ? d->count : 1));
    if (!cell)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", d->count);
    cf_error e = {0};
    /* Verification: the reported spring once in the validation lattice, against the cell. */
    cf_status st = cf_lattice_curve(&res->params, s, d, 0, cell, NULL, NULL, NULL, &e);
    if (st == CF_OK)
        st = cf_validate_run(&res->params, s, d, v, &e);
    if (st == CF_OK) {
        t->rmse_after = v->rmse;
        for (size_t i = 0; i < d->count; i++)
            t->verify_max_abs = fmax(t->verify_max_abs, fabs(v->stress_MPa[i] - cell[i]));
        t->verified = !v->by_cell;
    } else if (st == CF_E_INTERNAL) { /* out of memory: an error, not a skipped verification */
        free(cell);
        return cf_error_set(err, CF_E_INTERNAL, "%s", e.msg);
    } else if (!v->done) {
        cf_validate_run(&res->params, s, d, v, NULL);
    }
    free(cell);
    t->wall_time_s += cf_clock_s() - t0;
    return CF_OK;
}
