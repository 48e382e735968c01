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

/* ---- the Holzapfel-Ogden baselines of a joint fit -------------------------------------------- */

static const char *const ho_names[CF_HO_NP] = {"a", "b", "a_f", "b_f", "a_s", "b_s", "a_fs",
                                               "b_fs"};

/* One fit's parameters (the a's in the first table's unit) and objective. */
static void ho_line(FILE *o, const cf_joint_report *r, const cf_ho_fit *h)
{
    const cf_table *t0 = r->tables[0];
    fprintf(o, "    %s (%d):", h->form == CF_HO_TI ? "transversely isotropic" : "full",
            h->nparams);
    for (int k = 0; k < CF_HO_NP; k++) {
        if (h->form == CF_HO_TI && k >= 4)
            break;
        if (k % 2)
            fprintf(o, " %s %.4g%s", ho_names[k], h->p[k], k + 1 < h->nparams ? "," : "");
        else
            fprintf(o, " %s %.4g %s,", ho_names[k], h->p[k] * t0->y_to_file, t0->y_unit);
    }
    fprintf(o, "; weighted objective %.4g\n      RMSE:", h->objective);
    for (size_t k = 0; k < h->ntables; k++) {
        char name[128];
        cf_table_name(r->tables[k], name, sizeof name);
        fprintf(o, "%s %s %.4g %s", k ? "," : "", name, h->rmse_MPa[k] * r->tables[k]->y_to_file,
                r->tables[k]->y_unit);
    }
    fprintf(o, "\n");
}

void cf_report_ho_text(FILE *o, const cf_joint_report *r, int b)
{
    if (!r->ho_ran && !r->ho_why[0])
        return;
    fprintf(o, "\nHolzapfel-Ogden baselines (Holzapfel & Ogden 2009, incompressible, nominal "
               "stress; fitted jointly with the lattice's weighted objective)");
    if (!r->ho_ran) {
        fprintf(o, ": not fitted: %s\n", r->ho_why);
        return;
    }
    fprintf(o, ":\n");
    for (int c = 1; c >= 0; c--) {
        fprintf(o, "  biaxial tables' second direction along %s%s:\n", c ? "n" : "s",
                c ? " (conifit's choice: the cross-fibre direction of a slab cut in the wall "
                    "plane is the sheet-normal, as the data's source models it)"
                  : " (the sheet term then stiffens the cross-fibre direction, which the law "
                    "has no term for along n)");
        for (int f = CF_HO_FULL; f <= CF_HO_TI; f++)
            ho_line(o, r, &r->ho[f][c]);
    }
    if (b >= 0 && b < r->nfits)
        fprintf(o, "  the isotropic lattice (%s): weighted objective %.4g\n",
                cf_spring_type_name(r->fits[b].fit.type), r->fits[b].objective);
}

json_t *cf_report_ho_json(const cf_joint_report *r)
{
    if (!r->ho_ran)
        return NULL;
    json_t *a = json_array();
    for (int c = 0; a && c < 2; c++)
        for (int f = CF_HO_FULL; f <= CF_HO_TI; f++) {
            const cf_ho_fit *h = &r->ho[f][c];
            json_t *e = json_object(), *p = json_object(), *rm = json_array();
            if (!e || !p || !rm || json_array_append_new(a, e) != 0) {
                json_decref(e);
                json_decref(p);
                json_decref(rm);
                json_decref(a);
                return NULL;
            }
            for (int k = 0; k < h->nparams; k++)
                json_object_set_new(p, k % 2 ? ho_names[k] : ho_names[k],
                                    cf_json_number(k % 2 ? h->p[k] : h->p[k] * 1e3));
            for (size_t k = 0; k < h->ntables; k++)
                json_array_append_new(rm, cf_json_number(h->rmse_MPa[k] * 1e3));
            json_object_set_new(e, "model", json_string(f == CF_HO_TI ? "holzapfel-ogden-ti"
                                                                      : "holzapfel-ogden"));
            json_object_set_new(e, "cross_axis", json_string(c ? "n" : "s"));
            json_object_set_new(e, "parameters_a_kPa_b_dimensionless", p);
            json_object_set_new(e, "objective", cf_json_number(h->objective));
            json_object_set_new(e, "rmse_kPa", rm);
        }
    return a;
}
