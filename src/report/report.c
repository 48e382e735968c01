/*
** Fit reports (see report.h): what the report says of its fits (the better type, a tie, AIC) and
** the JSON fit file, through jansson. The readable text is in report_text.c.
*/
#include "report/report.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "base/atomic.h"
#include "io/fitfile_json.h"
#include "io/measures.h"
#include "report/report_baselines.h"
#include "report/report_json.h"
#include "report/report_notes.h"
#include "report/report_words.h"
#include "fit/lawkind.h"

void cf_report_free(cf_fit_report *r)
{
    if (!r)
        return;
    for (int i = 0; i < 2; i++)
        cf_validation_free(&r->val[i]);
}

void cf_report_settle(cf_fit_report *r)
{
    CF_GSL_GUARD;
    memset(&r->verdict, 0, sizeof r->verdict);
    if (r->nfits == 2)
        r->verdict = cf_fit_compare(&r->fits[0], &r->fits[1], r->table->count);
    else
        r->verdict.better = r->nfits == 1 && r->fits[0].feasible ? 0 : -1;
}

int cf_report_better(const cf_fit_report *r)
{
    return r->verdict.better;
}

int cf_report_types_tie(const cf_fit_report *r)
{
    return r->nfits == 2 && r->verdict.tie;
}

int cf_report_target_is_lattice(const cf_fit_report *r)
{
    int all = r->through_msm && r->nfits > 0;
    for (int i = 0; i < r->nfits; i++)
        all = all && r->thr[i].done;
    return all;
}

double cf_report_fit_aic(const cf_fit_report *r, int i)
{
    double f = r->table->y_to_file;
    return cf_baseline_aic(r->table->count, r->fits[i].rss * f * f, cf_fit_kind_of(&r->fits[i])->nq,
                           r->ymax * f);
}


#define num cf_json_number

static json_t *constraint_list(unsigned bits)
{
    json_t *a = json_array();
    for (int k = 0; k < CF_C_COUNT; k++)
        if (bits & (1u << k))
            json_array_append_new(a, json_string(cf_fit_constraint_name(1u << k)));
    return a;
}



/* limit_cost {limits, rmse, rmse_without_limits, flags}: what the limits holding fit i cost,
** present when the widened fit ran. */
static void limit_cost_json(json_t *o, const cf_fit_report *r, int i)
{
    const cf_limit_cost *lc = &r->limit_cost[i];
    if (!lc->checked || !o)
        return;
    json_t *flags = json_array();
    for (int b = 0; b < CF_C_COUNT; b++)
        if (lc->limits >> b & 1u)
            json_array_append_new(flags, json_string(cf_fit_constraint_flag(1u << b)));
    const double u = r->table->y_to_file;
    json_object_set_new(o, "limit_cost",
                        json_pack("{s:o, s:o, s:o, s:o, s:b}", "limits",
                                  constraint_list(lc->limits), "flags", flags, "rmse",
                                  num(lc->rmse * u), "rmse_without_limits",
                                  num(lc->rmse_free * u), "warning",
                                  lc->rmse > (1 + CF_LIMIT_COST_WARN) * lc->rmse_free));
}

/* How far the law is from solid at the data, in the table's own measure: the table strain at
** which the first spring reaches solid in the table's mode (the solid strain itself in
** uniaxial), its ratio to the table's largest strain, and whether that is close. */
static json_t *extrapolation_json(const cf_fit_report *r, const cf_fit_result *f)
{
    const int fd = cf_table_is_force(r->table);
    const double solid = cf_fit_family(f, fd).solid;
    const double at = f->solid_table_strain > 0 ? f->solid_table_strain : solid;
    json_t *o = json_pack("{s:o, s:o, s:o, s:b}", fd ? "travel_mm" : "solid_strain", num(solid), fd ? "largest_displacement_mm" : "largest_strain",
                          num(at / f->solid_ratio), "ratio", num(f->solid_ratio), "warning",
                          f->solid_ratio < CF_FIT_SOLID_RATIO_WARN);
    if (o && !fd) {
        json_object_set_new(o, "table_strain_at_solid", num(at));
        json_object_set_new(o, "mode", json_string(cf_mode_name(r->table->mode)));
    }
    return o;
}

