/*
** Report, fit file and plot of a viscoelastic fit (see viscoreport.h).
*/
#include "report/viscoreport.h"
#include "report/report_notes.h"
#include "report/report_words.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "base/atomic.h"
#include "io/fitfile_json.h"
#include "report/gnuplot.h"

#define num cf_json_number

void cf_visco_report_free(cf_visco_report *r)
{
    if (r)
        cf_visco_fit_free(&r->fit);
}

/* Sets o[key] to a standard error times scale, or, when it is not determined (< 0), leaves the
** key out and sets o[key_reason] instead: a fit file holds no null (fitfile_json.h). */
static void set_se(json_t *o, const char *key, double se, double scale)
{
    if (!o)
        return;
    if (se >= 0) {
        json_object_set_new(o, key, num(se * scale));
        return;
    }
    char rk[64];
    snprintf(rk, sizeof rk, "%s_reason", key);
    json_object_set_new(o, rk, json_string("not determined: the quantity sits on a limit or the "
                                           "Jacobian of the fit is numerically rank-deficient"));
}

/* The long-time relative modulus 1 - sum g_i(x) at |strain| x. */
static double g_inf_at(const cf_visco_params *p, double x)
{
    double g = 1;
    for (int i = 0; i < p->nbranch; i++)
        g -= p->g[i] + p->k[i] * x;
    return g;
}

static double g_inf(const cf_visco_params *p)
{
    return g_inf_at(p, 0);
}

static json_t *constraints(unsigned bits)
{
    json_t *a = json_array();
    for (int k = 0; k < CF_C_COUNT; k++)
        if (bits & (1u << k))
            json_array_append_new(a, json_string(cf_fit_constraint_name(1u << k)));
    return a;
}

/* The names of the elastic quantities set in mask (CF_IDENT_* bits), comma-separated. */
static void elastic_names(unsigned mask, char *buf, size_t cap)
{
    static const char *const names[CF_IDENT_COUNT] = {"rho", "s/H", "F_C/H^2"};
    size_t n = 0;
    buf[0] = '\0';
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        if (mask >> k & 1u)
            cf_report_append(buf, cap, &n, "%s%s", n ? ", " : "", names[k]);
}

/* The elastic quantities of the kept candidate the series does not determine: the JSON list and
** the text warning naming each. */
static json_t *elastic_list(unsigned mask)
{
    static const char *const names[CF_IDENT_COUNT] = {"rho", "s/H", "F_C/H^2"};
    json_t *a = json_array();
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        if (mask >> k & 1u)
            json_array_append_new(a, json_string(names[k]));
    return a;
}

static void elastic_unresolved_json(json_t *o, const cf_visco_fit *f)
{
    if (!f->elastic_unresolved)
        return;
    json_object_set_new(o, "elastic_undetermined", elastic_list(f->elastic_unresolved));
    json_object_set_new(o, "elastic_undetermined_reason",
                        json_string("a standard error larger than the quantity's range (rho and "
                                    "s/H lie in (0, 1]; the stress scale is positive)"));
}

static void elastic_unresolved_text(FILE *o, const cf_visco_fit *f)
{
    char names[64];
    if (!f->elastic_unresolved)
        return;
    elastic_names(f->elastic_unresolved, names, sizeof names);
    fprintf(o, " warning: the series does not determine the elastic %s (a standard error larger "
               "than its range): the candidate is not determined; hold the elastic part "
               "(--elastic) or fit its table jointly\n",
            names);
}

