/*
** Fit reports (see report.h): JSON through jansson, text through a memory stream.
*/
#include "conifit/report.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "base/atomic.h"
#include "io/fitfile_json.h"

void cf_report_free(cf_fit_report *r)
{
    if (!r)
        return;
    for (int i = 0; i < 2; i++)
        cf_validation_free(&r->val[i]);
}

int cf_report_better(const cf_fit_report *r)
{
    if (r->nfits == 2)
        return cf_fit_compare(&r->fits[0], &r->fits[1], r->table->count).better;
    return r->nfits == 1 && r->fits[0].feasible ? 0 : -1;
}

int cf_report_types_tie(const cf_fit_report *r)
{
    return r->nfits == 2 && cf_fit_compare(&r->fits[0], &r->fits[1], r->table->count).tie;
}

double cf_report_fit_aic(const cf_fit_report *r, int i)
{
    double f = r->table->y_to_file;
    return cf_baseline_aic(r->table->count, r->fits[i].rss * f * f, 3, r->ymax * f);
}

double cf_report_baseline_aic(const cf_fit_report *r, int k)
{
    double f = r->table->y_to_file;
    return cf_baseline_aic(r->table->count, r->baselines[k].rss * f * f, r->baselines[k].k, r->ymax * f);
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

/* Appends to buf (capacity cap, *n used), never past its end. */
static void app(char *buf, size_t cap, size_t *n, const char *fmt, ...)
{
    if (*n + 1 >= cap)
        return;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(buf + *n, cap - *n, fmt, ap);
    va_end(ap);
    if (k > 0)
        *n = fmin(*n + (size_t)k, cap - 1);
}

/* Why a profile interval was computed and where its ends come from, in words. */
static void interval_reason(const cf_fit_result *f, int k, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    unsigned why = f->interval_why[k], lim = why & ~CF_FIT_RANK_DEFICIENT;
    app(buf, cap, &n, "profile likelihood, 95 %% (F-test), because ");
    if (why & CF_FIT_RANK_DEFICIENT)
        app(buf, cap, &n, "the Jacobian is rank-deficient%s", lim ? " and " : "");
    if (lim) {
        app(buf, cap, &n, "the fit sits on");
        for (int b = 0; b < CF_C_COUNT; b++)
            if (lim & (1u << b))
                app(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
    }
    if (!why)
        app(buf, cap, &n, "the standard error reaches past the quantity's range");
    for (int e = 0; e < 2; e++) {
        unsigned b = f->interval_end[k][e];
        if (b)
            app(buf, cap, &n, "; the %s end is the limit %s: the data do not bound it", 
                e ? "upper" : "lower", cf_fit_constraint_name(b & (0u - b)));
    }
}

/* Why a fit has no standard errors (and no correlation matrix), in words. */
static const char *stderr_reason(const cf_fit_result *f)
{
    if (strcmp(f->optimizer, "placement") == 0)
        return "not computed: the spring is placed from the quantities of the fit through the "
               "lattice";
    for (int k = 0; k < 3; k++)
        if (f->interval_ok[k] && (f->interval_why[k] & CF_FIT_RANK_DEFICIENT))
            return "not determined: the Jacobian of the three quantities is numerically "
                   "rank-deficient (see interval)";
    return "not determined: the linearised covariance s^2 (J^T W J)^-1 could not be formed";
}

/* {value, stderr | stderr_reason, [interval, interval_reason]} in conifit's units (MPa, N, mm):
** a key is present only with a value, never null. */
static json_t *ident_json(const cf_fit_result *f, int k)
{
    double se = f->ident_se.v[k];
    json_t *o = json_pack("{s:o}", "value", num(f->ident.v[k]));
    if (!o)
        return NULL;
    if (se >= 0)
        json_object_set_new(o, "stderr", num(se));
    else
        json_object_set_new(o, "stderr_reason", json_string(stderr_reason(f)));
    if (f->interval_ok[k]) {
        char why[512];
        interval_reason(f, k, why, sizeof why);
        json_object_set_new(o, "interval",
                            json_pack("[o, o]", num(f->interval[k][0]), num(f->interval[k][1])));
        json_object_set_new(o, "interval_reason", json_string(why));
        /* an end that is a limit, not the data's: the interval is one-sided there */
        json_t *lim = json_object();
        for (int e = 0; e < 2; e++) {
            unsigned b = f->interval_end[k][e];
            if (b && lim)
                json_object_set_new(lim, e ? "upper" : "lower",
                                    json_string(cf_fit_constraint_name(b & (0u - b))));
        }
        if (lim && json_object_size(lim) > 0)
            json_object_set_new(o, "interval_limit", lim);
        else
            json_decref(lim);
    }
    return o;
}

/* {order, matrix} when every correlation is determined, else {order, reason}. */
static json_t *correlation_json(const cf_fit_result *f, const char *const names[3])
{
    json_t *o = json_pack("{s:[s, s, s]}", "order", names[0], names[1], names[2]);
    int ok = 1;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            ok = ok && isfinite(f->corr[a][b]);
    if (!o)
        return NULL;
    if (!ok) {
        json_object_set_new(o, "reason", json_string(stderr_reason(f)));
        return o;
    }
    json_t *m = json_array();
    for (int a = 0; a < 3; a++) {
        json_t *row = json_array();
        for (int b = 0; b < 3; b++)
            json_array_append_new(row, num(f->corr[a][b]));
        json_array_append_new(m, row);
    }
    json_object_set_new(o, "matrix", m);
    return o;
}


static json_t *fit_json_core(const cf_fit_report *r, int i)
{
    const cf_fit_result *f = &r->fits[i];
    double u = r->table->y_to_file;
    static const char *const ss_names[3] = {"rho", "solid_strain", "stress_scale_MPa"};
    static const char *const fd_names[3] = {"rho", "travel_mm", "F_C_N"};
    const int fd = cf_table_is_force(r->table);
    const char *const *names = fd ? fd_names : ss_names;
    json_t *ident = json_object();
    for (int k = 0; k < 3; k++)
        json_object_set_new(ident, names[k], ident_json(f, k));
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
    json_object_set_new(o, "identifiable_correlation", correlation_json(f, names));
    json_object_set_new(o, "held_by", constraint_list(f->held));
    json_object_set_new(
        o, "extrapolation",
        json_pack("{s:o, s:o, s:o, s:b}", fd ? "travel_mm" : "solid_strain", num(f->ident.solid),
                  fd ? "largest_displacement_mm" : "largest_strain",
                  num(f->ident.solid / f->solid_ratio), "ratio", num(f->solid_ratio), "warning",
                  f->solid_ratio < CF_FIT_SOLID_RATIO_WARN));
    return o;
}

/* {edge, face, body} */
static json_t *weights_json(const double w[CF_FAMILY_COUNT])
{
    return json_pack("{s:o, s:o, s:o}", "edge", num(w[CF_FAMILY_EDGE]), "face",
                     num(w[CF_FAMILY_FACE]), "body", num(w[CF_FAMILY_BODY]));
}

/* validation {rmse, r2, max_abs_error (file's unit), lattice {...}, wall_time_s} or {skipped} */
static json_t *validation_json(const cf_fit_report *r, int i)
{
    const cf_validation *v = &r->val[i];
    if (!v->done)
        return json_pack("{s:s}", "skipped", v->note);
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
    if (o && v->stability_checked) {
        if (v->stable_to_strain != 0) /* absent: stable over the whole range checked */
            json_object_set_new(o, "stable_to_strain", num(v->stable_to_strain));
        json_object_set_new(o, "stable_in_range", json_boolean(!v->unstable_in_range));
    }
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
    return o;
}

static json_t *fit_json(const cf_fit_report *r, int i)
{
    json_t *o = fit_json_core(r, i);
    if (o && r->validate)
        json_object_set_new(o, "validation", validation_json(r, i));
    if (o && r->through_msm && r->thr[i].done)
        json_object_set_new(o, "through_msm", through_json(r, i));
    return o;
}

static json_t *baseline_json(const cf_fit_report *r, int k)
{
    const cf_baseline *b = &r->baselines[k];
    double u = r->table->y_to_file;
    json_t *coef;
    /* coefficients in the file's y unit per unit x */
    if (b->kind == CF_BASE_LINEAR)
        coef = json_pack("{s:o}", "E", num(b->coef[0] * u));
    else if (b->kind == CF_BASE_DUFFING)
        coef = json_pack("{s:o, s:o}", "k1", num(b->coef[0] * u), "k3", num(b->coef[1] * u));
    else
        coef = json_pack("{s:o, s:o}", "A", num(b->coef[0] * u), "B", num(b->coef[1]));
    return json_pack("{s:s, s:s, s:o, s:i, s:o, s:o}", "model", cf_baseline_name(b->kind),
                     "formula",
                     b->kind == CF_BASE_LINEAR    ? "y = E x"
                     : b->kind == CF_BASE_DUFFING ? "y = k1 x + k3 x^3"
                                                  : "y = A (exp(B x) - 1)",
                     "coefficients", coef, "parameters", b->k, "rmse", num(b->rmse * u), "aic",
                     num(cf_report_baseline_aic(r, k)));
}

/* The one sentence that compares the two types (both fitted, at least one feasible). */
static void verdict_text(const cf_fit_report *r, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    cf_fit_verdict v = cf_fit_compare(&r->fits[0], &r->fits[1], r->table->count);
    if (v.better < 0) {
        app(buf, cap, &n, "no verdict: neither type has a spring inside its limits");
        return;
    }
    const cf_fit_result *g = &r->fits[v.better], *w = &r->fits[1 - v.better];
    double u = r->table->y_to_file;
    if (!w->feasible) {
        app(buf, cap, &n, "%s: the %s type has no spring inside its limits (violated:",
            cf_spring_type_name(g->type), cf_spring_type_name(w->type));
        for (int b = 0; b < CF_C_COUNT; b++)
            if (w->violated & (1u << b))
                app(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
        app(buf, cap, &n, ")");
        return;
    }
    double base = g->objective > 0 ? g->objective : 1.0;
    if (v.tie) {
        app(buf, cap, &n,
            "tie: the data do not tell the types apart (RMSE %.4g against %.4g %s; the residual "
            "sum of squares differs by %.3g of the better one's, below the F-test threshold "
            "%.3g at 95 %%)",
            r->fits[0].rmse * u, r->fits[1].rmse * u, r->table->y_unit, v.delta_rss / base,
            v.threshold / base);
        return;
    }
    app(buf, cap, &n,
        "%s (RMSE %.4g against %.4g %s; the residual sum of squares of %s is higher by %.3g of "
        "the better one's, above the F-test threshold %.3g at 95 %%); ",
        cf_spring_type_name(g->type), g->rmse * u, w->rmse * u, r->table->y_unit,
        cf_spring_type_name(w->type), v.delta_rss / base, v.threshold / base);
    if (v.held) {
        app(buf, cap, &n, "%s is held back by", cf_spring_type_name(w->type));
        for (int b = 0; b < CF_C_COUNT; b++)
            if (v.held & (1u << b))
                app(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
    } else {
        app(buf, cap, &n, "no limit of %s is active: its optimiser stopped at a worse point",
            cf_spring_type_name(w->type));
    }
}

/* Where one measure came from, in words: "comment, line 12", "column name", "assumed", ... */
static void source_text(char *buf, size_t cap, cf_decl_source from, size_t line, int overridden,
                        const char *file_value)
{
    size_t n = 0;
    buf[0] = '\0';
    app(buf, cap, &n, "%s", cf_decl_source_name(from));
    if (overridden)
        app(buf, cap, &n, ", which wins over the table's '%s'", file_value);
    if (line)
        app(buf, cap, &n, "%sline %zu", overridden ? " on " : ", ", line);
}

/* The sources of a table's measures (stress, strain) and its mode. */
static void sources_text(const cf_table *t, char src[3][128])
{
    const cf_table_measures *m = &t->measures;
    source_text(src[0], sizeof src[0], m->stress_from, m->stress_line, m->stress_overridden,
                cf_stress_measure_name((cf_stress_measure)m->stress_file));
    source_text(src[1], sizeof src[1], m->strain_from, m->strain_line, m->strain_overridden,
                cf_strain_measure_name((cf_strain_measure)m->strain_file));
    snprintf(src[2], sizeof src[2], "%s", t->mode_stated ? "stated" : "assumed");
}

/* What was done to the stress and strain columns, in one sentence ("" when nothing). */
static void conversion_text(const cf_table *t, char *buf, size_t cap)
{
    const cf_table_measures *m = &t->measures;
    size_t n = 0;
    buf[0] = '\0';
    if (m->strain_converted)
        app(buf, cap, &n, "%s", m->strain == CF_STRAIN_LOG
                                    ? "log strain e converted to engineering strain exp(e) - 1"
                                    : "stretch l converted to engineering strain l - 1");
    if (m->stress_converted) {
        app(buf, cap, &n, "%sCauchy stress converted to nominal ", n ? "; " : "");
        if (t->mode == CF_MODE_SHEAR)
            app(buf, cap, &n, "(simple shear: P12 = sigma12, the sheared face keeps its area)");
        else if (t->mode == CF_MODE_CONFINED)
            app(buf, cap, &n, "(confined: P = sigma, the lateral stretches are 1)");
        else
            app(buf, cap, &n, "P = sigma / (1 + strain), incompressible %s",
                cf_mode_name(t->mode));
    }
}

static json_t *measures_json(const cf_table *t)
{
    const cf_table_measures *m = &t->measures;
    char src[3][128], conv[256];
    sources_text(t, src);
    conversion_text(t, conv, sizeof conv);
    json_t *o = json_pack("{s:s, s:s, s:s, s:s, s:s, s:s}", "stress",
                          cf_stress_measure_name(m->stress), "stress_source", src[0], "strain",
                          cf_strain_measure_name(m->strain), "strain_source", src[1], "mode",
                          cf_mode_name(t->mode), "mode_source", src[2]);
    if (o && *conv) /* absent: the columns were taken as they are */
        json_object_set_new(o, "conversion", json_string(conv));
    return o;
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
    json_t *fits = json_array(), *base = json_array();
    for (int i = 0; i < r->nfits; i++)
        json_array_append_new(fits, fit_json(r, i));
    for (int k = 0; k < CF_BASE_COUNT; k++)
        json_array_append_new(base, baseline_json(r, k));
    json_t *root = json_pack("{s:s, s:o, s:o}", "conifit_version", r->version, "data", data,
                             "fits", fits);
    json_object_set_new(root, "limits", limits_json(r));
    int b = cf_report_better(r), tie = cf_report_types_tie(r);
    if (b >= 0 && !tie) /* absent on a tie (comparison.tie) or when no type has a spring */
        json_object_set_new(root, "better_type", json_string(cf_spring_type_name(r->fits[b].type)));
    if (r->nfits == 2 && b >= 0) {
        int o = 1 - b;
        cf_fit_verdict v = cf_fit_compare(&r->fits[0], &r->fits[1], r->table->count);
        char text[1024];
        verdict_text(r, text, sizeof text);
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
    json_object_set_new(root, "identifiability",
                        json_string("the law depends on the six design parameters only through "
                                    "rho, the solid strain (travel) and the stress (load) scale; "
                                    "params is one member of that family, chosen by the "
                                    "constraints"));
    return root;
}

char *cf_report_json_string(const cf_fit_report *r)
{
    json_t *root = report_json(r);
    if (!root)
        return NULL;
    char *s = cf_fitfile_dumps(root);
    json_decref(root);
    return s;
}

cf_status cf_report_json_prepare(const cf_fit_report *r, const char *path,
                                 const char *const *inputs, struct cf_atomic *out, cf_error *err)
{
    memset(out, 0, sizeof *out);
    json_t *root = report_json(r);
    if (!root)
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory building the report", path);
    cf_status st = cf_fitfile_prepare(root, path, inputs, out, err);
    json_decref(root);
    return st;
}

cf_status cf_report_json_write(const cf_fit_report *r, const char *path,
                               const char *const *inputs, cf_error *err)
{
    cf_atomic a;
    cf_status st = cf_report_json_prepare(r, path, inputs, &a, err);
    if (st == CF_OK)
        st = cf_atomic_commit(&a, err);
    return st;
}

/* ---- text ------------------------------------------------------------------------------------- */

static void row(FILE *o, const cf_fit_report *r, const char *label, const char *fmt, int which)
{
    fprintf(o, "  %-26s", label);
    for (int i = 0; i < r->nfits; i++) {
        const cf_fit_result *f = &r->fits[i];
        const cf_spring *p = &f->params;
        char cell[64];
        double u = r->table->y_to_file;
        switch (which) {
        case 0: case 1: case 2: case 3: case 4: case 5: /* the design parameters (spring.h) */
            snprintf(cell, sizeof cell, fmt, cf_spring_get(p, which)); break;
        case 6: snprintf(cell, sizeof cell, fmt, f->law.index_c); break;
        case 7: snprintf(cell, sizeof cell, fmt, f->law.travel_mm); break;
        case 8: snprintf(cell, sizeof cell, fmt, f->law.F_T_N); break;
        case 9: snprintf(cell, sizeof cell, fmt, f->law.F_C_N); break;
        case 10: snprintf(cell, sizeof cell, fmt, f->rmse * u, r->table->y_unit); break;
        case 11: snprintf(cell, sizeof cell, fmt, f->max_abs_error * u, r->table->y_unit); break;
        case 12: snprintf(cell, sizeof cell, fmt, f->r2); break;
        case 13: snprintf(cell, sizeof cell, fmt, cf_report_fit_aic(r, i)); break;
        case 14: snprintf(cell, sizeof cell, fmt, f->law.k0_N_per_mm); break;
        default: cell[0] = '\0';
        }
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
}

/* Significant digits that tell the ends of the interval [lo, hi] from the value v: 3, or more
** when an end lies closer to v than 3 digits show (a precise or long table), at most 17. */
static int interval_digits(double v, double lo, double hi)
{
    double w = INFINITY;
    if (v - lo > 0)
        w = v - lo;
    if (hi - v > 0)
        w = fmin(w, hi - v);
    if (!(v != 0) || !isfinite(w))
        return 3;
    double d = floor(log10(fabs(v))) - floor(log10(w)) + 1;
    return (int)fmin(17, fmax(3, d));
}

/* value ± standard error, or value [low, high] (the profile interval, marked *) */
static void ident_row(FILE *o, const cf_fit_report *r, const char *label, int k, double scale,
                      const char *unit)
{
    fprintf(o, "  %-26s", label);
    for (int i = 0; i < r->nfits; i++) {
        char cell[96];
        const cf_fit_result *f = &r->fits[i];
        const char *sp = *unit ? " " : "";
        if (f->interval_ok[k]) {
            const double v = f->ident.v[k] * scale, lo = f->interval[k][0] * scale,
                         hi = f->interval[k][1] * scale;
            const int dg = interval_digits(v, lo, hi);
            snprintf(cell, sizeof cell, "%.*g [%.*g, %.*g]*%s%s", dg > 4 ? dg : 4, v, dg, lo, dg,
                     hi, sp, unit);
        }
        else if (f->ident_se.v[k] >= 0)
            snprintf(cell, sizeof cell, "%.6g ± %.2g%s%s", f->ident.v[k] * scale,
                     f->ident_se.v[k] * scale, sp, unit);
        else /* uncertainty() computes an interval wherever the error is undetermined */
            snprintf(cell, sizeof cell, "%.6g%s%s (no error: placed, not fitted)",
                     f->ident.v[k] * scale, sp, unit);
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
}

/* Below the table: what each starred interval means, per type and quantity. */
static void interval_notes(FILE *o, const cf_fit_report *r, const char *const names[3])
{
    for (int i = 0; i < r->nfits; i++)
        for (int k = 0; k < 3; k++) {
            const cf_fit_result *f = &r->fits[i];
            if (!f->interval_ok[k])
                continue;
            char why[512];
            interval_reason(f, k, why, sizeof why);
            fprintf(o, "  * %s, %s: %s\n", cf_spring_type_name(f->type), names[k], why);
        }
}

/* One cell per fit from a printf format and a value (MPa values are converted by the caller). */
static void cells(FILE *o, const cf_fit_report *r, const char *label, const char *const *text)
{
    fprintf(o, "  %-26s", label);
    for (int i = 0; i < r->nfits; i++)
        fprintf(o, " %-24s", text[i]);
    fputc('\n', o);
}

/* The lattice the validation ran (the setup of a fit it was done for), its moduli, the test mode
** and what the fit targeted. */
static void validation_header(FILE *o, const cf_fit_report *r)
{
    const cf_validate_setup *su = &r->val[0].setup;
    const cf_validation *v0 = &r->val[0];
    for (int i = 0; i < r->nfits; i++)
        if (r->val[i].done) {
            su = &r->val[i].setup;
            v0 = &r->val[i];
        }
    const cf_lattice_config *lc = &su->cfg.lattice;
    cf_cubic_moduli cm = cf_cubic_moduli_of(lc->weight);
    fprintf(o,
            " validation in the lattice (%d x %d x %d cells, calibration %s: weights edge %.4g, "
            "face %.4g, body %.4g; small-strain modulus %.4g x k0/H, nu %.3f; bottom %s, %s):\n",
            lc->nx, lc->ny, lc->nz, cf_calibration_name(lc->calibration),
            lc->weight[CF_FAMILY_EDGE], lc->weight[CF_FAMILY_FACE], lc->weight[CF_FAMILY_BODY],
            cm.E, cm.nu, lc->bottom == CF_BOTTOM_CLAMPED ? "clamped" : "axial",
            cf_law_method_name(su->method));
    fprintf(o, "  mode %s, %s; fit target: %s\n", cf_mode_name(v0->mode),
            v0->by_cell ? "homogenised cell (the full lattice has no such boundary conditions)"
                        : "full lattice",
            r->through_msm ? "the lattice (through the homogenised cell)" : "the single spring");
}

/* Prints rows k < nrows of buf (one cell per fit) under their labels. */
static void cell_rows(FILE *o, const cf_fit_report *r, char (*buf)[2][64], int nrows,
                      const char *const *labels)
{
    const char *t[2];
    for (int k = 0; k < nrows; k++) {
        for (int i = 0; i < r->nfits; i++)
            t[i] = buf[k][i];
        cells(o, r, labels[k], t);
    }
}

/* The validation's numbers, one column per fit. */
static void validation_rows(FILE *o, const cf_fit_report *r)
{
    enum { ROWS = 7 };
    char buf[ROWS][2][64];
    const double u = r->table->y_to_file;
    const char *yu = r->table->y_unit;
    for (int i = 0; i < r->nfits; i++) {
        const cf_validation *v = &r->val[i];
        if (!v->done) {
            for (int k = 0; k < ROWS; k++)
                snprintf(buf[k][i], sizeof buf[k][i], k ? "" : "skipped (see below)");
            continue;
        }
        const cf_through_msm *th = &r->thr[i];
        double fr = r->through_msm && th->done ? th->cell_rmse : r->fits[i].rmse;
        snprintf(buf[0][i], sizeof buf[0][i], "%.4g %s", fr * u, yu);
        snprintf(buf[1][i], sizeof buf[1][i], "%.4g %s", v->rmse * u, yu);
        if (isfinite(v->law_rmse))
            snprintf(buf[2][i], sizeof buf[2][i], "%.4g %s", v->law_rmse * u, yu);
        else
            snprintf(buf[2][i], sizeof buf[2][i], "- (not uniaxial)");
        snprintf(buf[3][i], sizeof buf[3][i], "%.4g %s", v->max_abs_error * u, yu);
        snprintf(buf[4][i], sizeof buf[4][i], "%.6f", v->r2);
        snprintf(buf[5][i], sizeof buf[5][i], "%.1f ms, %zu solves", 1e3 * v->wall_time_s,
                 v->solves);
        if (!v->stability_checked)
            snprintf(buf[6][i], sizeof buf[6][i], "not checked");
        else if (v->stable_to_strain == 0)
            snprintf(buf[6][i], sizeof buf[6][i], "to solid");
        else
            snprintf(buf[6][i], sizeof buf[6][i], "to strain %.4g%s", v->stable_to_strain,
                     v->unstable_in_range ? " (!)" : "");
    }
    static const char *const labels[ROWS] = {"fit RMSE (its target)", "lattice RMSE",
                                             "lattice vs law (RMSE)", "lattice max |error|",
                                             "lattice R^2", "lattice time", "lattice stable"};
    cell_rows(o, r, buf, ROWS, labels);
}

/* The fit through the lattice: its RMSE before and after, its check in the full lattice, cost. */
static void through_rows(FILE *o, const cf_fit_report *r)
{
    char buf[3][2][64];
    const double u = r->table->y_to_file;
    const char *yu = r->table->y_unit;
    for (int i = 0; i < r->nfits; i++) {
        const cf_through_msm *th = &r->thr[i];
        if (th->done)
            snprintf(buf[0][i], sizeof buf[0][i], "%.4g -> %.4g %s", th->rmse_before * u,
                     th->cell_rmse * u, yu);
        else
            snprintf(buf[0][i], sizeof buf[0][i], "not run");
        if (th->done && th->verified)
            snprintf(buf[1][i], sizeof buf[1][i], "max |full - cell| %.3g %s",
                     th->verify_max_abs * u, yu);
        else
            snprintf(buf[1][i], sizeof buf[1][i], "%s", th->done ? "cell only" : "");
        snprintf(buf[2][i], sizeof buf[2][i], "%.3f s, %ld cell curves", th->wall_time_s,
                 th->evaluations);
    }
    static const char *const tl[3] = {"through lattice: RMSE", "verified in full lattice",
                                      "through lattice: cost"};
    cell_rows(o, r, buf, 3, tl);
}

/* The lattice validation (and the fit through the lattice) beside the single-spring quality. */
static void validation_text(FILE *o, const cf_fit_report *r)
{
    int any = 0;
    for (int i = 0; i < r->nfits; i++)
        any |= r->val[i].done;
    if (!any) {
        fprintf(o, " validation in the lattice: skipped: %s\n", r->val[0].note);
        return;
    }
    validation_header(o, r);
    validation_rows(o, r);
    for (int i = 0; i < r->nfits; i++)
        if (r->val[i].done && r->val[i].unstable_in_range)
            fprintf(o, "  (!) %s: the lattice loses stability at strain %.4g, inside the table's "
                    "range: past it the static curve is an unstable equilibrium (a column of "
                    "cells buckles sideways in a dynamic run)\n",
                    cf_spring_type_name(r->fits[i].type), r->val[i].stable_to_strain);
    if (r->through_msm)
        through_rows(o, r);
    for (int i = 0; i < r->nfits; i++)
        if (!r->val[i].done)
            fprintf(o, "  (%s: validation skipped: %s)\n", cf_spring_type_name(r->fits[i].type),
                    r->val[i].note);
}

/* The table: its size, columns, sign, and (stress-strain) its measures and their conversion. */
static void table_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, "%s: %zu points, %s [%s] against %s [%s], %s\n", r->table->path, r->table->count,
            r->table->x_column, r->table->x_unit, r->table->y_column, r->table->y_unit,
            r->table->compression ? "compression negative" : "tension positive");
    if (cf_table_is_force(r->table))
        return;
    const cf_table_measures *m = &r->table->measures;
    char src[3][128], conv[256];
    sources_text(r->table, src);
    conversion_text(r->table, conv, sizeof conv);
    fprintf(o, " measures: stress %s (%s), strain %s (%s), mode %s (%s)\n",
            cf_stress_measure_name(m->stress), src[0], cf_strain_measure_name(m->strain), src[1],
            cf_mode_name(r->table->mode), src[2]);
    if (*conv)
        fprintf(o, " fitted as engineering strain and nominal stress: %s\n", conv);
    fputc('\n', o);
}

/* The three quantities the data determine, their intervals, correlations and distance to solid. */
static void identifiable_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, " identifiable (determined by the data):\n");
    ident_row(o, r, "rho = D1/D2", 0, 1, "");
    if (cf_table_is_force(r->table)) {
        ident_row(o, r, "travel s", 1, 1, "mm");
        ident_row(o, r, "solid load F_C", 2, 1, "N");
    } else {
        ident_row(o, r, "solid strain s/H", 1, 1, "");
        ident_row(o, r, "stress scale F_C/H^2", 2, r->table->y_to_file, r->table->y_unit);
    }
    static const char *const ss_names[3] = {"rho", "solid strain", "stress scale"};
    static const char *const fd_names[3] = {"rho", "travel", "solid load"};
    interval_notes(o, r, cf_table_is_force(r->table) ? fd_names : ss_names);
    fprintf(o, "  %-26s", "correlation rho-s, rho-A, s-A");
    for (int i = 0; i < r->nfits; i++) {
        char cell[64];
        const cf_fit_result *f = &r->fits[i];
        if (isfinite(f->corr[0][1]))
            snprintf(cell, sizeof cell, "%.3f, %.3f, %.3f", f->corr[0][1], f->corr[0][2],
                     f->corr[1][2]);
        else
            snprintf(cell, sizeof cell, "not determined");
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
    fprintf(o, "  %-26s", cf_table_is_force(r->table) ? "solid / largest |u|" : "solid / largest |strain|");
    for (int i = 0; i < r->nfits; i++) {
        char cell[64];
        const cf_fit_result *f = &r->fits[i];
        snprintf(cell, sizeof cell, "%.3g%s", f->solid_ratio,
                 f->solid_ratio < CF_FIT_SOLID_RATIO_WARN ? " (close to solid!)" : "");
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
}

/* One spring of the family (the field table's parameters and what follows from them), and the
** fit's quality. */
static void spring_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, " one spring of that family (chosen by the constraints):\n");
    for (int k = 0; k < CF_P_COUNT; k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        char fmt[32];
        snprintf(fmt, sizeof fmt, "%%.6g%s%s", strcmp(sp->unit, "-") ? " " : "",
                 strcmp(sp->unit, "-") ? sp->unit : "");
        row(o, r, sp->name, fmt, k);
    }
    row(o, r, "spring index c = D1/d", "%.4g", 6);
    row(o, r, "travel s", "%.6g mm", 7);
    row(o, r, "F_T, F_C", "%.4g N", 8);
    row(o, r, "", "%.4g N", 9);
    row(o, r, "k0", "%.6g N/mm", 14);
    fprintf(o, " quality:\n");
    row(o, r, "RMSE", "%.4g %s", 10);
    row(o, r, "max |error|", "%.4g %s", 11);
    row(o, r, "R^2", "%.6f", 12);
    row(o, r, "AIC (k = 3)", "%.2f", 13);
}

/* One row of constraint names per fit: those of its active (which = 0) or holding (1) mask,
** joined by commas, or `none` when there are none. */
static void constraint_row(FILE *o, const cf_fit_report *r, const char *label, int which,
                           const char *none)
{
    fprintf(o, "  %-26s", label);
    for (int i = 0; i < r->nfits; i++) {
        const cf_fit_result *f = &r->fits[i];
        const unsigned mask = which == 0 ? f->active : f->held;
        char cell[160] = "";
        size_t n = 0;
        for (int k = 0; k < CF_C_COUNT; k++)
            if (mask & (1u << k))
                app(cell, sizeof cell, &n, "%s%s", n ? "," : "", cf_fit_constraint_name(1u << k));
        fprintf(o, " %-24s", n ? cell : none);
    }
    fputc('\n', o);
}

/* Feasibility, the constraints that are active and that hold the spring, the optimiser's cost,
** and the limits the fit ran under. */
static void constraints_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, "  %-26s", "feasible");
    for (int i = 0; i < r->nfits; i++) {
        char cell[160] = "yes";
        if (!r->fits[i].feasible) {
            snprintf(cell, sizeof cell, "NO:");
            for (int k = 0; k < CF_C_COUNT; k++)
                if (r->fits[i].violated & (1u << k))
                    snprintf(cell + strlen(cell), sizeof cell - strlen(cell), " %s",
                             cf_fit_constraint_name(1u << k));
        }
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
    constraint_row(o, r, "active constraints", 0, "none");
    fprintf(o, "  %-26s", "optimizer, evaluations");
    for (int i = 0; i < r->nfits; i++) {
        char cell[64];
        snprintf(cell, sizeof cell, "%s, %ld, %.1f ms", r->fits[i].optimizer,
                 r->fits[i].evaluations, 1e3 * r->fits[i].wall_time_s);
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
    constraint_row(o, r, "held by", 1, "nothing");
    const cf_fit_options *fo = &r->fit_options;
    fprintf(o, "  limits: rho >= %g, %g <= n <= %g, 3 <= D1/d <= %g, D2 <= %g H, G <= %g MPa "
               "(flags --rho-min, --n-max, --index-max, --D2-max-H, --G-max)\n",
            fo->rho_min, fo->lower[CF_P_N], fo->upper[CF_P_N], fo->index_max, fo->D2_over_H_max,
            fo->upper[CF_P_G]);
}

/* The verdict on the type, the baselines, and what the six numbers mean. */
static void verdict_and_baselines(FILE *o, const cf_fit_report *r)
{
    int b = cf_report_better(r);
    if (r->nfits == 2 && b >= 0) {
        char text[1024];
        verdict_text(r, text, sizeof text);
        fprintf(o, "\nType: %s\n", text);
    } else if (b < 0) {
        fprintf(o, "\nNo feasible fit: no spring meets every constraint on this table (see "
                   "'feasible' above).\n");
    }
    fprintf(o, "\nBaselines (plain least squares):\n");
    for (int k = 0; k < CF_BASE_COUNT; k++) {
        const cf_baseline *bl = &r->baselines[k];
        char co[96];
        double u = r->table->y_to_file;
        if (bl->kind == CF_BASE_LINEAR)
            snprintf(co, sizeof co, "E = %.4g %s", bl->coef[0] * u, r->table->y_unit);
        else if (bl->kind == CF_BASE_DUFFING)
            snprintf(co, sizeof co, "k1 = %.4g, k3 = %.4g %s", bl->coef[0] * u, bl->coef[1] * u,
                     r->table->y_unit);
        else
            snprintf(co, sizeof co, "A = %.4g %s, B = %.4g", bl->coef[0] * u, r->table->y_unit,
                     bl->coef[1]);
        fprintf(o, "  %-8s %-36s RMSE %.4g %s   AIC %.2f (k = %d)\n", cf_baseline_name(bl->kind), co,
                bl->rmse * u, r->table->y_unit, cf_report_baseline_aic(r, k), bl->k);
    }
    fprintf(o, "\nThe law seen through this table depends on the six design parameters only through "
               "rho,\nthe %s and the %s. The six numbers above are one member of a family of "
               "equally\ngood springs, chosen by the constraints (spring index, n >= 2, type, "
               "bounds, fixed values).\n",
            cf_table_is_force(r->table) ? "travel" : "solid strain",
            cf_table_is_force(r->table) ? "solid load" : "stress scale");
}

char *cf_report_text(const cf_fit_report *r)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *o = open_memstream(&buf, &len);
    if (!o)
        return NULL;
    table_text(o, r);
    fprintf(o, "  %-26s", "");
    for (int i = 0; i < r->nfits; i++)
        fprintf(o, " %-24s", cf_spring_type_name(r->fits[i].type));
    fputc('\n', o);
    identifiable_text(o, r);
    spring_text(o, r);
    if (r->validate)
        validation_text(o, r);
    constraints_text(o, r);
    verdict_and_baselines(o, r);
    fclose(o);
    return buf;
}