/* The law kinds fitted for fits[i]: each one's quality, AIC, feasibility and the quantities it
** has beyond the conical law's, and which one the fit keeps; through_lattice when they were
** fitted through the lattice (their RMSE and AIC are the lattice's). */
static json_t *law_comparison_json(const cf_fit_report *r, int i)
{
    const cf_law_choice *lc = &r->law_choice[i];
    const double u = r->table->y_to_file;
    const cf_law_row *first = cf_fit_kind_of(&lc->cand[0]);
    json_t *o = json_pack("{s:s, s:b}", "chosen", cf_fit_kind_of(&lc->cand[lc->chosen])->name,
                          "through_lattice", r->through_msm && r->thr[i].done);
    for (int j = 0; o && j < lc->n; j++) {
        const cf_fit_result *f = &lc->cand[j];
        const cf_law_row *row = cf_fit_kind_of(f);
        json_t *c = json_pack("{s:o, s:o, s:b}", "rmse", num(f->rmse * u), "aic",
                              num(lc->aic[j]), "feasible", f->feasible);
        for (int k = 0; c && k < row->nq; k++) {
            const char *key = cf_law_q_key(row, k, r->table);
            int shared = 0;
            for (int m = 0; m < first->nq; m++)
                shared = shared || strcmp(key, cf_law_q_key(first, m, r->table)) == 0;
            if (!shared)
                json_object_set_new(c, key, cf_report_ident_json(f, k));
        }
        char nested[320];
        cf_report_nested(r, f, nested, sizeof nested);
        if (c && nested[0]) /* the conical optimum it contains: why */
            json_object_set_new(c, "no_tail", json_string(nested));
        json_object_set_new(o, row->name, c);
    }
    return o;
}

static json_t *fit_json_core(const cf_fit_report *r, int i)
{
    const cf_fit_result *f = &r->fits[i];
    double u = r->table->y_to_file;
    const cf_law_row *row = cf_fit_kind_of(f);
    const char *names[CF_Q_MAX];
    json_t *ident = json_object();
    for (int k = 0; k < row->nq; k++) {
        names[k] = cf_law_q_key(row, k, r->table);
        json_object_set_new(ident, names[k], cf_report_ident_json(f, k));
    }
    json_t *o = cf_fitfile_spring_json(&f->law);
    json_t *rest = json_pack(
        "{s:o, s:o, s:o, s:o, s:o, s:b, s:o, s:o, s:s, s:I, s:o}", "identifiable", ident, "rmse",
        num(f->rmse * u), "max_abs_error", num(f->max_abs_error * u), "r2", num(f->r2), "aic",
        num(cf_report_fit_aic(r, i)), "feasible", f->feasible, "active_constraints",
        constraint_list(f->active), "violated_constraints", constraint_list(f->violated),
        "optimizer", f->optimizer, "evaluations", (json_int_t)f->evaluations, "wall_time_s",
        num(r->with_timing ? f->wall_time_s : 0.0));
    if (!o || !rest) {
        json_decref(o);
        json_decref(rest);
        return NULL;
    }
    json_object_update(o, rest);
    json_decref(rest);
    /* the type fitted: an infeasible fit's geometry may be of the other type */
    json_object_set_new(o, "type", json_string(cf_spring_type_name(f->type)));
    json_object_set_new(o, "identifiable_correlation", cf_report_correlation_json(f, names, row->ncorr ? row->ncorr : row->nq));
    json_object_set_new(o, "law", json_string(row->name));
    if (r->law_choice[i].ran)
        json_object_set_new(o, "law_comparison", law_comparison_json(r, i));
    json_object_set_new(o, "held_by", constraint_list(f->held));
    json_object_set_new(o, "extrapolation", extrapolation_json(r, f));
    limit_cost_json(o, r, i);
    return o;
}

/* {edge, face, body} */
static json_t *weights_json(const double w[CF_FAMILY_COUNT])
{
    return json_pack("{s:o, s:o, s:o}", "edge", num(w[CF_FAMILY_EDGE]), "face",
                     num(w[CF_FAMILY_FACE]), "body", num(w[CF_FAMILY_BODY]));
}