static json_t *predictions_json(const cf_visco_report *r)
{
    const cf_visco_predict *p = &r->fit.pred;
    const double u = r->table->y_to_file;
    json_t *h = p->hysteresis_done
                    ? json_pack("{s:o, s:o, s:o, s:o}", "strain_amplitude", num(p->cycle_strain),
                                "period_s", num(p->cycle_period_s), "loop_area_kPa",
                                num(p->loop_area_MPa * 1e3), "loading_work_kPa",
                                num(p->loading_work_MPa * 1e3))
                    : json_pack("{s:s}", "skipped",
                                cf_report_why(p->note, "not predicted (no reason recorded)"));
    /* a fraction only of a cycle that did work: absent, never NaN (which the writer refuses) */
    if (h && p->hysteresis_done && p->loading_work_MPa > 0)
        json_object_set_new(h, "dissipated_fraction",
                            num(p->loop_area_MPa / p->loading_work_MPa));
    json_t *c = p->creep_done
                    ? json_pack("{s:o, s:s, s:o, s:o, s:o, s:o, s:o}", "stress",
                                num(p->creep_stress_MPa * u), "stress_unit", r->table->y_unit, "ramp_s",
                                num(p->creep_ramp_s), "hold_s", num(p->creep_hold_s),
                                "strain_end_of_ramp", num(p->creep_strain_ramp), "strain_end",
                                num(p->creep_strain_end), "creep_strain",
                                num(p->creep_strain_end - p->creep_strain_ramp))
                    : json_pack("{s:s}", "skipped",
                                cf_report_why(p->note, "not predicted (no reason recorded)"));
    return json_pack("{s:o, s:o}", "hysteresis", h, "creep", c);
}

/* The viscoelastic part of one fit entry (the same for every placed spring). */
static void visco_keys(const cf_visco_report *r, json_t *o)
{
    const cf_visco_fit *f = &r->fit;
    const double u = r->table->y_to_file;
    json_t *prony = json_array();
    for (int i = 0; i < f->p.nbranch; i++) {
        json_t *e = json_pack("{s:o, s:o}", "g", num(f->p.g[i]), "tau_s", num(f->p.tau_s[i]));
        set_se(e, "stderr_g", f->se_g[i], 1);
        set_se(e, "stderr_tau_s", f->se_tau_s[i], 1);
        if (f->strain_mask >> i & 1u) { /* absent: constant in strain */
            json_object_set_new(e, "g_per_strain", num(f->p.k[i]));
            set_se(e, "stderr_g_per_strain", f->se_k[i], 1);
        }
        json_array_append_new(prony, e);
    }
    json_object_set_new(o, "rmse", num(f->rmse * u));
    if (f->rmse_ramp >= 0) /* absent without a point on the ramp */
        json_object_set_new(o, "rmse_ramp", num(f->rmse_ramp * u));
    if (f->rmse_hold >= 0) /* absent without a point in the hold */
        json_object_set_new(o, "rmse_hold", num(f->rmse_hold * u));
    json_object_set_new(o, "points_ramp", json_integer((json_int_t)f->n_ramp));
    json_object_set_new(o, "points_hold", json_integer((json_int_t)f->n_hold));
    json_object_set_new(o, "max_abs_error", num(f->max_abs_error * u));
    json_object_set_new(o, "r2", num(f->r2));
    /* AIC with RSS in the file's unit, k = fitted parameters */
    double aic_shift = (double)f->count * log(u * u);
    json_object_set_new(o, "aic", num(f->aic + aic_shift));
    json_object_set_new(o, "parameters", json_integer(f->k));
    json_object_set_new(o, "prony", prony);
    json_object_set_new(o, "g_inf", num(g_inf(&f->p)));
    if (f->strain_relaxation) { /* absent: quasi-linear, g_inf the same at every strain */
        json_object_set_new(o, "largest_strain", num(f->x_max));
        json_object_set_new(o, "g_inf_at_largest_strain", num(g_inf_at(&f->p, f->x_max)));
    }
    json_object_set_new(o, "relaxation", json_string(f->strain_relaxation ? "strain" : "qlv"));
    if (f->dashpot) { /* absent without one */
        json_t *dp = json_pack("{s:o}", "eta_kPa_s", num(f->p.eta_MPa_s * 1e3));
        set_se(dp, "stderr_kPa_s", f->se_eta_MPa_s, 1e3);
        json_object_set_new(o, "dashpot", dp);
    }
    json_object_set_new(o, "instantaneous_modulus_kPa", num(f->E_inst_MPa * 1e3));
    json_object_set_new(o, "equilibrium_modulus_kPa", num(f->E_eq_MPa * 1e3));
    json_object_set_new(o, "branch_choice", json_string(f->chosen_by_aic ? "aic" : "given"));
    if (f->chosen_by_aic) {
        json_t *a = json_array();
        for (int n = 0; n < CF_VISCO_AIC_MAX; n++)
            for (int gs = 0; gs < 2; gs++) {
                const cf_visco_candidate *cd = &f->by_n[n][gs];
                if (!cd->fitted)
                    continue;
                json_t *c = json_pack("{s:i, s:s, s:i, s:o, s:b}", "branches", n + 1,
                                      "relaxation", gs ? "strain" : "qlv",
                                      "terms_depending_on_strain", cd->strain_terms, "aic",
                                      num(cd->aic + aic_shift), "determined", cd->identified);
                if (c && cd->elastic_unresolved)
                    json_object_set_new(c, "elastic_undetermined",
                                        elastic_list(cd->elastic_unresolved));
                json_array_append_new(a, c);
            }
        json_object_set_new(o, "aic_by_branches", a);
    }
    json_object_set_new(o, "terms_determined", json_boolean(f->identified));
    elastic_unresolved_json(o, f);
    json_object_set_new(o, "elastic_held", json_boolean(f->held_elastic));
    json_object_set_new(o, "rho_at_limit", json_boolean(f->rho_at_limit));
    json_object_set_new(o, "solid_strain_at_stability_limit", json_boolean(f->at_stability_limit));
    json_object_set_new(o, "stress_scale_at_design_limit", json_boolean(f->at_design_limit));
    if (f->stable_to_strain != 0) /* absent: stable over the range scanned */
        json_object_set_new(o, "stable_to_strain", num(f->stable_to_strain));
    json_object_set_new(o, "predictions", predictions_json(r));
    json_object_set_new(o, "evaluations", json_integer((json_int_t)f->evaluations));
    json_object_set_new(o, "wall_time_s", num(r->with_timing ? f->wall_time_s : 0.0));
}

