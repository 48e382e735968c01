/*
** Scene files (scene.h): the checked reading of one key, whose messages name the file, the key and
** the value.
*/
#include <math.h>
#include <string.h>

#include "io/scene_internal.h"
#include "model/calibration.h"

/* Refuses keys of obj that are not in the NULL-terminated list. */
cf_status cf_scene_only_keys(ctx *c, json_t *obj, const char *where, const char *const *allowed)
{
    const char *key;
    json_t *v;
    json_object_foreach(obj, key, v)
    {
        int ok = 0;
        for (size_t i = 0; allowed[i]; i++)
            ok |= strcmp(key, allowed[i]) == 0;
        if (!ok)
            return cf_error_set(c->err, CF_E_DATA, "%s: unknown key '%s%s%s'", c->name, where,
                                *where ? "." : "", key);
    }
    return CF_OK;
}

/* A number at obj[key]: required or default; checked finite and within [lo, hi] (or (lo, hi]
** with open_lo). */
cf_status cf_scene_number(ctx *c, json_t *obj, const char *where, const char *key, int required,
                          double dflt, double lo, int open_lo, double hi, double *out)
{
    json_t *v = obj ? json_object_get(obj, key) : NULL;
    const char *dot = *where ? "." : "";
    if (!v) {
        if (required)
            return cf_error_set(c->err, CF_E_DATA, "%s: missing key '%s%s%s'", c->name, where,
                                dot, key);
        *out = dflt;
        return CF_OK;
    }
    if (!json_is_number(v))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s%s%s' must be a number", c->name,
                            where, dot, key);
    double x = json_number_value(v);
    if (!isfinite(x) || (open_lo ? !(x > lo) : !(x >= lo)) || !(x <= hi))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s%s%s' = %g: must be %s %g and <= %g",
                            c->name, where, dot, key, x, open_lo ? ">" : ">=", lo, hi);
    *out = x;
    return CF_OK;
}

cf_status cf_scene_kappa(ctx *c, json_t *obj, const char *where, const cf_spring *spring,
                         double dflt, double *out)
{
    double x;
    cf_status st = cf_scene_number(c, obj, where, "volume_modulus_MPa", 0, dflt, 0, 0, INFINITY, &x);
    if (st != CF_OK)
        return st;
    if (!(x <= CF_KAPPA_MAX_MPA))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key '%s.volume_modulus_MPa' = %g: must be >= 0 and at most %g MPa "
                            "(" CF_KAPPA_MAX_WHY ")",
                            c->name, where, x, CF_KAPPA_MAX_MPA);
    cf_law law;
    if (obj && json_object_get(obj, "volume_modulus_MPa") && spring &&
        cf_law_init(&law, spring, NULL) == CF_OK) {
        const double k = law.k0_N_per_mm / law.p.H_mm;
        cf_law_free(&law);
        if (!(x <= CF_KAPPA_MAX_RATIO * k))
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key '%s.volume_modulus_MPa' = %g: must be at most %g times "
                                "the spring's small-strain stiffness k0/H = %g MPa, %g MPa "
                                "(" CF_KAPPA_RATIO_WHY ")",
                                c->name, where, x, CF_KAPPA_MAX_RATIO, k, CF_KAPPA_MAX_RATIO * k);
    }
    *out = x;
    return CF_OK;
}

cf_status cf_scene_boolean(ctx *c, json_t *obj, const char *where, const char *key, int *out)
{
    json_t *v = obj ? json_object_get(obj, key) : NULL;
    *out = 0;
    if (!v)
        return CF_OK;
    if (!json_is_boolean(v))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.%s' must be true or false", c->name,
                            where, key);
    *out = json_is_true(v);
    return CF_OK;
}

cf_status cf_scene_object(ctx *c, json_t *root, const char *key, int required, json_t **out)
{
    json_t *v = json_object_get(root, key);
    *out = NULL;
    if (!v) {
        if (required)
            return cf_error_set(c->err, CF_E_DATA, "%s: missing key '%s'", c->name, key);
        return CF_OK;
    }
    if (!json_is_object(v))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, key);
    *out = v;
    return CF_OK;
}

/* A JSON array of three finite numbers at obj[key] into v. */
cf_status cf_scene_vec3(ctx *c, json_t *obj, const char *where, const char *key, double v[3])
{
    json_t *a = json_object_get(obj, key);
    if (!a)
        return cf_error_set(c->err, CF_E_DATA, "%s: missing key '%s.%s'", c->name, where, key);
    if (!json_is_array(a) || json_array_size(a) != 3)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.%s' must be an array of 3 numbers",
                            c->name, where, key);
    for (size_t i = 0; i < 3; i++) {
        json_t *x = json_array_get(a, i);
        if (!json_is_number(x) || !isfinite(json_number_value(x)))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.%s' must be an array of 3 finite "
                                "numbers", c->name, where, key);
        v[i] = json_number_value(x);
    }
    return CF_OK;
}

