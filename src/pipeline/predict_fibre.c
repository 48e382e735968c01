/*
** The fibre-frame models of a fit file predicted at tables (predict_fibre.h).
*/
#include "pipeline/predict_fibre.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/input.h"
#include "fit/joint.h"
#include "io/fitfile_json.h"

static const char *const ho_keys[CF_HO_NP] = {"a", "b", "a_f", "b_f", "a_s", "b_s", "a_fs",
                                              "b_fs"};

/* The finite number o[key] into *v (times mul); CF_E_DATA naming where and key otherwise. */
static cf_status number(const json_t *o, const char *key, double mul, double *v,
                        const char *path, const char *where, cf_error *err)
{
    const json_t *j = json_object_get(o, key);
    if (!json_is_number(j) || !isfinite(json_number_value(j)))
        return cf_error_set(err, CF_E_DATA, "%s: %s.%s: %s", path, where, key,
                            j ? "not a finite number" : "missing");
    *v = json_number_value(j) * mul;
    return CF_OK;
}

/* The cross axis o["cross_axis"] ('n' or 's') into *c. */
static cf_status cross_of(const json_t *o, char *c, const char *path, const char *where,
                          cf_error *err)
{
    const char *s = json_string_value(json_object_get(o, "cross_axis"));
    if (!s || (strcmp(s, "n") != 0 && strcmp(s, "s") != 0))
        return cf_error_set(err, CF_E_DATA, "%s: %s.cross_axis: not \"n\" or \"s\"", path, where);
    *c = s[0];
    return CF_OK;
}

/* One family {rho, solid_strain, stress_scale_kPa} into q. */
static cf_status family(const json_t *o, cf_ident *q, const char *path, const char *where,
                        cf_error *err)
{
    if (!json_is_object(o))
        return cf_error_set(err, CF_E_DATA, "%s: %s: missing or not an object", path, where);
    cf_status st = number(o, "rho", 1.0, &q->rho, path, where, err);
    if (st == CF_OK)
        st = number(o, "solid_strain", 1.0, &q->solid, path, where, err);
    if (st == CF_OK)
        st = number(o, "stress_scale_kPa", 1e-3, &q->scale, path, where, err);
    return st;
}

/* A "fibre_lattice" entry e (index k) into m. */
static cf_status lattice_entry(const json_t *e, size_t k, cf_pf_model *m, const char *path,
                               cf_error *err)
{
    char where[64];
    snprintf(where, sizeof where, "fibre_lattice[%zu]", k);
    cf_fibre_fit *f = &m->lattice;
    m->kind = CF_PF_LATTICE;
    cf_status st = cross_of(e, &m->cross, path, where, err);
    f->cross = m->cross;
    if (st == CF_OK)
        st = family(json_object_get(e, "matrix"), &f->matrix, path, where, err);
    if (st == CF_OK)
        st = number(e, "volume_modulus_kPa", 1e-3, &f->kappa_MPa, path, where, err);
    if (st == CF_OK)
        st = number(e, "objective", 1.0, &m->fit_objective, path, where, err);
    const json_t *fw = json_object_get(e, "family_weights"); /* absent: equal (all 0 here) */
    for (int q = 0; st == CF_OK && fw && q < CF_FAMILY_COUNT; q++) {
        const json_t *v = json_array_get(fw, (size_t)q);
        f->family[q] = json_is_number(v) ? json_number_value(v) : NAN;
        if (!(f->family[q] >= (q ? 0 : 1e-300)) || !(f->family[q] <= 1e6) ||
            json_array_size(fw) != CF_FAMILY_COUNT)
            st = cf_error_set(err, CF_E_DATA, "%s: %s.family_weights: not [edge > 0, face >= 0, "
                              "body >= 0], each at most 1e6", path, where);
    }
    const json_t *gs = json_object_get(e, "fibre_groups");
    if (st == CF_OK && (!json_is_array(gs) || json_array_size(gs) > CF_FIBRE_MAX))
        return cf_error_set(err, CF_E_DATA, "%s: %s.fibre_groups: not an array of at most %d",
                            path, where, CF_FIBRE_MAX);
    for (size_t g = 0; st == CF_OK && g < json_array_size(gs); g++) {
        const json_t *o = json_array_get(gs, g);
        const char *ax = json_string_value(json_object_get(o, "axis"));
        char gw[128];
        snprintf(gw, sizeof gw, "%s.fibre_groups[%zu]", where, g);
        if (!ax || strlen(ax) != 1 || !strchr("fsn", ax[0]) || strchr(f->groups, ax[0]))
            return cf_error_set(err, CF_E_DATA, "%s: %s.axis: not one of f, s, n (each once)",
                                path, gw);
        f->groups[g] = ax[0];
        f->ngroups = (int)g + 1;
        st = family(o, &f->fibre[g], path, gw, err);
        f->slack[g] = 0; /* a fit file before recruitment: taut at rest */
        if (st == CF_OK && json_object_get(o, "recruitment_strain"))
            st = number(o, "recruitment_strain", 1.0, &f->slack[g], path, gw, err);
        if (st == CF_OK && !(f->slack[g] >= 0 && f->slack[g] < 1))
            st = cf_error_set(err, CF_E_DATA, "%s: %s.recruitment_strain = %g: not in [0, 1)",
                              path, gw, f->slack[g]);
    }
    return st;
}