static json_t *fit_json(const cf_visco_report *r, int i)
{
    const cf_fit_result *f = &r->placed[i];
    const cf_visco_fit *v = &r->fit;
    json_t *o = cf_fitfile_spring_json(&f->law);
    json_t *id = json_pack("{s:{s:o}, s:{s:o}, s:{s:o}}", "rho", "value", num(v->p.ident.rho),
                           "solid_strain", "value", num(v->p.ident.solid), "stress_scale_MPa",
                           "value", num(v->p.ident.scale));
    set_se(json_object_get(id, "rho"), "stderr", v->ident_se.rho, 1);
    set_se(json_object_get(id, "solid_strain"), "stderr", v->ident_se.solid, 1);
    set_se(json_object_get(id, "stress_scale_MPa"), "stderr", v->ident_se.scale, 1);
    json_t *rest = json_pack("{s:o, s:b, s:o, s:o}", "identifiable", id, "feasible", f->feasible,
                             "active_constraints", constraints(f->active), "violated_constraints",
                             constraints(f->violated));
    if (!o || !rest || json_object_update(o, rest) != 0) {
        json_decref(o);
        json_decref(rest);
        return NULL;
    }
    json_decref(rest);
    /* a held tailed spring: the law named and its fourth quantity, held (no standard error), as a
    ** static fit of the conical-tail law writes them; absent for the conical law */
    if (v->p.e_tail > 0) {
        json_object_set_new(o, "law", json_string("conical-tail"));
        json_t *et = json_pack("{s:o}", "value", num(v->p.e_tail));
        set_se(et, "stderr", -1, 1); /* held */
        json_object_set_new(id, "tail_compliance", et);
    }
    visco_keys(r, o);
    return o;
}

static json_t *series_json(const cf_visco_report *r)
{
    const cf_table *d = r->table;
    json_t *t = json_array(), *x = json_array(), *y = json_array(), *m = json_array();
    for (size_t k = 0; k < d->count; k++) {
        json_array_append_new(t, num(d->t[k]));
        json_array_append_new(x, num(d->x[k]));
        json_array_append_new(y, num(d->y[k] * d->y_to_file));
        json_array_append_new(m, num(r->fit.model_MPa[k] * d->y_to_file));
    }
    return json_pack("{s:o, s:o, s:o, s:o}", "time_s", t, "strain", x, "stress", y, "model", m);
}