/* validation {rmse, r2, max_abs_error (file's unit), lattice {...}, wall_time_s} or {skipped} */
/* The stability in the table's mode: how far it holds over the table's range, by which check
** (the full lattice's negative pivots, or the cell's incremental stiffness), or why unchecked. */
static void stability_json(json_t *o, const cf_validation *v)
{
    if (!v->stability_checked) {
        json_object_set_new(o, "stability_reason",
                            json_string(cf_report_why(v->stability_note,
                                                      "the stability scan did not run")));
        return;
    }
    json_object_set_new(o, "stable_to_strain", num(v->stable_to_strain));
    json_object_set_new(o, "stable_in_range", json_boolean(!v->unstable_in_range));
    json_object_set_new(o, "stability_by", json_string(v->by_cell ? "cell tangent"
                                                                  : "full lattice"));
    if (v->cell_stability_checked && !v->by_cell) {
        json_object_set_new(o, "cell_stable_to_strain", num(v->cell_stable_to_strain));
        json_object_set_new(o, "cell_stable_in_range", json_boolean(!v->cell_unstable_in_range));
    }
}

static json_t *validation_json(const cf_fit_report *r, int i)
{
    const cf_validation *v = &r->val[i];
    if (!v->done)
        return json_pack("{s:s}", "skipped",
                         cf_report_why(v->note, "the validation did not run (no reason recorded)"));
    const cf_lattice_config *lc = &v->setup.cfg.lattice;
    double u = r->table->y_to_file;
    cf_cubic_moduli cm = cf_cubic_moduli_of(lc->weight);
    json_t *lat = json_pack("{s:i, s:i, s:i, s:s, s:o, s:o, s:o, s:s}", "nx", lc->nx, "ny",
                            lc->ny, "nz", lc->nz, "calibration",
                            cf_calibration_name(lc->calibration), "weights",
                            weights_json(lc->weight), "modulus_ratio", num(cm.E), "poisson_ratio",
                            num(cm.nu), "bottom",
                            lc->bottom == CF_BOTTOM_CLAMPED ? "clamped" : "axial");
    double fit_rmse = r->through_msm && r->thr[i].done ? r->thr[i].cell_rmse : r->fits[i].rmse;
    json_t *o = json_pack("{s:s, s:s, s:o, s:o, s:o, s:o, s:o, s:s, s:I, s:o}", "mode",
                     cf_mode_name(v->mode), "model", v->by_cell ? "homogenised cell" :
                     "full lattice", "fit_rmse", num(fit_rmse * u), "rmse", num(v->rmse * u),
                     "r2", num(v->r2),
                     "max_abs_error", num(v->max_abs_error * u), "lattice", lat, "law_method",
                     cf_law_method_name(v->setup.method), "solves", (json_int_t)v->solves,
                     "wall_time_s", num(r->with_timing ? v->wall_time_s : 0.0));
    if (o && isfinite(v->law_rmse)) /* uniaxial tables only: the law's own curve is uniaxial */
        json_object_set_new(o, "law_difference_rmse", num(v->law_rmse * u));
    if (o)
        stability_json(o, v);
    return o;
}

static json_t *through_json(const cf_fit_report *r, int i)
{
    const cf_through_msm *t = &r->thr[i];
    double u = r->table->y_to_file;
    json_t *o = json_pack("{s:o, s:o, s:o, s:b, s:b, s:o, s:I}", "rmse_before",
                          num(t->rmse_before * u), "cell_rmse", num(t->cell_rmse * u),
                          "rmse_after", num(t->rmse_after * u), "improved", t->improved,
                          "verified", t->verified, "wall_time_s",
                          num(r->with_timing ? t->wall_time_s : 0.0), "evaluations",
                          (json_int_t)t->evaluations);
    if (o && t->verified)
        json_object_set_new(o, "verification_max_abs", num(t->verify_max_abs * u));
    if (o) /* of evaluations: the Jacobian and the profiles of the uncertainty */
        json_object_set_new(o, "uncertainty_evaluations", json_integer(t->uncertainty_curves));
    return o;
}