/* The family weights: exactly one of 'weights' {edge, face, body}, 'calibration' (isotropic,
** axial), or the shorthands 'diagonals' / 'diagonal_weight' (edges 1, the named diagonals the
** given weight: the uncalibrated lattice); none of them: isotropic, or
** the fitted weights of the joint fit the scene's spring names. */
cf_status cf_scene_weights(ctx *c, json_t *lt, cf_lattice_config *L)
{
    static const char *const wkeys[] = {"edge", "face", "body", NULL};
    json_t *w = lt ? json_object_get(lt, "weights") : NULL;
    json_t *cal = lt ? json_object_get(lt, "calibration") : NULL;
    json_t *dg = lt ? json_object_get(lt, "diagonals") : NULL;
    json_t *dw = lt ? json_object_get(lt, "diagonal_weight") : NULL;
    int given = (w != NULL) + (cal != NULL) + (dg != NULL || dw != NULL);
    if (given > 1)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'lattice.%s': give one of 'lattice.weights', "
                            "'lattice.calibration' or the shorthands 'lattice.diagonals' / "
                            "'lattice.diagonal_weight'",
                            c->name, w && cal ? "calibration" : dg ? "diagonals" : "diagonal_weight");
    cf_status st;
    cf_error e = {0};
    if (w) {
        if (!json_is_object(w))
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'lattice.weights' must be an object {\"edge\": ..., "
                                "\"face\": ..., \"body\": ...}",
                                c->name);
        if ((st = cf_scene_only_keys(c, w, "lattice.weights", wkeys)))
            return st;
        for (int f = 0; f < CF_FAMILY_COUNT; f++)
            if ((st = cf_scene_number(c, w, "lattice.weights", wkeys[f], 1, 0, 0, 0, 1e6, &L->weight[f])))
                return st;
        if (cf_calibration_check(L->weight, &e) != CF_OK)
            return cf_error_set(c->err, CF_E_DATA, "%s: key %s", c->name, e.msg);
        L->calibration = CF_CAL_CUSTOM;
        return CF_OK;
    }
    if (cal) {
        const char *name = json_string_value(cal);
        if (cf_calibration_parse(name, &L->calibration, &e) != CF_OK)
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'lattice.calibration' = '%s': "
                                "expected isotropic, axial or fitted", c->name,
                                name ? name : "(not a string)");
        if (L->calibration == CF_CAL_FITTED)
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'lattice.calibration' = 'fitted': a scene takes fitted "
                                "weights from the joint fit its 'spring.fit' names (give no "
                                "lattice weights), or as 'lattice.weights'",
                                c->name);
        return cf_calibration_weights(L->calibration, L->weight, c->err);
    }
    /* none given: the default of cf_lattice_default() (isotropic), or a joint fit's fitted
    ** weights (its springs are the material in their lattice) */
    if (!dg && !dw && c->from_fit && cf_fitted_own_weights(&c->fit))
        memcpy(L->weight, c->fit.weight, sizeof L->weight), L->calibration = CF_CAL_FITTED;
    if (!dg && !dw)
        return CF_OK;
    double wd = 1;
    if ((st = cf_scene_number(c, lt, "lattice", "diagonal_weight", 0, 1, 0, 0, 1e6, &wd)))
        return st;
    unsigned fam = 3; /* bit 0 face, bit 1 body */
    if (dg) {
        const char *s = json_string_value(dg);
        if (s && strcmp(s, "none") == 0)
            fam = 0;
        else if (s && strcmp(s, "face") == 0)
            fam = 1;
        else if (s && strcmp(s, "body") == 0)
            fam = 2;
        else if (s && strcmp(s, "face+body") == 0)
            fam = 3;
        else
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'lattice.diagonals' = '%s': expected none, face, body or "
                                "face+body",
                                c->name, s ? s : "(not a string)");
    }
    L->weight[CF_FAMILY_EDGE] = 1;
    L->weight[CF_FAMILY_FACE] = (fam & 1) ? wd : 0;
    L->weight[CF_FAMILY_BODY] = (fam & 2) ? wd : 0;
    L->calibration = CF_CAL_CUSTOM;
    return CF_OK;
}
