/*
** Reading fitted springs back from a conifit fit file (see fitfile.h for the schema).
*/
#include "conifit/fitfile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

cf_status cf_spring_type_parse(const char *name, cf_spring_type *type, cf_error *err)
{
    if (name && strcmp(name, "telescoping") == 0) {
        *type = CF_TELESCOPING;
        return CF_OK;
    }
    if (name && strcmp(name, "non-telescoping") == 0) {
        *type = CF_NON_TELESCOPING;
        return CF_OK;
    }
    return cf_error_set(err, CF_E_USAGE,
                        "unknown spring type '%s' (expected telescoping or non-telescoping)",
                        name ? name : "(null)");
}

static void copy_string(json_t *obj, const char *key, char *dst, size_t cap)
{
    const char *s = json_string_value(json_object_get(obj, key));
    snprintf(dst, cap, "%s", s ? s : "");
}

cf_status cf_fitfile_load(const char *path, const char *type_name, cf_fitted_spring *out,
                          cf_error *err)
{
    static const char *keys[6] = {"D1_mm", "D2_mm", "n", "d_mm", "G_MPa", "H_mm"};
    memset(out, 0, sizeof *out);
    out->rmse = NAN;
    FILE *f = fopen(path, "rb");
    if (!f)
        return cf_error_set(err, CF_E_NOINPUT, "%s: cannot open fit file: %s", path,
                            strerror(errno));
    json_error_t jerr;
    json_t *root = json_loadf(f, JSON_REJECT_DUPLICATES, &jerr);
    fclose(f);
    if (!root)
        return cf_error_set(err, CF_E_DATA, "%s:%d:%d: not a valid fit file: %s", path, jerr.line,
                            jerr.column, jerr.text);
    cf_status st = CF_OK;
    json_t *fit = NULL;
    size_t i = 0;
    char where[64];
    const char *want = (type_name && *type_name) ? type_name : NULL;
    const char *schema = json_string_value(json_object_get(root, "schema"));
    if (schema && strcmp(schema, CF_SPRINGFILE_SCHEMA) == 0) {
        /* a single exported spring: the root itself holds type and params */
        const char *t = json_string_value(json_object_get(root, "type"));
        if (want && (!t || strcmp(t, want) != 0)) {
            st = cf_error_set(err, CF_E_DATA, "%s: the spring is of type '%s', not '%s'", path,
                              t ? t : "(missing)", want);
            goto done;
        }
        fit = root;
        snprintf(where, sizeof where, "spring");
    } else {
        json_t *fits = json_object_get(root, "fits");
        if (!json_is_array(fits) || json_array_size(fits) == 0) {
            st = cf_error_set(err, CF_E_DATA,
                              "%s: key 'fits' is missing or not a non-empty array", path);
            goto done;
        }
        if (!want && json_array_size(fits) > 1) {
            want = json_string_value(json_object_get(root, "better_type"));
            if (!want) {
                st = cf_error_set(err, CF_E_DATA,
                                  "%s: several fits and no 'better_type'; name the type", path);
                goto done;
            }
        }
        json_t *item;
        json_array_foreach(fits, i, item)
        {
            const char *t = json_string_value(json_object_get(item, "type"));
            if (!want || (t && strcmp(t, want) == 0)) {
                fit = item;
                break;
            }
        }
        if (!fit) {
            st = cf_error_set(err, CF_E_DATA, "%s: no fit of type '%s' in 'fits'", path, want);
            goto done;
        }
        snprintf(where, sizeof where, "fits[%zu]", i);
    }
    const char *t = json_string_value(json_object_get(fit, "type"));
    if (cf_spring_type_parse(t, &out->type, NULL) != CF_OK) {
        st = cf_error_set(err, CF_E_DATA,
                          "%s: %s.type = '%s' is not telescoping or non-telescoping", path,
                          where, t ? t : "(missing)");
        goto done;
    }
    json_t *params = json_object_get(fit, "params");
    double *slot[6] = {&out->params.D1_mm, &out->params.D2_mm, &out->params.n,
                       &out->params.d_mm,  &out->params.G_MPa, &out->params.H_mm};
    for (int k = 0; k < 6; k++) {
        json_t *v = json_object_get(params, keys[k]);
        if (!json_is_number(v) || !isfinite(json_number_value(v))) {
            char *text = v ? json_dumps(v, JSON_ENCODE_ANY) : NULL;
            st = cf_error_set(err, CF_E_DATA, "%s: %s.params.%s = %.40s is not a number", path,
                              where, keys[k], text ? text : "(missing)");
            free(text);
            goto done;
        }
        *slot[k] = json_number_value(v);
    }
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init(&law, &out->params, &lerr) != CF_OK) {
        st = cf_error_set(err, CF_E_DATA, "%s: %s.params: %s", path, where, lerr.msg);
        goto done;
    }
    if (law.type != out->type) {
        st = cf_error_set(err, CF_E_DATA,
                          "%s: %s says type '%s' but its parameters make a %s spring", path,
                          where, t, cf_spring_type_name(law.type));
        goto done;
    }
    cf_law_free(&law);
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
done:
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