static json_t *report_json(const cf_visco_report *r)
{
    const cf_lattice_config *lc = &r->setup.cfg.lattice;
    const cf_table *tb = r->table;
    json_t *data = json_pack("{s:s, s:I, s:s, s:s, s:s, s:s, s:s, s:s}", "file", tb->path,
                             "points", (json_int_t)tb->count, "x_column", tb->x_column, "x_unit",
                             "-", "y_column", tb->y_column, "y_unit", tb->y_unit, "kind",
                             "time-series", "sign",
                             tb->compression ? "compression-negative" : "tension-positive");
    cf_report_notes_json(data, tb);
    const int tailed = r->fit.p.e_tail > 0;
    json_t *model = json_pack(
        "{s:s, s:s, s:{s:i, s:i, s:i, s:s, s:{s:o, s:o, s:o}, s:s}, s:s, s:i}", "elastic",
        tailed ? "conical spring law with a cylindrical tail (conical-tail): the instantaneous "
                 "response"
               : "conical spring law: the instantaneous response",
        "viscous",
        r->fit.strain_relaxation
            ? "Prony series on every spring, relaxation depending on strain: g_i(e) = g_i + "
              "g_per_strain_i |e| at the spring's strain e, each branch relaxing g_i(e) times the "
              "law force"
            : "Prony series on every spring (quasi-linear viscoelasticity): G(t) = g_inf + sum g_i "
              "exp(-t/tau_i)",
        "lattice", "nx", lc->nx, "ny", lc->ny, "nz", lc->nz, "calibration",
        cf_calibration_name(lc->calibration), "weights", "edge", num(lc->weight[CF_FAMILY_EDGE]),
        "face", num(lc->weight[CF_FAMILY_FACE]), "body", num(lc->weight[CF_FAMILY_BODY]),
        "bottom", lc->bottom == CF_BOTTOM_CLAMPED ? "clamped" : "axial", "law_method",
        cf_law_method_name(r->setup.method), "substeps", r->setup.cfg.quasi_substeps);
    json_t *fits = json_array();
    int better = -1;
    for (int i = 0; i < r->nplaced; i++) {
        json_array_append_new(fits, fit_json(r, i));
        if (better < 0 && r->placed[i].feasible)
            better = i;
    }
    if (better < 0)
        better = 0;
    return json_pack("{s:s, s:o, s:o, s:o, s:s, s:o, s:s}", "conifit_version", r->version,
                     "data", data, "model", model, "fits", fits, "better_type",
                     cf_spring_type_name(r->placed[better].type), "series", series_json(r),
                     "identifiability",
                     tailed ? "the model depends on the eight design parameters only through "
                              "rho, the solid strain, the stress scale and the tail compliance; "
                              "every placed spring gives the same stress along the series"
                            : "the model depends on the six design parameters only through rho, "
                              "the solid strain and the stress scale; every placed spring gives "
                              "the same stress along the series");
}

cf_status cf_visco_report_json_prepare(const cf_visco_report *r, const char *path,
                                       const char *const *inputs, cf_output *out,
                                       cf_error *err)
{
    cf_status st = cf_atomic_begin_one("cf_visco_report_json_prepare", r, path, out, err);
    if (st != CF_OK)
        return st;
    json_t *root = report_json(r);
    if (!root)
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory building the report", path);
    st = cf_fitfile_prepare(root, path, inputs, out, err);
    json_decref(root);
    return st;
}

/* ---- text ------------------------------------------------------------------------------------ */

static void value_se_text(FILE *o, const char *label, double v, double se, double scale,
                          const char *unit)
{
    fprintf(o, "  %-30s %.6g", label, v * scale);
    if (se >= 0)
        fprintf(o, " ± %.2g", se * scale);
    else
        fprintf(o, " (± ?)");
    fprintf(o, "%s%s\n", *unit ? " " : "", unit);
}