/* A "holzapfel_ogden" entry e (index k) into m. */
static cf_status ho_entry(const json_t *e, size_t k, cf_pf_model *m, const char *path,
                          cf_error *err)
{
    char where[64];
    snprintf(where, sizeof where, "holzapfel_ogden[%zu]", k);
    const char *model = json_string_value(json_object_get(e, "model"));
    m->kind = model && strcmp(model, "holzapfel-ogden-ti") == 0 ? CF_PF_HO_TI : CF_PF_HO;
    cf_status st = cross_of(e, &m->cross, path, where, err);
    if (st == CF_OK)
        st = number(e, "objective", 1.0, &m->fit_objective, path, where, err);
    const json_t *p = json_object_get(e, "parameters_a_kPa_b_dimensionless");
    char pw[128];
    snprintf(pw, sizeof pw, "%s.parameters_a_kPa_b_dimensionless", where);
    const int np = m->kind == CF_PF_HO_TI ? 4 : CF_HO_NP;
    for (int i = 0; st == CF_OK && i < CF_HO_NP; i++) {
        m->ho[i] = i % 2 ? 1.0 : 0.0; /* the TI form's a_s = a_fs = 0 */
        if (i < np)
            st = number(p, ho_keys[i], i % 2 ? 1.0 : 1e-3, &m->ho[i], path, pw, err);
    }
    return st;
}

/* The entries of both objects of root into r. */
static cf_status read_models(const json_t *root, cf_pf_result *r, const char *path,
                             cf_error *err)
{
    const json_t *fl = json_object_get(root, "fibre_lattice");
    const json_t *ho = json_object_get(root, "holzapfel_ogden");
    cf_status st = CF_OK;
    for (size_t k = 0; st == CF_OK && k < json_array_size(fl) && r->n < CF_PF_MAX; k++)
        st = lattice_entry(json_array_get(fl, k), k, &r->m[r->n++], path, err);
    for (size_t k = 0; st == CF_OK && k < json_array_size(ho) && r->n < CF_PF_MAX; k++)
        st = ho_entry(json_array_get(ho, k), k, &r->m[r->n++], path, err);
    return st;
}

/* Model m at the rows of table t (k its index) into m->rmse_MPa[k], m->term[k]. */
static cf_status eval_table(cf_pf_model *m, const cf_fibre_model *cell, const cf_table *t,
                            size_t k, const double *sw, cf_error *err)
{
    int axes[2];
    if (cf_ho_axes(t, m->cross, axes) != 0)
        return CF_OK;
    double ss = 0, term = 0;
    for (size_t i = 0; i < t->count; i++) {
        double y = 0;
        if (m->kind == CF_PF_LATTICE) {
            if (cf_fibre_row_stress(cell, t, i, axes, &y, NULL) != CF_OK) {
                m->failed_row[k] = i + 1;
                return CF_OK;
            }
        } else {
            y = cf_ho_row_stress(m->ho, t, i, axes);
        }
        if (!isfinite(y))
            return cf_error_set(err, CF_E_DATA, "%s: row %zu: the model's stress is not finite",
                                t->path, i + 1);
        const double d = y - t->y[i];
        ss += d * d;
        term += sw[i] * sw[i] * d * d;
    }
    m->rmse_MPa[k] = sqrt(ss / (double)t->count);
    m->term[k] = term;
    m->sum_terms += term;
    return CF_OK;
}

/* Every model of r at every table that lies in the fibre frame. */
static cf_status eval_all(cf_pf_result *r, const cf_table *const *t, size_t n, cf_error *err)
{
    cf_status st = CF_OK;
    for (int j = 0; st == CF_OK && j < r->n; j++) {
        cf_pf_model *m = &r->m[j];
        m->rmse_MPa = calloc(n + 1, sizeof(double));
        m->term = calloc(n + 1, sizeof(double));
        m->failed_row = calloc(n + 1, sizeof(size_t));
        if (!m->rmse_MPa || !m->term || !m->failed_row)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory");
        cf_fibre_model cell;
        memset(&cell, 0, sizeof cell);
        if (m->kind == CF_PF_LATTICE && (st = cf_fibre_model_init(&cell, &m->lattice, err)))
            return st;
        for (size_t k = 0; st == CF_OK && k < n; k++) {
            double *sw = malloc((t[k]->count + 1) * sizeof(double));
            if (!sw)
                st = cf_error_set(err, CF_E_INTERNAL, "out of memory");
            else if (r->ok[k] && cf_joint_table_weights(t[k], &r->rms_MPa[k], sw) == 0)
                st = eval_table(m, &cell, t[k], k, sw, err);
            free(sw);
        }
        if (m->kind == CF_PF_LATTICE)
            cf_fibre_model_free(&cell);
    }
    return st;
}