/* {model: lattice | spring, mode, evaluated_by}: what the fit's numbers are of. */
static json_t *target_json(const cf_fit_report *r)
{
    const int lat = cf_report_target_is_lattice(r);
    return json_pack("{s:s, s:s, s:s}", "model", lat ? "lattice" : "spring", "mode",
                     cf_table_is_force(r->table) ? "force-displacement" : cf_mode_name(r->table->mode),
                     "evaluated_by", lat ? "homogenised cell" : "the spring's law");
}

/* The single spring's own law against a uniaxial table, beside a lattice target. */
static json_t *spring_law_json(const cf_fit_report *r, int i)
{
    const cf_through_msm *t = &r->thr[i];
    double u = r->table->y_to_file;
    return json_pack("{s:s, s:o, s:o, s:o}", "what",
                     "the single spring's uniaxial law against the table, not the fit's target",
                     "rmse", num(t->law_rmse * u), "max_abs_error", num(t->law_max_abs_error * u),
                     "r2", num(t->law_r2));
}

static json_t *fit_json(const cf_fit_report *r, int i)
{
    json_t *o = fit_json_core(r, i);
    if (o)
        json_object_set_new(o, "target", target_json(r));
    if (o && cf_report_target_is_lattice(r) && isfinite(r->thr[i].law_rmse))
        json_object_set_new(o, "spring_law", spring_law_json(r, i));
    if (o && r->validate)
        json_object_set_new(o, "validation", validation_json(r, i));
    if (o && r->through_msm && r->thr[i].done)
        json_object_set_new(o, "through_msm", through_json(r, i));
    return o;
}






static json_t *measures_json(const cf_table *t)
{
    const cf_table_measures *m = &t->measures;
    char src[3][128], conv[256];
    cf_report_sources(t, src);
    cf_report_conversion(t, conv, sizeof conv);
    const char *strain = cf_report_strain_name(t, src);
    json_t *o = json_pack("{s:s, s:s, s:s, s:s, s:s, s:s}", "stress",
                          cf_stress_measure_name(m->stress), "stress_source", src[0], "strain",
                          strain, "strain_source", src[1], "mode",
                          cf_mode_name(t->mode), "mode_source", src[2]);
    if (o && *conv) /* absent: the columns were taken as they are */
        json_object_set_new(o, "conversion", json_string(conv));
    return o;
}

/* A mode the table's kind cannot honour: stated, with why (data.mode, mode_honoured false,
** mode_reason). */
static void mode_dropped_json(json_t *data, const cf_table *t)
{
    const char *why = cf_report_mode_dropped(t);
    if (!why || !data)
        return;
    json_object_set_new(data, "mode", json_string(cf_mode_name(t->mode)));
    json_object_set_new(data, "mode_honoured", json_false());
    json_object_set_new(data, "mode_reason", json_string(why));
}

/* The limits every fit ran under. */
static json_t *limits_json(const cf_fit_report *r)
{
    const cf_fit_options *o = &r->fit_options;
    return json_pack("{s:o, s:o, s:o, s:o, s:o, s:o, s:o}", "rho_min", num(o->rho_min), "n_min",
                     num(o->lower[CF_P_N]), "n_max", num(o->upper[CF_P_N]), "D2_over_H_max",
                     num(o->D2_over_H_max), "G_max_MPa", num(o->upper[CF_P_G]), "index_min",
                     num(3.0), "index_max", num(o->index_max));
}

/* warnings[]: what the model cannot follow (absent when nothing). */
static void warnings_json(json_t *root, const cf_fit_report *r)
{
    char w[CF_REPORT_WARNINGS_MAX][CF_REPORT_WARNING_LEN];
    int n = cf_report_warnings(r, w, CF_REPORT_WARNINGS_MAX);
    if (n == 0)
        return;
    json_t *a = json_array();
    for (int k = 0; k < n; k++)
        json_array_append_new(a, json_string(w[k]));
    json_object_set_new(root, "warnings", a);
}

