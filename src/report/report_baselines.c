/*
** The baselines in a fit report (see report_baselines.h).
*/
#include "report/report_baselines.h"

#include <stdio.h>

#include "io/fitfile_json.h"
#include "report/report_words.h"

/* The names of baseline kind's coefficients, and which are in the stress (force) unit: the
** others are per unit x (Fung's B) or dimensionless (Ogden's alpha). Returns their count. */
double cf_report_baseline_aic(const cf_fit_report *r, int k)
{
    double f = r->table->y_to_file;
    return cf_baseline_aic(r->table->count, r->baselines[k].rss * f * f, r->baselines[k].k, r->ymax * f);
}

static int coefficient_names(cf_baseline_kind kind, const char *name[3], int in_y[3])
{
    static const char *const names[CF_BASE_COUNT][3] = {
        [CF_BASE_LINEAR] = {"E"},          [CF_BASE_DUFFING] = {"k1", "k3"},
        [CF_BASE_FUNG] = {"A", "B"},       [CF_BASE_YEOH] = {"C1", "C2", "C3"},
        [CF_BASE_OGDEN] = {"mu", "alpha"},
    };
    int n = 0;
    for (; n < 3 && kind < CF_BASE_COUNT && names[kind][n]; n++) {
        name[n] = names[kind][n];
        in_y[n] = !(kind == CF_BASE_FUNG && n == 1) && !(kind == CF_BASE_OGDEN && n == 1);
    }
    return n;
}

void cf_report_baseline_coefficients(const cf_fit_report *r, int k, char *buf, size_t cap)
{
    const cf_baseline *b = &r->baselines[k];
    const char *name[3];
    int in_y[3];
    const int n = coefficient_names(b->kind, name, in_y);
    size_t used = 0;
    buf[0] = '\0';
    for (int j = 0; j < n; j++) {
        cf_report_append(buf, cap, &used, "%s%s = %.4g", j ? ", " : "", name[j],
                         b->coef[j] * (in_y[j] ? r->table->y_to_file : 1.0));
        if (in_y[j] && (j + 1 == n || !in_y[j + 1]))
            cf_report_append(buf, cap, &used, " %s", r->table->y_unit);
    }
}

json_t *cf_report_baseline_json(const cf_fit_report *r, int k)
{
    const cf_baseline *b = &r->baselines[k];
    const double u = r->table->y_to_file;
    json_t *o = json_pack("{s:s, s:s}", "model", cf_baseline_name(b->kind), "formula",
                          cf_baseline_formula(b->kind, b->form));
    if (!o)
        return NULL;
    if (b->kind == CF_BASE_YEOH || b->kind == CF_BASE_OGDEN)
        json_object_set_new(o, "form", json_string(cf_mode_name(b->form)));
    if (!b->fitted) {
        json_object_set_new(o, "parameters", json_integer(b->k));
        json_object_set_new(o, "reason", json_string(b->why));
        return o;
    }
    /* coefficients in the file's y unit (per unit x), Fung's B per unit x, Ogden's alpha bare */
    const char *name[3];
    int in_y[3];
    const int n = coefficient_names(b->kind, name, in_y);
    json_t *coef = json_object();
    for (int j = 0; j < n; j++)
        json_object_set_new(coef, name[j], cf_json_number(b->coef[j] * (in_y[j] ? u : 1.0)));
    json_object_set_new(o, "coefficients", coef);
    json_object_set_new(o, "parameters", json_integer(b->k));
    json_object_set_new(o, "rmse", cf_json_number(b->rmse * u));
    json_object_set_new(o, "aic", cf_json_number(cf_report_baseline_aic(r, k)));
    return o;
}