cf_status cf_pf_predict(const char *path, const cf_table *const *tables, size_t n,
                        cf_pf_result *r, cf_error *err)
{
    memset(r, 0, sizeof *r);
    FILE *f = cf_input_open(path, "fit file", err);
    if (!f)
        return CF_E_NOINPUT;
    json_error_t jerr;
    json_t *root = json_loadf(f, JSON_REJECT_DUPLICATES, &jerr);
    fclose(f);
    char why[JSON_ERROR_TEXT_LENGTH];
    if (!root)
        return cf_error_set(err, CF_E_DATA, "%s:%d:%d: not a valid fit file: %s", path,
                            jerr.line, jerr.column, cf_json_reason(&jerr, why, sizeof why));
    cf_status st = read_models(root, r, path, err);
    json_decref(root);
    if (st != CF_OK || r->n == 0)
        return st;
    r->ntables = n;
    r->ok = calloc(n + 1, 1);
    r->rms_MPa = calloc(n + 1, sizeof(double));
    if (!r->ok || !r->rms_MPa)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    for (size_t k = 0; k < n; k++) {
        int axes[2];
        r->ok[k] = cf_ho_axes(tables[k], 'n', axes) == 0;
    }
    return eval_all(r, tables, n, err);
}

void cf_pf_free(cf_pf_result *r)
{
    if (!r)
        return;
    for (int j = 0; j < r->n; j++) {
        free(r->m[j].rmse_MPa);
        free(r->m[j].term);
        free(r->m[j].failed_row);
    }
    free(r->ok);
    free(r->rms_MPa);
    memset(r, 0, sizeof *r);
}

static const char *model_name(const cf_pf_model *m)
{
    return m->kind == CF_PF_LATTICE ? "fibre lattice"
           : m->kind == CF_PF_HO    ? "Holzapfel-Ogden full"
                                    : "Holzapfel-Ogden TI";
}

/* One cross axis's block: a row per table, a column per model of that axis. */
static void cross_block(FILE *o, const cf_pf_result *r, const cf_table *const *tables, char cross)
{
    int idx[CF_PF_MAX], n = 0;
    for (int j = 0; j < r->n; j++)
        if (r->m[j].cross == cross)
            idx[n++] = j;
    if (n == 0)
        return;
    fprintf(o, "  biaxial second direction along %c:\n    %-36s", cross, "table");
    for (int j = 0; j < n; j++)
        fprintf(o, " %-26s", model_name(&r->m[idx[j]]));
    for (size_t k = 0; k < r->ntables; k++) {
        char name[128];
        cf_table_name(tables[k], name, sizeof name);
        fprintf(o, "\n    %-36s", name);
        for (int j = 0; j < n; j++) {
            const cf_pf_model *m = &r->m[idx[j]];
            char cell[64] = "not in the fibre frame";
            if (r->ok[k] && m->failed_row[k])
                snprintf(cell, sizeof cell, "no cell state at row %zu", m->failed_row[k]);
            else if (r->ok[k])
                snprintf(cell, sizeof cell, "%.4g %s (%.4g)",
                         m->rmse_MPa[k] * tables[k]->y_to_file, tables[k]->y_unit, m->term[k]);
            fprintf(o, " %-26s", cell);
        }
    }
    fprintf(o, "\n    %-36s", "sum of the terms (-)");
    for (int j = 0; j < n; j++)
        fprintf(o, " %-26.4g", r->m[idx[j]].sum_terms);
    fprintf(o, "\n    %-36s", "the fit's own objective (-)");
    for (int j = 0; j < n; j++)
        fprintf(o, " %-26.4g", r->m[idx[j]].fit_objective);
    fprintf(o, "\n");
}

void cf_pf_text(FILE *o, const cf_pf_result *r, const cf_table *const *tables)
{
    if (r->n == 0)
        return;
    fprintf(o, "\nFibre-frame models of the fit file, without refitting (each at its biaxial "
               "cross-fibre axis; per table the RMSE in the table's unit and, in brackets, its "
               "term (RMSE / RMS stress)^2; the fit's own objective is over the tables it was "
               "fitted to):\n");
    cross_block(o, r, tables, 'n');
    cross_block(o, r, tables, 's');
}