static json_t *report_json(const cf_fit_report *r)
{
    json_t *data = json_pack(
        "{s:s, s:I, s:s, s:s, s:s, s:s, s:s, s:s}", "file", r->table->path, "points",
        (json_int_t)r->table->count, "x_column", r->table->x_column, "x_unit", r->table->x_unit, "y_column",
        r->table->y_column, "y_unit", r->table->y_unit, "kind",
        cf_table_is_force(r->table) ? "force-displacement" : "stress-strain", "sign",
        r->table->compression ? "compression-negative" : "tension-positive");
    if (!cf_table_is_force(r->table))
        json_object_set_new(data, "measures", measures_json(r->table));
    mode_dropped_json(data, r->table);
    cf_report_notes_json(data, r->table);
    json_t *fits = json_array(), *base = json_array();
    for (int i = 0; i < r->nfits; i++)
        json_array_append_new(fits, fit_json(r, i));
    for (int k = 0; k < CF_BASE_COUNT; k++)
        json_array_append_new(base, cf_report_baseline_json(r, k));
    json_t *root = json_pack("{s:s, s:o, s:o}", "conifit_version", r->version, "data", data,
                             "fits", fits);
    json_object_set_new(root, "limits", limits_json(r));
    int b = cf_report_better(r), tie = cf_report_types_tie(r);
    if (b >= 0 && !tie) /* absent on a tie (comparison.tie) or when no type has a spring */
        json_object_set_new(root, "better_type", json_string(cf_spring_type_name(r->fits[b].type)));
    if (r->nfits == 2 && b >= 0) {
        int o = 1 - b;
        const cf_fit_verdict v = r->verdict;
        char text[1024];
        cf_report_verdict(r, text, sizeof text);
        json_t *c = json_pack("{s:b, s:s, s:s, s:o, s:o, s:o}", "tie", tie, "verdict", text,
                              "test", "F(1, N - 3) at 95 % on the weighted residual sum of squares",
                              "held_back_by", constraint_list(tie ? 0u : v.held),
                              "rmse_ratio_other_to_better",
                              num(r->fits[b].rmse > 0 ? r->fits[o].rmse / r->fits[b].rmse : 1.0),
                              "aic_difference",
                              num(cf_report_fit_aic(r, o) - cf_report_fit_aic(r, b)));
        /* the test's numbers, absent when the other type has no spring inside its limits (no
        ** contest: the verdict says so) */
        if (c && isfinite(v.delta_rss) && isfinite(v.threshold)) {
            json_object_set_new(c, "delta_weighted_rss", num(v.delta_rss));
            json_object_set_new(c, "threshold_weighted_rss", num(v.threshold));
        }
        json_object_set_new(root, "comparison", c);
    }
    json_object_set_new(root, "baselines", base);
    warnings_json(root, r);
    json_object_set_new(root, "identifiability",
                        json_string("the law depends on the six design parameters only through "
                                    "rho, the solid strain (travel) and the stress (load) scale; "
                                    "params is one member of that family, chosen by the "
                                    "constraints"));
    return root;
}

char *cf_report_json_string(const cf_fit_report *r)
{
    CF_GSL_GUARD;
    json_t *root = report_json(r);
    if (!root)
        return NULL;
    char *s = cf_fitfile_dumps(root);
    json_decref(root);
    return s;
}

cf_status cf_report_json_prepare(const cf_fit_report *r, const char *path,
                                 const char *const *inputs, cf_output *out, cf_error *err)
{
    CF_GSL_GUARD;
    cf_status st = cf_atomic_begin_one("cf_report_json_prepare", r, path, out, err);
    if (st != CF_OK)
        return st;
    json_t *root = report_json(r);
    if (!root)
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory building the report", path);
    st = cf_fitfile_prepare(root, path, inputs, out, err);
    json_decref(root);
    return st;
}

cf_status cf_report_json_write(const cf_fit_report *r, const char *path,
                               const char *const *inputs, cf_error *err)
{
    CF_GSL_GUARD;
    cf_atomic a = {0};
    cf_status st = cf_report_json_prepare(r, path, inputs, &a, err);
    if (st == CF_OK)
        st = cf_atomic_commit(&a, err);
    return st;
}
