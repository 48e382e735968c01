/*
** Validation of fitted springs in the static uniaxial lattice (see validate.h).
*/
#include "conifit/validate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    v->law_rmse = d->mode == CF_MODE_UNIAXIAL ? sqrt(ss / (double)d->count) : NAN;
    free(law);
    if (!v->by_cell && (st = stability(p, s, d, v, &e)) != CF_OK) {
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
    const double t0 = cf_clock_s();
    cf_validation_free(v);
    memset(v, 0, sizeof *v);
    if (cf_table_is_force(d))
        return cf_validate_run(&res->params, s, d, v, err); /* records the reason it is skipped */
    if (!t->done)
        return CF_OK;
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