/* The text report of a viscoelastic fit, section after section in the order printed (table,
** model, elastic quantities, Prony terms, errors over ramp and hold, predictions, springs).
** Long only because the report is: no branch depends on an earlier section. */
char *cf_visco_report_text(const cf_visco_report *r)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *o = open_memstream(&buf, &len);
    if (!o)
        return NULL;
    const cf_visco_fit *f = &r->fit;
    const double u = r->table->y_to_file;
    const cf_lattice_config *lc = &r->setup.cfg.lattice;
    fprintf(o, "%s: time series of %zu points (%s [s], %s [-], %s [%s]), %s\n", r->table->path,
            r->table->count, "time", r->table->x_column, r->table->y_column, r->table->y_unit,
            r->table->compression ? "compression negative" : "tension positive");
    if (r->table->measures.stress_converted)
        fprintf(o, " (its Cauchy stress is fitted as nominal stress, converted under "
                   "incompressibility; errors below are nominal)\n");
    cf_report_notes_text(o, r->table, " ");
    fprintf(o, " viscoelastic fit: %s law (instantaneous) + %d Prony term%s%s, in the "
               "lattice (%dx%dx%d cells, calibration %s), driven by the measured strain history\n",
            f->p.e_tail > 0 ? "conical-tail" : "conical", f->p.nbranch, f->p.nbranch == 1 ? "" : "s", f->dashpot ? " + dashpot" : "", lc->nx,
            lc->ny, lc->nz, cf_calibration_name(lc->calibration));
    if (f->chosen_by_aic) {
        fprintf(o, " chosen: the lowest AIC among the candidates whose terms the series "
                   "determines (each time constant, modulus and strain slope larger than its "
                   "standard error)\n");
        for (int n = 0; n < CF_VISCO_AIC_MAX; n++) {
            const char *sep = "";
            for (int gs = 0; gs < 2; gs++) {
                const cf_visco_candidate *cd = &f->by_n[n][gs];
                if (!cd->fitted)
                    continue;
                if (!*sep)
                    fprintf(o, "  AIC with %d term%s:", n + 1, n ? "s" : "");
                char what[48] = "qlv";
                if (gs)
                    snprintf(what, sizeof what, cd->strain_terms <= n ? "strain (%d of them)" : "strain",
                             cd->strain_terms);
                char why[80] = " (terms undetermined)";
                if (cd->elastic_unresolved) {
                    char names[48];
                    elastic_names(cd->elastic_unresolved, names, sizeof names);
                    snprintf(why, sizeof why, " (%s undetermined)", names);
                }
                fprintf(o, "%s %s %.2f%s", sep, what, cd->aic + (double)f->count * log(u * u),
                        cd->identified ? "" : why);
                sep = ",";
            }
            if (*sep)
                fputc('\n', o);
        }
    }
    elastic_unresolved_text(o, f);
    if (!f->identified && !f->elastic_unresolved)
        fprintf(o, " warning: the series does not determine every time-dependent quantity of "
                   "this model (a standard error as large as its value, or '?' below); fewer "
                   "terms (--branches) or --relaxation qlv\n");
    fprintf(o, " elastic part%s:\n", f->held_elastic ? " (held from --elastic)" : "");
    value_se_text(o, f->rho_at_limit ? "rho = D1/D2 (at --rho-min)" : "rho = D1/D2", f->p.ident.rho,
                  f->ident_se.rho, 1, "");
    value_se_text(o, f->at_stability_limit ? "solid strain s/H (at the stability limit)"
                                           : "solid strain s/H",
                  f->p.ident.solid, f->ident_se.solid, 1, "");
    value_se_text(o, f->at_design_limit ? "F_C/H^2 (at the design limit)" : "stress scale F_C/H^2",
                  f->p.ident.scale, f->ident_se.scale, u, r->table->y_unit);
    if (f->p.e_tail > 0)
        value_se_text(o, "tail compliance e_t", f->p.e_tail, -1, 1, "");
    if (f->stable_to_strain != 0)
        fprintf(o, "  elastic lattice stable to strain %.4g (one cell; larger lattices further)\n",
                f->stable_to_strain);
    fprintf(o, " Prony series, G(t) = g_inf + sum g_i exp(-t/tau_i):\n");
    for (int i = 0; i < f->p.nbranch; i++) {
        char l[32];
        snprintf(l, sizeof l, "g_%d", i + 1);
        value_se_text(o, l, f->p.g[i], f->se_g[i], 1, "");
        snprintf(l, sizeof l, "tau_%d", i + 1);
        value_se_text(o, l, f->p.tau_s[i], f->se_tau_s[i], 1, "s");
        snprintf(l, sizeof l, "g_%d per unit |strain|", i + 1);
        if (f->strain_mask >> i & 1u)
            value_se_text(o, l, f->p.k[i], f->se_k[i], 1, "");
        else if (f->strain_relaxation)
            fprintf(o, "  %-30s 0 (held: this term's change with strain was not determined)\n", l);
    }
    if (f->strain_relaxation)
        fprintf(o, "  (relaxation depends on strain: g_i + g_per_strain_i |strain| at a spring's "
                   "strain)\n");
    fprintf(o, "  %-30s %.6g%s\n", "g_inf = 1 - sum g_i", g_inf(&f->p),
            f->strain_relaxation ? " (at zero strain)" : "");
    if (f->strain_relaxation)
        fprintf(o, "  %-30s %.6g (at |strain| %.4g, the series' largest)\n", "g_inf(strain)",
                g_inf_at(&f->p, f->x_max), f->x_max);
    if (f->dashpot)
        value_se_text(o, "dashpot eta", f->p.eta_MPa_s, f->se_eta_MPa_s, 1e3, "kPa s");
    fprintf(o, "  %-30s %.4g kPa (instantaneous), %.4g kPa (equilibrium)\n",
            "small-strain modulus", f->E_inst_MPa * 1e3, f->E_eq_MPa * 1e3);
    fprintf(o, " quality:\n");
    fprintf(o, "  %-30s %.4g %s (ramp %zu points: %.4g, hold %zu points: %.4g)\n", "RMSE",
            f->rmse * u, r->table->y_unit, f->n_ramp, f->rmse_ramp >= 0 ? f->rmse_ramp * u : 0.0,
            f->n_hold, f->rmse_hold >= 0 ? f->rmse_hold * u : 0.0);
    fprintf(o, "  %-30s %.4g %s\n", "max |error|", f->max_abs_error * u, r->table->y_unit);
    fprintf(o, "  %-30s %.6f\n", "R^2", f->r2);
    fprintf(o, "  %-30s %.2f (k = %d)\n", "AIC", f->aic + (double)f->count * log(u * u), f->k);
    fprintf(o, " predicted:\n");
    const cf_visco_predict *p = &f->pred;
    if (p->hysteresis_done)
        fprintf(o, "  %-30s %.4g kPa (kJ/m^3) in a load-unload cycle to strain %.4g in %.4g s, "
                   "%.1f %% of the loading work\n",
                "hysteresis loop area", p->loop_area_MPa * 1e3, p->cycle_strain,
                p->cycle_period_s,
                p->loading_work_MPa > 0 ? 100 * p->loop_area_MPa / p->loading_work_MPa : 0.0);
    if (p->creep_done)
        fprintf(o, "  %-30s strain %.4g after the %.4g s ramp to %.4g %s, %.4g after %.4g s "
                   "held (creep %.4g)\n",
                "creep", p->creep_strain_ramp, p->creep_ramp_s, p->creep_stress_MPa * u,
                r->table->y_unit, p->creep_strain_end, p->creep_hold_s,
                p->creep_strain_end - p->creep_strain_ramp);
    if (p->note[0])
        fprintf(o, "  note: %s\n", p->note);
    fprintf(o, " one spring of the family (the model depends only on rho, s/H, F_C/H^2%s):\n",
            f->p.e_tail > 0 ? ", e_t" : "");
    for (int i = 0; i < r->nplaced; i++) {
        char sp[160];
        fprintf(o, "  %-30s %s%s\n", cf_spring_type_name(r->placed[i].type),
                cf_spring_text(&r->placed[i].params, 6, 0, sp, sizeof sp),
                r->placed[i].feasible ? "" : " (infeasible)");
    }
    fprintf(o, "  %-30s %ld model runs, %.2f s\n", "cost", f->evaluations,
            r->with_timing ? f->wall_time_s : 0.0);
    if (fclose(o) != 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

/* ---- plot ------------------------------------------------------------------------------------ */

/* Left: stress against time (measured points, model line) over the residuals; right: stress
** against strain (the loop of the series and the model's). */
static void visco_script(cf_gp *g, const cf_visco_report *r)
{
    const cf_table *d = r->table;
    const double u = r->table->y_to_file;
    cf_gp_block_begin(g, "DATA");
    for (size_t k = 0; k < d->count; k++) {
        double row[5] = {d->t[k], d->x[k], d->y[k] * u, r->fit.model_MPa[k] * u,
                         (r->fit.model_MPa[k] - d->y[k]) * u};
        cf_gp_block_row(g, 5, row);
    }
    cf_gp_block_end(g);
    char yl[96];
    snprintf(yl, sizeof yl, "%s [%s]", r->table->y_column, r->table->y_unit);
    char fl[160];
    snprintf(fl, sizeof fl, "model: %d Prony term%s%s, RMSE %.3g %s", r->fit.p.nbranch,
             r->fit.p.nbranch == 1 ? "" : "s", r->fit.dashpot ? " + dashpot" : "",
             r->fit.rmse * u, r->table->y_unit);
    char title[300];
    if (r->title) {
        snprintf(title, sizeof title, "%s", r->title);
    } else {
        cf_table_name(r->table, title, sizeof title);
    }
    cf_gp_cmd(g, "set multiplot title %q noenhanced", title);
    cf_gp_cmd(g, "set grid");
    cf_gp_cmd(g, "set key bottom right box opaque noenhanced");
    cf_gp_cmd(g, "set size 0.55,0.62");
    cf_gp_cmd(g, "set origin 0,0.33");
    cf_gp_cmd(g, "set xlabel %q", "time [s]");
    cf_gp_cmd(g, "set ylabel %q noenhanced", yl);
    cf_gp_cmd(g, "plot $DATA using 1:3 with points pt 7 ps 0.7 lc rgb %q title %q, $DATA using "
                 "1:4 with lines lw 2 lc rgb %q title %q",
              "black", "measured", "#d62728", fl);
    cf_gp_cmd(g, "set size 0.55,0.33");
    cf_gp_cmd(g, "set origin 0,0");
    cf_gp_cmd(g, "set key off");
    char rl[96];
    snprintf(rl, sizeof rl, "residual [%s]", r->table->y_unit);
    cf_gp_cmd(g, "set ylabel %q noenhanced", rl);
    cf_gp_cmd(g, "plot 0 with lines lc rgb %q notitle, $DATA using 1:5 with linespoints pt 7 ps "
                 "0.5 lc rgb %q notitle",
              "black", "#d62728");
    cf_gp_cmd(g, "set size 0.45,0.95");
    cf_gp_cmd(g, "set origin 0.55,0");
    cf_gp_cmd(g, "set key top left box opaque noenhanced");
    cf_gp_cmd(g, "set xlabel %q", "strain [-]");
    cf_gp_cmd(g, "set ylabel %q noenhanced", yl);
    cf_gp_cmd(g, "plot $DATA using 2:3 with points pt 7 ps 0.7 lc rgb %q title %q, $DATA using "
                 "2:4 with lines lw 2 lc rgb %q title %q",
              "black", "measured", "#d62728", "model");
    cf_gp_cmd(g, "unset multiplot");
}

cf_status cf_visco_plot(const cf_visco_report *r, const char *path, const char *const *inputs,
                        cf_output *out, cf_error *err)
{
    cf_status st = cf_atomic_begin_one("cf_visco_plot", r, path, out, err);
    if (st != CF_OK)
        return st;
    cf_gp g;
    cf_gp_init(&g);
    cf_gp_terminal(&g, path, 1300, 700);
    visco_script(&g, r);
    st = cf_gp_render(&g, path, inputs, out, err);
    cf_gp_free(&g);
    return st;
}
