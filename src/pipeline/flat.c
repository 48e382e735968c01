/*
** Flat calls (conifit/flat.h): each one the short chain of library calls a front end makes for
** one job, with its arguments checked before anything runs.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/budget.h"
#include "base/gslguard.h"
#include "export/export.h"
#include "io/fitfile.h"
#include "conifit/flat.h"
#include "pipeline/export.h"
#include "pipeline/simulate.h"
#include "check/hysteresis.h"
#include "model/lattice.h"
#include "model/law_internal.h"
#include "io/measure.h"
#include "model/msm.h"
#include "pipeline/pipeline.h"
#include "report/report.h"
#include "io/scene.h"

static cf_status need(const void *p, const char *what, cf_error *err)
{
    return p ? CF_OK : cf_error_set(err, CF_E_USAGE, "%s is NULL", what);
}

/* The force of spring p (the tail's two included; 0 and 0 without one): cf_flat_force's work. */
static cf_status force_of(const double *spring, int nparams, const char *method, size_t count,
                          const double *u_mm, double *F_N, double *k_N_per_mm, cf_error *err)
{
    cf_status s;
    if ((s = need(spring, "the spring", err)) != CF_OK ||
        (count && ((s = need(u_mm, "the displacements", err)) != CF_OK ||
                   (s = need(F_N, "the force array", err)) != CF_OK)))
        return s;
    for (size_t i = 0; i < count; i++)
        if (!isfinite(u_mm[i]))
            return cf_error_set(err, CF_E_DATA,
                                "displacement %zu (counting from 0) is not a finite number (%s): "
                                "give each u in mm",
                                i, isnan(u_mm[i]) ? "not a number" : u_mm[i] > 0 ? "+infinity"
                                                                                 : "-infinity");
    cf_law_method m = CF_LAW_CLOSED;
    if (method && (s = cf_law_method_parse(method, &m, err)) != CF_OK)
        return s;
    cf_spring p = {0};
    for (int k = 0; k < nparams; k++)
        cf_spring_set(&p, k, spring[k]);
    cf_law law;
    if ((s = cf_law_init(&law, &p, err)) != CF_OK)
        return s;
    if (m == CF_LAW_TABLE && (s = cf_law_table_build(&law, CF_LAW_TABLE_DEFAULT, err)) != CF_OK) {
        cf_law_free(&law);
        return s;
    }
    cf_law_force_many(&law, m, count, u_mm, F_N, k_N_per_mm);
    cf_law_free(&law);
    return CF_OK;
}

cf_status cf_flat_force(const double spring[6], const char *method, size_t count,
                        const double *u_mm, double *F_N, double *k_N_per_mm, cf_error *err)
{
    return force_of(spring, CF_P_COUNT, method, count, u_mm, F_N, k_N_per_mm, err);
}

cf_status cf_flat_force_tail(const double spring[8], const char *method, size_t count,
                             const double *u_mm, double *F_N, double *k_N_per_mm, cf_error *err)
{
    return force_of(spring, CF_P_ALL, method, count, u_mm, F_N, k_N_per_mm, err);
}

cf_status cf_flat_fit(const char *table_path, const char *type, int validate, char **json,
                      cf_error *err)
{
    CF_GSL_GUARD;
    cf_status s;
    if ((s = need(json, "the result pointer", err)) != CF_OK)
        return s;
    *json = NULL;
    if ((s = need(table_path, "the table path", err)) != CF_OK)
        return s;
    cf_pipeline_options opt = cf_pipeline_default_options();
    if (type && strcmp(type, "both") != 0) {
        cf_spring_type t;
        if ((s = cf_spring_type_parse(type, &t, err)) != CF_OK)
            return s;
        opt.types = 1u << t;
    }
    opt.validate = validate != 0;
    cf_measure_options mopt = cf_measure_default_options();
    cf_table tab;
    if ((s = cf_measure_load(table_path, &mopt, &tab, err)) != CF_OK)
        return s;
    if (tab.t) {
        cf_table_free(&tab);
        return cf_error_set(err, CF_E_DATA, "%s is a time series: fit it with conifit fit",
                            table_path);
    }
    cf_fit_report rep;
    if ((s = cf_pipeline_fit(&tab, &opt, &rep, err)) == CF_OK) {
        *json = cf_report_json_string(&rep);
        if (!*json)
            s = cf_error_set(err, CF_E_INTERNAL, "out of memory for the fit file");
        cf_report_free(&rep);
    }
    cf_table_free(&tab);
    return s;
}

cf_status cf_flat_simulate(const char *scene_path, double **samples, size_t *count,
                           cf_error *err)
{
    CF_GSL_GUARD;
    cf_status s;
    if ((s = need(samples, "the samples pointer", err)) != CF_OK ||
        (s = need(count, "the count pointer", err)) != CF_OK)
        return s;
    *samples = NULL;
    *count = 0;
    if ((s = need(scene_path, "the scene path", err)) != CF_OK)
        return s;
    cf_scene sc;
    if ((s = cf_scene_load(scene_path, &sc, err)) != CF_OK)
        return s;
    /* the default budget of conifit simulate: a scene too large is refused before it runs */
    const cf_budget budget = cf_budget_default();
    cf_sim_run run;
    double *out = NULL;
    if ((s = cf_pipeline_simulate(&sc, scene_path, &budget, 0, &run, err)) == CF_OK &&
        !(out = calloc(run.count ? run.count * CF_FLAT_SAMPLE_COLUMNS : 1, sizeof *out)))
        s = cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu samples", run.count);
    if (s == CF_OK) {
        size_t lost = cf_hysteresis_first_unstable(run.samples, run.count);
        for (size_t i = 0; i < run.count; i++) {
            const cf_msm_sample *m = &run.samples[i];
            double *row = out + i * CF_FLAT_SAMPLE_COLUMNS;
            row[0] = m->t_s;
            row[1] = m->strain;
            row[2] = m->stress_MPa * 1e3;
            row[3] = m->kinetic_mJ;
            row[4] = run.spring_MPa[i] * 1e3;
            row[5] = sc.effects.inertia ? -1 : i < lost;
            row[6] = m->lateral_stretch;
        }
        *samples = out;
        *count = run.count;
    }
    cf_sim_run_free(&run);
    cf_scene_free(&sc);
    return s;
}

cf_status cf_flat_export(const char *fit_path, const char *type, const char *format, double tol,
                         char **text, cf_error *err)
{
    cf_status s;
    if ((s = need(text, "the result pointer", err)) != CF_OK)
        return s;
    *text = NULL;
    if ((s = need(fit_path, "the fit file path", err)) != CF_OK ||
        (s = need(format, "the format", err)) != CF_OK)
        return s;
    cf_export_options opt = cf_export_default_options();
    if ((s = cf_export_format_parse(format, &opt.format, err)) != CF_OK)
        return s;
    if (tol != 0) {
        if (!(tol >= CF_EXPORT_TOL_MIN && tol <= CF_EXPORT_TOL_MAX))
            return cf_error_set(err, CF_E_DATA, "tolerance %g is not in %g..%g", tol,
                                CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX);
        opt.tol = tol;
    } else {
        opt.auto_tol = 1;
    }
    cf_fitted_spring fs;
    if ((s = cf_fitfile_load_element(fit_path, type, &fs, err)) != CF_OK) /* a pair whole */
        return s;
    opt.source = fit_path;
    size_t len = 0;
    s = cf_pipeline_export(&fs, &opt, NULL, NULL, text, &len, err);
    return s;
}

void cf_flat_free(void *p)
{
    free(p);
}
