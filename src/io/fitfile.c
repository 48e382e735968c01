/*
** Reading fitted springs back from a conifit fit file (see fitfile.h for the schema).
*/
#include "io/fitfile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "base/atomic.h"
#include "base/input.h"
#include "io/fitfile_json.h"
#include "model/calibration.h"

static void copy_string(json_t *obj, const char *key, char *dst, size_t cap)
{
    const char *s = json_string_value(json_object_get(obj, key));
    snprintf(dst, cap, "%s", s ? s : "");
}

/* The Prony terms {"g", "tau_s"} and the dashpot {"eta_kPa_s"} of a viscoelastic fit, checked
** as the lattice takes them (msm.h). */
static cf_status read_visco(json_t *fit, const char *path, const char *where,
                            cf_fitted_spring *out, cf_error *err)
{
    json_t *pr = json_object_get(fit, "prony");
    out->viscoelastic = 0;
    out->prony_count = 0;
    out->eta_MPa_s = 0;
    if (!pr)
        return CF_OK;
    if (!json_is_array(pr) || json_array_size(pr) > CF_PRONY_MAX)
        return cf_error_set(err, CF_E_DATA, "%s: %s.prony must be a list of at most %d terms",
                            path, where, CF_PRONY_MAX);
    cf_msm_effects fx;
    memset(&fx, 0, sizeof fx);
    size_t i;
    json_t *term;
    json_array_foreach(pr, i, term)
    {
        json_t *g = json_object_get(term, "g"), *tau = json_object_get(term, "tau_s");
        json_t *k = json_object_get(term, "g_per_strain");
        if (!json_is_number(g) || !json_is_number(tau))
            return cf_error_set(err, CF_E_DATA, "%s: %s.prony[%zu] needs numbers 'g' and 'tau_s'",
                                path, where, i);
        if (k && !json_is_number(k))
            return cf_error_set(err, CF_E_DATA, "%s: %s.prony[%zu].g_per_strain must be a number",
                                path, where, i);
        fx.prony_g[i] = json_number_value(g);
        fx.prony_tau_s[i] = json_number_value(tau);
        fx.prony_k[i] = k ? json_number_value(k) : 0.0;
    }
    fx.prony_count = (int)json_array_size(pr);
    cf_error e = {0};
    if (cf_msm_prony_check(&fx, &e) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: %s.prony: %s", path, where, e.msg);
    json_t *dp = json_object_get(fit, "dashpot"), *eta = json_object_get(dp, "eta_kPa_s");
    if (dp && !json_is_null(dp)) {
        if (!json_is_number(eta) || !(json_number_value(eta) >= 0) ||
            !isfinite(json_number_value(eta)))
            return cf_error_set(err, CF_E_DATA,
                                "%s: %s.dashpot.eta_kPa_s must be a finite number >= 0", path,
                                where);
        out->eta_MPa_s = json_number_value(eta) * 1e-3;
    }
    out->viscoelastic = 1;
    out->prony_count = fx.prony_count;
    memcpy(out->prony_g, fx.prony_g, sizeof out->prony_g);
    memcpy(out->prony_tau_s, fx.prony_tau_s, sizeof out->prony_tau_s);
    memcpy(out->prony_k, fx.prony_k, sizeof out->prony_k);
    return CF_OK;
}

/* Reads one fit file top to bottom: open (a folder or "-"), parse, choose the fit (a single
** exported spring, the requested or better type, a tie), its params by the field table, then
** provenance and the viscoelastic terms. Kept as one function because each step narrows the same
** JSON node and every error names the file and key it stopped at. */
/* The six parameters of a spring object (key `name` of fit, at `where`) into *p, each a finite
** number; CF_E_DATA naming the key and value otherwise. */
static cf_status read_params6(json_t *fit, const char *name, const char *path, const char *where,
                              cf_spring *p, cf_error *err)
{
    json_t *params = json_object_get(fit, name);
    memset(p, 0, sizeof *p);
    for (int k = 0; k < CF_P_COUNT; k++) {
        const char *key = cf_spring_param_info(k)->key;
        json_t *v = json_object_get(params, key);
        if (!json_is_number(v) || !isfinite(json_number_value(v))) {
            char *text = v ? json_dumps(v, JSON_ENCODE_ANY) : NULL;
            cf_status st = cf_error_set(err, CF_E_DATA, "%s: %s.%s.%s = %.40s is not a number",
                                        path, where, name, key, text ? text : "(missing)");
            free(text);
            return st;
        }
        cf_spring_set(p, k, json_number_value(v));
    }
    return CF_OK;
}

static cf_status read_finite(json_t *obj, const char *key, const char *path, const char *where,
                             double *v, cf_error *err);

/* The family weights object w (at `at`, for messages) into weight: each finite, a lattice
** cf_calibration_check accepts; CF_E_DATA naming the key otherwise. */
static cf_status read_weights(json_t *w, const char *path, const char *at,
                              double weight[CF_FAMILY_COUNT], cf_error *err)
{
    static const char *const key[CF_FAMILY_COUNT] = {"edge", "face", "body"};
    for (int f = 0; f < CF_FAMILY_COUNT; f++) {
        cf_status st = read_finite(w, key[f], path, at, &weight[f], err);
        if (st != CF_OK)
            return st;
    }
    cf_error e = {0};
    if (cf_calibration_check(weight, &e) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: %s: %s", path, at, e.msg);
    return CF_OK;
}

/* A joint fit's family weights ("lattice.weights": its springs are the material only in a lattice
** of those weights) into out->weight, has_weight 1; absent (a single fit, an exported spring):
** has_weight 0. */
static cf_status read_fit_weights(json_t *fit, const char *path, const char *where,
                                  cf_fitted_spring *out, cf_error *err)
{
    json_t *w = json_object_get(json_object_get(fit, "lattice"), "weights");
    out->has_weight = 0;
    if (!w)
        return CF_OK;
    char at[96];
    snprintf(at, sizeof at, "%s.lattice.weights", where);
    cf_status st = read_weights(w, path, at, out->weight, err);
    out->has_weight = st == CF_OK;
    return st;
}

int cf_fitted_own_weights(const cf_fitted_spring *fs)
{
    double iso[CF_FAMILY_COUNT];
    if (!fs->has_weight || cf_calibration_weights(CF_CAL_ISOTROPIC, iso, NULL) != CF_OK)
        return 0;
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        if (!(fabs(fs->weight[f] - iso[f]) <= 1e-9 * iso[f]))
            return 1;
    return 0;
}

/* The double-acting element and the volume term of fit (see cf_fitfile_load_element), or their
** refusal when allow is 0. */
static cf_status read_element(json_t *fit, const char *path, const char *where, int allow,
                              cf_fitted_spring *out, cf_error *err)
{
    json_t *pe = json_object_get(fit, "params_extension");
    json_t *kv = json_object_get(json_object_get(fit, "lattice"), "volume_modulus_MPa");
    if (kv && (!json_is_number(kv) || !(json_number_value(kv) >= 0 &&
                                         json_number_value(kv) <= CF_KAPPA_MAX_MPA)))
        return cf_error_set(err, CF_E_DATA,
                            "%s: %s.lattice.volume_modulus_MPa is not a number from 0 to %g MPa "
                            "(" CF_KAPPA_MAX_WHY ")",
                            path, where, CF_KAPPA_MAX_MPA);
    const double kappa = kv ? json_number_value(kv) : 0.0;
    if (!allow && (pe || kappa > 0))
        return cf_error_set(err, CF_E_DATA,
                            "%s: %s is %s: this reader takes one spring per element and no volume "
                            "term, and will not run it as its compression spring alone (a "
                            "scene's 'spring.fit' runs the whole element)",
                            path, where,
                            pe ? "a double-acting element (key 'params_extension')"
                               : "a lattice with a volume term (key "
                                 "'lattice.volume_modulus_MPa')");
    out->volume_modulus_MPa = kappa;
    cf_status st = read_fit_weights(fit, path, where, out, err);
    if (st != CF_OK || !pe)
        return st;
    st = read_params6(fit, "params_extension", path, where, &out->extension, err);
    if (st != CF_OK)
        return st;
    cf_law le;
    cf_error lerr = {0};
    if (cf_law_init(&le, &out->extension, &lerr) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: %s.params_extension: %s", path, where, lerr.msg);
    if (out->extension.H_mm != out->params.H_mm)
        return cf_error_set(err, CF_E_DATA,
                            "%s: %s.params_extension.H_mm = %.17g differs from params.H_mm = "
                            "%.17g (a double-acting element shares its free length)",
                            path, where, out->extension.H_mm, out->params.H_mm);
    out->has_extension = 1;
    return CF_OK;
}

static cf_status load(const char *path, const char *type_name, int allow_element,
                      cf_fitted_spring *out, cf_error *err);

cf_status cf_fitfile_load(const char *path, const char *type_name, cf_fitted_spring *out,
                          cf_error *err)
{
    return load(path, type_name, 0, out, err);
}

cf_status cf_fitfile_load_element(const char *path, const char *type_name,
                                  cf_fitted_spring *out, cf_error *err)
{
    return load(path, type_name, 1, out, err);
}

/* The fit file at path (or standard input, "-") parsed as JSON into *root; *shown is the name
** for messages. */
static cf_status read_root(const char *path, const char **shown, json_t **root, cf_error *err)
{
    const int from_stdin = strcmp(path, "-") == 0; /* "-": standard input */
    *shown = path;
    FILE *f = from_stdin ? stdin : cf_input_open(path, "fit file", err);
    if (!f)
        return CF_E_NOINPUT;
    json_error_t jerr;
    errno = 0;
    *root = json_loadf(f, JSON_REJECT_DUPLICATES, &jerr);
    int unreadable = ferror(f), e = errno;
    if (from_stdin)
        *shown = "(standard input)";
    else
        fclose(f);
    if (!*root && unreadable) /* a read error, not bad JSON */
        return cf_error_set(err, CF_E_NOINPUT, "%s: cannot read fit file: %s", *shown,
                            strerror(e ? e : EIO));
    char why[JSON_ERROR_TEXT_LENGTH];
    if (!*root)
        return cf_error_set(err, CF_E_DATA, "%s:%d:%d: not a valid fit file: %s", *shown,
                            jerr.line, jerr.column, cf_json_reason(&jerr, why, sizeof why));
    return CF_OK;
}

/* The fit of type want (NULL: the better type, or the first feasible one where the types tie)
** in root: root itself for an exported spring, else an entry of its 'fits'; where names it for
** messages. */
static cf_status pick_fit(json_t *root, const char *path, const char *want, json_t **fit,
                          char where[64], cf_error *err)
{
    *fit = NULL;
    const char *schema = json_string_value(json_object_get(root, "schema"));
    if (schema && strcmp(schema, CF_SPRINGFILE_SCHEMA) == 0) {
        /* a single exported spring: the root itself holds type and params */
        const char *t = json_string_value(json_object_get(root, "type"));
        if (want && (!t || strcmp(t, want) != 0))
            return cf_error_set(err, CF_E_DATA, "%s: the spring is of type '%s', not '%s'", path,
                                t ? t : "(missing)", want);
        *fit = root;
        snprintf(where, 64, "spring");
        return CF_OK;
    }
    json_t *fits = json_object_get(root, "fits");
    if (!json_is_array(fits) || json_array_size(fits) == 0)
        return cf_error_set(err, CF_E_DATA, "%s: key 'fits' is missing or not a non-empty array",
                            path);
    int tie = 0; /* the types tie: the first feasible fit stands for both */
    if (!want && json_array_size(fits) > 1) {
        want = json_string_value(json_object_get(root, "better_type"));
        tie = !want && json_is_true(json_object_get(json_object_get(root, "comparison"), "tie"));
        if (!want && !tie)
            return cf_error_set(err, CF_E_DATA,
                                "%s: several fits and no 'better_type'; name the type", path);
    }
    size_t i = 0;
    json_t *item;
    json_array_foreach(fits, i, item)
    {
        const char *t = json_string_value(json_object_get(item, "type"));
        if (tie ? json_is_true(json_object_get(item, "feasible"))
                : (!want || (t && strcmp(t, want) == 0))) {
            *fit = item;
            break;
        }
    }
    if (!*fit)
        return cf_error_set(err, CF_E_DATA, "%s: no fit of type '%s' in 'fits'", path, want);
    snprintf(where, 64, "fits[%zu]", i);
    return CF_OK;
}

/* The fit's type and design parameters, checked to make a spring of that type. */
static cf_status read_spring(json_t *fit, const char *path, const char *where,
                             cf_fitted_spring *out, cf_error *err)
{
    const char *t = json_string_value(json_object_get(fit, "type"));
    if (cf_spring_type_parse(t, &out->type, NULL) != CF_OK)
        return cf_error_set(err, CF_E_DATA,
                            "%s: %s.type = '%s' is not telescoping or non-telescoping", path,
                            where, t ? t : "(missing)");
    json_t *params = json_object_get(fit, "params");
    for (int k = 0; k < CF_P_ALL; k++) {
        const char *key = cf_spring_param_info(k)->key;
        json_t *v = json_object_get(params, key);
        if (!v && k >= CF_P_COUNT) /* the tail's keys: absent without a tail */
            continue;
        if (!json_is_number(v) || !isfinite(json_number_value(v))) {
            char *text = v ? json_dumps(v, JSON_ENCODE_ANY) : NULL;
            cf_status st = cf_error_set(err, CF_E_DATA, "%s: %s.params.%s = %.40s is not a number",
                                        path, where, key, text ? text : "(missing)");
            free(text);
            return st;
        }
        cf_spring_set(&out->params, k, json_number_value(v));
    }
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init(&law, &out->params, &lerr) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: %s.params: %s", path, where, lerr.msg);
    cf_law_free(&law);
    if (law.type != out->type)
        return cf_error_set(err, CF_E_DATA,
                            "%s: %s says type '%s' but its parameters make a %s spring", path,
                            where, t, cf_spring_type_name(law.type));
    return CF_OK;
}

/* A fit of a law kind that is not one of the library's (its "law" names another): the kind from the
** registry (lawmech.h) and its quantities from "law_params", checked to make its law. */
static cf_status read_kind(json_t *fit, const char *path, const char *where,
                           cf_fitted_spring *out, cf_error *err)
{
    const char *name = json_string_value(json_object_get(fit, "law"));
    static const char *const own[] = {"conical", "conical-tail", "double-acting"};
    for (size_t i = 0; name && i < sizeof own / sizeof own[0]; i++)
        if (strcmp(name, own[i]) == 0)
            return CF_OK;
    if (!name) /* a file written before kinds were recorded: the conical law */
        return CF_OK;
    if (!(out->mech = cf_law_mech_find(name)))
        return cf_error_set(err, CF_E_DATA,
                            "%s: %s.law = '%s' is a law kind this program does not know (a kind "
                            "a program defines is read once it registers it)",
                            path, where, name);
    json_t *q = json_object_get(fit, "law_params");
    for (int k = 0; k < out->mech->nq; k++) {
        json_t *v = json_object_get(q, out->mech->key[k]);
        if (!json_is_number(v) || !isfinite(json_number_value(v)))
            return cf_error_set(err, CF_E_DATA, "%s: %s.law_params.%s of law kind '%s' is %s",
                                path, where, out->mech->key[k], name,
                                v ? "not a finite number" : "missing");
        out->q[k] = json_number_value(v);
    }
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init_kind(&law, out->mech, out->q, out->params.H_mm, &lerr) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: %s.law_params: %s", path, where, lerr.msg);
    cf_law_free(&law);
    return CF_OK;
}

cf_status cf_fitted_law(const cf_fitted_spring *fs, cf_law *law, cf_error *err)
{
    if (fs->mech)
        return cf_law_init_kind(law, fs->mech, fs->q, fs->params.H_mm, err);
    return cf_law_init(law, &fs->params, err);
}

/* Where the fit came from: its RMSE, data file and unit, the version, whether it is a lattice's. */
static void read_provenance(json_t *root, json_t *fit, cf_fitted_spring *out)
{
    json_t *prov = json_object_get(root, "provenance");
    json_t *r = json_object_get(fit == root ? prov : fit, "rmse");
    if (json_is_number(r) && isfinite(json_number_value(r)))
        out->rmse = json_number_value(r);
    if (fit == root) {
        copy_string(prov, "data_file", out->data_file, sizeof out->data_file);
        copy_string(prov, "rmse_unit", out->y_unit, sizeof out->y_unit);
    } else {
        json_t *data = json_object_get(root, "data");
        copy_string(data, "file", out->data_file, sizeof out->data_file);
        copy_string(data, "y_unit", out->y_unit, sizeof out->y_unit);
    }
    copy_string(root, "conifit_version", out->version, sizeof out->version);
    /* a joint fit is the lattice's; a fit file's fit says so in its target */
    const char *model = json_string_value(json_object_get(json_object_get(fit, "target"), "model"));
    out->target_lattice = json_is_true(json_object_get(root, "joint")) ||
                          (model && strcmp(model, "lattice") == 0);
}

/* load's steps with the document kept: *root (the caller releases it, also on failure), *fit
** the fit read, *shown the file's name for messages and where the fit's key path. */
static cf_status load_fit(const char *path, const char *type_name, int allow_element,
                          cf_fitted_spring *out, json_t **root, json_t **fit, const char **shown,
                          char where[64], cf_error *err)
{
    memset(out, 0, sizeof *out);
    out->rmse = NAN;
    *root = NULL;
    *fit = NULL;
    const char *want = (type_name && *type_name) ? type_name : NULL;
    cf_status st = read_root(path, shown, root, err);
    if (st == CF_OK && (st = pick_fit(*root, *shown, want, fit, where, err)) == CF_OK &&
        (st = read_spring(*fit, *shown, where, out, err)) == CF_OK &&
        (st = read_kind(*fit, *shown, where, out, err)) == CF_OK) {
        read_provenance(*root, *fit, out);
        if ((st = read_visco(*fit, *shown, where, out, err)) == CF_OK)
            st = read_element(*fit, *shown, where, allow_element, out, err);
    }
    return st;
}

static cf_status load(const char *path, const char *type_name, int allow_element,
                      cf_fitted_spring *out, cf_error *err)
{
    json_t *root, *fit;
    char where[64];
    cf_status st = load_fit(path, type_name, allow_element, out, &root, &fit, &path, where, err);
    json_decref(root);
    return st;
}

/* ---- a fit as a model to evaluate (cf_fitfile_load_model) ------------------------------------ */

/* The finite number obj[key] (at `where`, for messages) into *v; CF_E_DATA naming it otherwise. */
static cf_status read_finite(json_t *obj, const char *key, const char *path, const char *where,
                             double *v, cf_error *err)
{
    json_t *j = json_object_get(obj, key);
    if (json_is_number(j) && isfinite(json_number_value(j))) {
        *v = json_number_value(j);
        return CF_OK;
    }
    char *text = j ? json_dumps(j, JSON_ENCODE_ANY) : NULL;
    cf_status st = cf_error_set(err, CF_E_DATA, "%s: %s.%s = %.40s is not a number", path, where,
                                key, text ? text : "(missing)");
    free(text);
    return st;
}

/* The lattice a fit was evaluated in: its family weights (a joint fit's "lattice", a single fit's
** "validation.lattice"; required when the fit's target is the lattice) and law method. */
static cf_status read_lattice(json_t *fit, const char *path, const char *where,
                              cf_fitted_model *out, cf_error *err)
{
    json_t *val = json_object_get(fit, "validation");
    json_t *lat = out->joint ? json_object_get(fit, "lattice") : json_object_get(val, "lattice");
    char at[96];
    snprintf(at, sizeof at, "%s.%s.weights", where, out->joint ? "lattice" : "validation.lattice");
    json_t *w = json_object_get(lat, "weights");
    out->method = CF_LAW_CLOSED;
    const char *m = out->joint ? NULL : json_string_value(json_object_get(val, "law_method"));
    if (m && cf_law_method_parse(m, &out->method, NULL) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: %s.validation.law_method = '%.40s' is not exact, "
                                            "closed, closed+newton or table", path, where, m);
    if (!w && !out->spring.target_lattice)
        return CF_OK;
    cf_status st = read_weights(w, path, at, out->weight, err);
    out->has_weight = st == CF_OK;
    return st;
}

/* One fitted table's record (the keys of a joint fit's "tables" entry, or a single fit's "data"
** with the fit's rmse) into *t. */
static cf_status read_fitted_table(json_t *e, json_t *fit, const char *path, const char *at,
                                   int joint, cf_fitfile_table *t, cf_error *err)
{
    copy_string(e, "file", t->file, sizeof t->file);
    copy_string(joint ? e : json_object_get(e, "measures"), "mode", t->mode, sizeof t->mode);
    copy_string(e, joint ? "unit" : "y_unit", t->unit, sizeof t->unit);
    json_t *pts = json_object_get(e, "points");
    t->points = json_is_integer(pts) && json_integer_value(pts) > 0
                    ? (size_t)json_integer_value(pts) : 0;
    t->scale = NAN;
    cf_status st = read_finite(joint ? e : fit, "rmse", path, at, &t->rmse, err);
    if (st == CF_OK && joint && json_object_get(e, "scale")) /* absent: not recorded */
        st = read_finite(e, "scale", path, at, &t->scale, err);
    return st;
}

/* The tables the fit was fitted to and a joint fit's objective. */
static cf_status read_fitted(json_t *root, json_t *fit, const char *path, const char *where,
                             cf_fitted_model *out, cf_error *err)
{
    out->objective = NAN;
    if (!out->joint) {
        out->ntables = 1;
        return read_fitted_table(json_object_get(root, "data"), fit, path, where, 0, &out->tab[0],
                                 err);
    }
    cf_status st = read_finite(fit, "objective", path, where, &out->objective, err);
    json_t *tabs = json_object_get(fit, "tables");
    if (st == CF_OK && (!json_is_array(tabs) || json_array_size(tabs) == 0 ||
                        json_array_size(tabs) > CF_FITFILE_TABLES))
        return cf_error_set(err, CF_E_DATA, "%s: %s.tables is not a list of 1 to %d tables", path,
                            where, CF_FITFILE_TABLES);
    for (size_t k = 0; st == CF_OK && k < json_array_size(tabs); k++) {
        char at[96];
        snprintf(at, sizeof at, "%s.tables[%zu]", where, k);
        st = read_fitted_table(json_array_get(tabs, k), fit, path, at, 1, &out->tab[k], err);
        out->ntables = k + 1;
    }
    return st;
}

cf_status cf_fitfile_load_model(const char *path, const char *type_name, cf_fitted_model *out,
                                cf_error *err)
{
    memset(out, 0, sizeof *out);
    json_t *root, *fit;
    char where[64];
    const char *shown = path;
    cf_status st = load_fit(path, type_name, 1, &out->spring, &root, &fit, &shown, where, err);
    if (st == CF_OK && fit == root)
        st = cf_error_set(err, CF_E_DATA, "%s: a single exported spring does not record the "
                                          "lattice it was fitted in; give its fit file", shown);
    else if (st == CF_OK && out->spring.viscoelastic)
        st = cf_error_set(err, CF_E_DATA, "%s: %s is a time-series fit (key 'prony'): its "
                                          "stress follows the strain history, not a curve",
                          shown, where);
    if (st == CF_OK) {
        out->joint = json_is_true(json_object_get(root, "joint"));
        const char *kind = json_string_value(json_object_get(json_object_get(root, "data"),
                                                             "kind"));
        out->force_displacement = kind && strcmp(kind, "force-displacement") == 0;
        copy_string(json_object_get(fit, "target"), "mode", out->target_mode,
                    sizeof out->target_mode);
        if ((st = read_lattice(fit, shown, where, out, err)) == CF_OK)
            st = read_fitted(root, fit, shown, where, out, err);
    }
    json_decref(root);
    return st;
}

cf_status cf_fitfile_load_spec(const char *spec, cf_fitted_spring *out, cf_error *err)
{
    char path[4096];
    const char *type = NULL;
    snprintf(path, sizeof path, "%s", spec);
    char *colon = strrchr(path, ':');
    if (colon && (strcmp(colon + 1, "telescoping") == 0 ||
                  strcmp(colon + 1, "non-telescoping") == 0)) {
        *colon = '\0';
        type = colon + 1;
    }
    return cf_fitfile_load(path, type, out, err);
}

/* ---- writing (fitfile_json.h) ----------------------------------------------------------------- */

json_t *cf_json_number(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

const char *cf_json_reason(const json_error_t *e, char *out, size_t cap)
{
    snprintf(out, cap, "%s", e->text);
    char *near = strstr(out, " near ");
    if (near)
        *near = '\0';
    return out;
}

json_t *cf_fitfile_spring_json(const cf_law *law)
{
    const cf_spring *p = &law->p;
    json_t *params = json_object();
    const int count = law->tail ? CF_P_ALL : CF_P_COUNT; /* the tail's keys only with a tail */
    for (int k = 0; params && k < count; k++)
        json_object_set_new(params, cf_spring_param_info(k)->key,
                            cf_json_number(cf_spring_get(p, k)));
    json_t *derived = json_pack(
        "{s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o}", "rho", cf_json_number(law->rho),
        "travel_mm", cf_json_number(law->travel_mm), "solid_strain",
        cf_json_number(law->travel_mm / p->H_mm), "F_T_N", cf_json_number(law->F_T_N), "F_C_N",
        cf_json_number(law->F_C_N), "k0_N_per_mm", cf_json_number(law->k0_N_per_mm), "u_T_mm",
        cf_json_number(law->u_T_mm), "index_c", cf_json_number(law->index_c), "L_min_mm",
        cf_json_number(law->L_min_mm), "L_max_mm", cf_json_number(law->L_max_mm));
    if (derived && law->tail) {
        const struct { const char *key; double v; } tail[] = {
            {"u_C_mm", law->u_C_mm}, {"F_solid_N", law->F_solid_N},
            {"k_tail_N_per_mm", law->k_tail_N_per_mm}, {"tau", law->tau}};
        for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++)
            json_object_set_new(derived, tail[i].key, cf_json_number(tail[i].v));
    }
    if (!params || !derived) {
        json_decref(params);
        json_decref(derived);
        return NULL;
    }
    json_t *o = json_pack("{s:s, s:o, s:o}", "type", cf_spring_type_name(law->type), "params",
                          params, "derived", derived);
    if (o && law->mech) { /* a law kind's: its name and quantities, read back by read_kind */
        json_t *q = json_object();
        for (int k = 0; q && k < law->mech->nq; k++)
            json_object_set_new(q, law->mech->key[k], cf_json_number(law->q[k]));
        json_object_set_new(o, "law", json_string(law->mech->name));
        json_object_set_new(o, "law_params", q);
    }
    return o;
}

/* Depth-first search for a null in v; path (capacity cap) receives its key path ("fits[0].rmse").
** 1 when one is found. */
static int find_null(const json_t *v, char *path, size_t cap, size_t used)
{
    if (json_is_null(v))
        return 1;
    if (json_is_object(v)) {
        const char *key;
        json_t *item;
        json_object_foreach((json_t *)v, key, item) {
            int n = snprintf(path + used, cap - used, "%s%s", used ? "." : "", key);
            size_t u = n > 0 && (size_t)n < cap - used ? used + (size_t)n : cap - 1;
            if (find_null(item, path, cap, u))
                return 1;
        }
    } else if (json_is_array(v)) {
        for (size_t i = 0; i < json_array_size(v); i++) {
            int n = snprintf(path + used, cap - used, "[%zu]", i);
            size_t u = n > 0 && (size_t)n < cap - used ? used + (size_t)n : cap - 1;
            if (find_null(json_array_get(v, i), path, cap, u))
                return 1;
        }
    }
    path[used] = '\0';
    return 0;
}

int cf_json_find_null(const json_t *root, char *path, size_t cap)
{
    if (cap == 0)
        return json_is_null(root);
    path[0] = '\0';
    return find_null(root, path, cap, 0);
}

char *cf_fitfile_dumps(const json_t *root)
{
    char where[256];
    if (cf_json_find_null(root, where, sizeof where))
        return NULL;
    char *s = json_dumps(root, JSON_INDENT(2) | JSON_REAL_PRECISION(17) | JSON_PRESERVE_ORDER);
    if (!s)
        return NULL;
    size_t n = strlen(s);
    char *t = realloc(s, n + 2);
    if (!t) {
        free(s);
        return NULL;
    }
    t[n] = '\n';
    t[n + 1] = '\0';
    return t;
}

cf_status cf_fitfile_prepare(const json_t *root, const char *path, const char *const *inputs,
                             cf_output *out, cf_error *err)
{
    memset(out, 0, sizeof *out);
    char where[256];
    if (cf_json_find_null(root, where, sizeof where))
        return cf_error_set(err, CF_E_INTERNAL,
                            "%s: the value of '%s' is not a finite number; nothing written", path,
                            where);
    char *s = cf_fitfile_dumps(root);
    if (!s)
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory writing the JSON", path);
    cf_status st = cf_atomic_open(out, path, inputs, err);
    if (st == CF_OK) {
        fputs(s, out->fp);
        st = cf_atomic_finish(out, err);
    }
    free(s);
    return st;
}

/* One family of a "fibre_lattice" entry at where: rho, solid_strain, stress_scale_kPa. */
static cf_status fibre_family(json_t *e, const char *path, const char *where, cf_ident *q,
                              cf_error *err)
{
    static const char *const keys[] = {"rho", "solid_strain", "stress_scale_kPa"};
    double v[3];
    for (int k = 0; k < 3; k++) {
        json_t *x = json_is_object(e) ? json_object_get(e, keys[k]) : NULL;
        v[k] = json_is_number(x) ? json_number_value(x) : NAN;
    }
    if (!(v[0] > 0 && v[0] <= 1) || !(v[1] > 0 && v[1] < 1) || !(v[2] > 0) || !isfinite(v[2]))
        return cf_error_set(err, CF_E_DATA,
                            "%s: key '%s': rho %g (0 to 1), solid_strain %g (0 to 1), "
                            "stress_scale_kPa %g (> 0): not a fitted spring",
                            path, where, v[0], v[1], v[2]);
    q->rho = v[0], q->solid = v[1], q->scale = v[2] * 1e-3;
    return CF_OK;
}

/* The entry e of "fibre_lattice" (at where) into out. */
static cf_status fibre_entry(json_t *e, const char *path, const char *where, cf_fitted_fibre *out,
                             cf_error *err)
{
    char w[96];
    snprintf(w, sizeof w, "%s.matrix", where);
    cf_status st = fibre_family(json_object_get(e, "matrix"), path, w, &out->matrix, err);
    if (st != CF_OK)
        return st;
    json_t *gs = json_object_get(e, "fibre_groups"), *kv = json_object_get(e, "volume_modulus_kPa");
    const size_t n = json_array_size(gs);
    if (!json_is_array(gs) || n == 0 || n > CF_FIBRE_MAX)
        return cf_error_set(err, CF_E_DATA, "%s: key '%s.fibre_groups' must hold 1 to %d groups",
                            path, where, CF_FIBRE_MAX);
    json_t *fw = json_object_get(e, "family_weights"); /* files before it: equal weights */
    for (int k = 0; k < CF_FAMILY_COUNT; k++) {
        json_t *v = json_array_get(fw, (size_t)k);
        out->family[k] = !fw ? 1 : json_is_number(v) ? json_number_value(v) : NAN;
    }
    if (fw && (!json_is_array(fw) || json_array_size(fw) != CF_FAMILY_COUNT ||
               !(out->family[0] > 0 && out->family[0] <= 1e6 && out->family[1] >= 0 &&
                 out->family[1] <= 1e6 && out->family[2] >= 0 && out->family[2] <= 1e6)))
        return cf_error_set(err, CF_E_DATA, "%s: key '%s.family_weights' must be [edge, face, "
                            "body]: edge > 0, face and body >= 0, each at most 1e6", path, where);
    out->kappa_MPa = json_is_number(kv) ? json_number_value(kv) * 1e-3 : NAN;
    if (!(out->kappa_MPa >= 0) || !isfinite(out->kappa_MPa))
        return cf_error_set(err, CF_E_DATA, "%s: key '%s.volume_modulus_kPa' must be a finite "
                            "number >= 0", path, where);
    for (size_t k = 0; k < n; k++) {
        json_t *g = json_array_get(gs, k);
        const char *a = json_string_value(json_object_get(g, "axis"));
        snprintf(w, sizeof w, "%s.fibre_groups[%zu]", where, k);
        if (!a || strlen(a) != 1 || !strchr("fsn", a[0]) || memchr(out->axis, a[0], k))
            return cf_error_set(err, CF_E_DATA, "%s: key '%s.axis' must be one of f, s, n, each "
                                "once", path, w);
        out->axis[k] = a[0];
        if ((st = fibre_family(g, path, w, &out->group[k], err)) != CF_OK)
            return st;
        json_t *rs = json_object_get(g, "recruitment_strain"); /* files before it: taut */
        out->slack[k] = rs ? (json_is_number(rs) ? json_number_value(rs) : NAN) : 0;
        if (!(out->slack[k] >= 0 && out->slack[k] < 1))
            return cf_error_set(err, CF_E_DATA, "%s: key '%s.recruitment_strain' = %g: must be "
                                "a number in [0, 1)", path, w, out->slack[k]);
    }
    out->ngroups = (int)n;
    return CF_OK;
}

cf_status cf_fitfile_load_fibre(const char *path, const char *cross, cf_fitted_fibre *out,
                                cf_error *err)
{
    memset(out, 0, sizeof *out);
    const char *shown;
    json_t *root;
    cf_status st = read_root(path, &shown, &root, err);
    if (st != CF_OK)
        return st;
    json_t *fl = json_object_get(root, "fibre_lattice");
    size_t k = 0;
    for (; k < json_array_size(fl); k++) {
        const char *c = json_string_value(json_object_get(json_array_get(fl, k), "cross_axis"));
        if (c && strcmp(c, cross) == 0)
            break;
    }
    char where[48];
    snprintf(where, sizeof where, "fibre_lattice[%zu]", k);
    if (k < json_array_size(fl))
        st = fibre_entry(json_array_get(fl, k), shown, where, out, err);
    else
        st = cf_error_set(err, CF_E_DATA, "%s: no key 'fibre_lattice' with an entry of "
                          "cross_axis '%s' (a joint fit with --fibres writes one per cross-fibre "
                          "axis)", shown, cross);
    json_decref(root);
    return st;
}
