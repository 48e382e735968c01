/*
** Scene files (see scene.h and src/notes/simulate.md, "Scenes"): JSON parsing with jansson, strict
** key checking, and the conversion of a loading protocol into a piecewise-linear path and the
** times at which samples are reported.
*/
#include "io/scene.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "base/input.h"
#include "base/safetext.h"
#include "io/fitfile.h"
#include "io/fitfile_json.h"
#include "io/scene_haptic.h"
#include "io/scene_internal.h"

/* Most cycles and samples a scene may ask for (keeps memory and run time bounded). */
#define MAX_CYCLES 1000
#define MAX_SAMPLES_PER_SEGMENT 100000

static cf_status spring_section(ctx *c, json_t *sp, cf_scene *sc)
{
    static const char *const allowed[] = {"fit", "type", "params", NULL};
    const char *pkeys[CF_P_ALL + 1]; /* the keys of the spring description (spring.h) */
    for (int k = 0; k < CF_P_ALL; k++)
        pkeys[k] = cf_spring_param_info(k)->key;
    pkeys[CF_P_ALL] = NULL;
    cf_status st = cf_scene_only_keys(c, sp, "spring", allowed);
    if (st)
        return st;
    json_t *fit = json_object_get(sp, "fit"), *params = json_object_get(sp, "params");
    json_t *type = json_object_get(sp, "type");
    if ((fit != NULL) == (params != NULL))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'spring' needs exactly one of 'spring.fit' or 'spring.params'",
                            c->name);
    if (type && !json_is_string(type))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'spring.type' must be a string", c->name);
    if (fit) {
        if (!json_is_string(fit))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'spring.fit' must be a file name",
                                c->name);
        const char *tn = type ? json_string_value(type) : NULL;
        if (tn && cf_spring_type_parse(tn, &(cf_spring_type){0}, NULL) != CF_OK)
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'spring.type' = '%s': expected telescoping or "
                                "non-telescoping",
                                c->name, tn);
        cf_fitted_spring fs;
        cf_error ferr = {0};
        /* the whole element: a double-acting fit's extension spring and its lattice's volume
        ** term come with it (never its compression spring alone) */
        st = cf_fitfile_load_element(json_string_value(fit), tn, &fs, &ferr);
        if (st)
            return cf_error_set(c->err, st, "%s: key 'spring.fit': %s", c->name, ferr.msg);
        sc->spring = fs.params;
        if (fs.has_extension) {
            sc->extension = fs.extension;
            sc->has_extension = 1;
        }
        c->fit = fs;
        c->from_fit = 1;
        /* the name as reports and output files may show it (base/safetext.h) */
        char named[sizeof sc->spring_source];
        snprintf(named, sizeof named, "%s:%s", json_string_value(fit), cf_spring_type_name(fs.type));
        cf_safe_text(sc->spring_source, sizeof sc->spring_source, named, strlen(named));
        snprintf(sc->fit_path, sizeof sc->fit_path, "%s", json_string_value(fit));
        return CF_OK;
    }
    if (type)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'spring.type' only goes with 'spring.fit'", c->name);
    if (!json_is_object(params))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'spring.params' must be an object",
                            c->name);
    if ((st = cf_scene_only_keys(c, params, "spring.params", pkeys)))
        return st;
    for (int k = 0; k < CF_P_ALL; k++) { /* the cone's six are required, the tail's two not */
        double v;
        const int cone = k < CF_P_COUNT;
        if ((st = cf_scene_number(c, params, "spring.params", pkeys[k], cone, 0, 0, cone, INFINITY, &v)))
            return st;
        cf_spring_set(&sc->spring, k, v);
    }
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init(&law, &sc->spring, &lerr) != CF_OK)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'spring.params': %s", c->name, lerr.msg);
    snprintf(sc->spring_source, sizeof sc->spring_source, "params");
    return CF_OK;
}

/* 'spring_extension': {"params": {...}}, the extension spring of a double-acting element (the
** six parameters of a conical spring, H the spring's). */
static cf_status extension_section(ctx *c, json_t *ex, cf_scene *sc)
{
    static const char *const allowed[] = {"params", NULL};
    const char *pkeys[CF_P_COUNT + 1];
    for (int k = 0; k < CF_P_COUNT; k++)
        pkeys[k] = cf_spring_param_info(k)->key;
    pkeys[CF_P_COUNT] = NULL;
    cf_status st = cf_scene_only_keys(c, ex, "spring_extension", allowed);
    if (st)
        return st;
    if (sc->has_extension) /* from 'spring.fit' */
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'spring_extension': 'spring.fit' = '%s' already holds a "
                            "double-acting element's extension spring",
                            c->name, sc->fit_path);
    json_t *params = json_object_get(ex, "params");
    if (!json_is_object(params))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'spring_extension.params' must be an object", c->name);
    if ((st = cf_scene_only_keys(c, params, "spring_extension.params", pkeys)))
        return st;
    memset(&sc->extension, 0, sizeof sc->extension);
    for (int k = 0; k < CF_P_COUNT; k++) {
        double v;
        if ((st = cf_scene_number(c, params, "spring_extension.params", pkeys[k], 1, 0, 0, 1, INFINITY,
                         &v)))
            return st;
        cf_spring_set(&sc->extension, k, v);
    }
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init(&law, &sc->extension, &lerr) != CF_OK)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'spring_extension.params': %s", c->name,
                            lerr.msg);
    if (sc->extension.H_mm != sc->spring.H_mm)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'spring_extension.params.H_mm' = %g: a double-acting element "
                            "shares the spring's free length %g mm",
                            c->name, sc->extension.H_mm, sc->spring.H_mm);
    sc->has_extension = 1;
    return CF_OK;
}

/* The volume term: 'lattice.volume_modulus_MPa' (kappa >= 0) or 'lattice.poisson_ratio' (the
** small-strain nu along an axis, 0.25 <= nu < 0.5 and at least the springs' own: kappa from the
** weights and the spring's k0/H, calibration.h); not both, and no nu for a double-acting
** element (its lattice has one nu in compression and another in tension). */
static cf_status volume_keys(ctx *c, json_t *lt, cf_scene *sc)
{
    cf_lattice_config *L = &sc->cfg.lattice;
    json_t *kv = lt ? json_object_get(lt, "volume_modulus_MPa") : NULL;
    json_t *nv = lt ? json_object_get(lt, "poisson_ratio") : NULL;
    cf_status st;
    if (kv && nv)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'lattice' takes 'volume_modulus_MPa' or "
                                               "'poisson_ratio', not both", c->name);
    const double fit_kappa = c->from_fit ? c->fit.volume_modulus_MPa : 0.0;
    if ((kv || nv) && fit_kappa > 0)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'lattice.%s': 'spring.fit' = '%s' already gives the "
                            "lattice's volume term (volume_modulus_MPa = %g)",
                            c->name, kv ? "volume_modulus_MPa" : "poisson_ratio", sc->fit_path,
                            fit_kappa);
    if ((st = cf_scene_kappa(c, lt, "lattice", &sc->spring, fit_kappa, &L->volume_modulus_MPa)))
        return st;
    if (!nv)
        return CF_OK;
    double nu;
    if ((st = cf_scene_number(c, lt, "lattice", "poisson_ratio", 1, 0, 0.25, 0, 0.5, &nu)))
        return st;
    if (!(nu < 0.5))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'lattice.poisson_ratio' = %g: must be "
                                               "below 0.5 (incompressible)", c->name, nu);
    if (sc->has_extension)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'lattice.poisson_ratio' = %g: a double-acting element's "
                            "lattice has one small-strain nu in compression and another in "
                            "tension; give 'volume_modulus_MPa'",
                            c->name, nu);
    cf_law law;
    if (cf_law_init(&law, &sc->spring, NULL) != CF_OK)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'lattice.poisson_ratio': no spring",
                            c->name);
    const double kappa = cf_cubic_kappa_of_nu(L->weight, law.k0_N_per_mm / law.p.H_mm, nu);
    if (!(kappa >= 0))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'lattice.poisson_ratio' = %g: the lattice's springs alone "
                            "give %.4g along an axis, and the volume term only raises it",
                            c->name, nu, cf_cubic_moduli_of(L->weight).nu);
    L->volume_modulus_MPa = kappa;
    return CF_OK;
}

static cf_status lattice_section(ctx *c, json_t *lt, cf_scene *sc)
{
    static const char *const allowed[] = {"nx", "ny", "nz", "weights", "calibration", "diagonals",
                                          "diagonal_weight", "bottom", "volume_modulus_MPa",
                                          "poisson_ratio", "hourglass", NULL};
    cf_status st;
    cf_lattice_config *L = &sc->cfg.lattice;
    if (lt && (st = cf_scene_only_keys(c, lt, "lattice", allowed)))
        return st;
    const char *dn[3] = {"nx", "ny", "nz"};
    int *dv[3] = {&L->nx, &L->ny, &L->nz};
    for (int k = 0; k < 3; k++) {
        double v;
        if ((st = cf_scene_number(c, lt, "lattice", dn[k], 0, *dv[k], 1, 0, 1000, &v)))
            return st;
        if (v != floor(v))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'lattice.%s' = %g: must be a whole "
                                "number", c->name, dn[k], v);
        *dv[k] = (int)v;
    }
    if ((st = cf_scene_weights(c, lt, L)))
        return st;
    json_t *b = lt ? json_object_get(lt, "bottom") : NULL;
    const char *bs = b ? json_string_value(b) : NULL;
    if (b && !(bs && (strcmp(bs, "axial") == 0 || strcmp(bs, "clamped") == 0)))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'lattice.bottom' = '%s': expected axial or clamped", c->name,
                            bs ? bs : "(not a string)");
    if (b)
        L->bottom = strcmp(bs, "clamped") == 0 ? CF_BOTTOM_CLAMPED : CF_BOTTOM_AXIAL;
    /* hourglass control (lattice_hourglass.h), absent: automatic */
    if ((st = cf_scene_number(c, lt, "lattice", "hourglass", 0, CF_HOURGLASS_AUTO, 0, 0, 1000,
                              &L->hourglass)))
        return st;
    return volume_keys(c, lt, sc);
}

/* effects.viscosity.prony: [{"g": .., "tau_s": .., "g_per_strain": ..}, ...] (g_per_strain
** optional, 0: quasi-linear), alone (no E_kPa, tau_s beside it),
** checked as the lattice takes it (g >= 0, sum g < 1, tau > 0, at most CF_PRONY_MAX). */
static cf_status prony_list(ctx *c, json_t *vs, json_t *pr, cf_msm_effects *e)
{
    static const char *const tkeys[] = {"g", "tau_s", "g_per_strain", NULL};
    if (json_object_get(vs, "E_kPa") || json_object_get(vs, "tau_s"))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'effects.viscosity' takes either 'prony' or 'E_kPa' and "
                            "'tau_s', not both",
                            c->name);
    if (!json_is_array(pr) || json_array_size(pr) < 1 || json_array_size(pr) > CF_PRONY_MAX)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'effects.viscosity.prony' must be a list of 1 to %d terms "
                            "{\"g\": .., \"tau_s\": ..}",
                            c->name, CF_PRONY_MAX);
    size_t i;
    json_t *term;
    cf_status st;
    json_array_foreach(pr, i, term)
    {
        char where[64];
        snprintf(where, sizeof where, "effects.viscosity.prony[%zu]", i);
        if (!json_is_object(term))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name,
                                where);
        if ((st = cf_scene_only_keys(c, term, where, tkeys)) ||
            (st = cf_scene_number(c, term, where, "g", 1, 0, 0, 0, 1, &e->prony_g[i])) ||
            (st = cf_scene_number(c, term, where, "tau_s", 1, 0, 0, 1, 1e12, &e->prony_tau_s[i])) ||
            (st = cf_scene_number(c, term, where, "g_per_strain", 0, 0, -1e6, 0, 1e6, &e->prony_k[i])))
            return st;
    }
    e->prony_count = (int)json_array_size(pr);
    cf_error pe = {0};
    if (cf_msm_prony_check(e, &pe) != CF_OK)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'effects.viscosity.prony': %s", c->name,
                            pe.msg);
    return CF_OK;
}

static cf_status effects_section(ctx *c, json_t *ef, cf_scene *sc)
{
    static const char *const allowed[] = {"inertia", "damping", "viscosity", "gravity", NULL};
    static const char *const dkeys[] = {"eta_kPa_s", NULL};
    static const char *const vkeys[] = {"E_kPa", "tau_s", "prony", NULL};
    cf_status st;
    cf_msm_effects *e = &sc->effects;
    memset(e, 0, sizeof *e);
    /* A viscoelastic fit file brings its Prony terms and dashpot; the scene's own
    ** effects.viscosity and effects.damping replace them. */
    const int fit_visco = c->from_fit && c->fit.viscoelastic;
    if (fit_visco) {
        e->prony_count = c->fit.prony_count;
        memcpy(e->prony_g, c->fit.prony_g, sizeof e->prony_g);
        memcpy(e->prony_tau_s, c->fit.prony_tau_s, sizeof e->prony_tau_s);
        memcpy(e->prony_k, c->fit.prony_k, sizeof e->prony_k);
        e->eta_MPa_s = c->fit.eta_MPa_s;
    }
    if (!ef)
        return CF_OK;
    if ((st = cf_scene_only_keys(c, ef, "effects", allowed)))
        return st;
    if ((st = cf_scene_boolean(c, ef, "effects", "inertia", &e->inertia)))
        return st;
    int g = 0;
    if ((st = cf_scene_boolean(c, ef, "effects", "gravity", &g)))
        return st;
    e->gravity_mm_per_s2 = g ? 9806.65 : 0.0;
    json_t *dm = json_object_get(ef, "damping"), *vs = json_object_get(ef, "viscosity");
    if (dm) {
        if (!json_is_object(dm))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'effects.damping' must be an object "
                                "{\"eta_kPa_s\": ...}", c->name);
        double eta;
        e->eta_MPa_s = 0;
        if ((st = cf_scene_only_keys(c, dm, "effects.damping", dkeys)) ||
            (st = cf_scene_number(c, dm, "effects.damping", "eta_kPa_s", 1, 0, 0, 1, 1e12, &eta)))
            return st;
        e->eta_MPa_s = eta * 1e-3;
    }
    if (vs) {
        if (!json_is_object(vs))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'effects.viscosity' must be an object "
                                "{\"E_kPa\": ..., \"tau_s\": ...}", c->name);
        double E, tau;
        json_t *pr = json_object_get(vs, "prony");
        e->prony_count = 0;
        if ((st = cf_scene_only_keys(c, vs, "effects.viscosity", vkeys)))
            return st;
        if (pr) {
            if ((st = prony_list(c, vs, pr, e)))
                return st;
        } else {
            if ((st = cf_scene_number(c, vs, "effects.viscosity", "E_kPa", 1, 0, 0, 1, 1e12, &E)) ||
                (st = cf_scene_number(c, vs, "effects.viscosity", "tau_s", 1, 0, 0, 1, 1e12, &tau)))
                return st;
            e->maxwell_E_MPa = E * 1e-3;
            e->maxwell_tau_s = tau;
        }
    }
    if (e->prony_count > 0 && e->inertia && !sc->has_body) /* a body uses the elastic law */
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: Prony terms (effects.viscosity.prony or a viscoelastic "
                            "spring.fit) are solved quasi-statically: they do not combine with "
                            "'effects.inertia' = true",
                            c->name);
    if (g && !e->inertia)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'effects.gravity' = true needs 'effects.inertia' = true "
                            "(weight is carried by masses)",
                            c->name);
    return CF_OK;
}

static cf_status push(cf_scene *sc, size_t *cap, double t, double v)
{
    if (sc->npath == *cap) {
        size_t nc = *cap ? 2 * *cap : 8;
        double *a = realloc(sc->path_t_s, nc * sizeof(double));
        if (!a)
            return CF_E_INTERNAL;
        sc->path_t_s = a;
        double *b = realloc(sc->path_v, nc * sizeof(double));
        if (!b)
            return CF_E_INTERNAL;
        sc->path_v = b;
        *cap = nc;
    }
    sc->path_t_s[sc->npath] = t;
    sc->path_v[sc->npath] = v;
    sc->npath++;
    return CF_OK;
}

/* protocol "history": {"t_s": [...], "to_strain": [...]} (or "to_stress_kPa": [...]), the path
** through those points (time increasing, compressive values, as for the other kinds): a measured
** loading history, e.g. the series of a viscoelastic fit. */
static cf_status history_protocol(ctx *c, json_t *pr, cf_scene *sc, size_t *cap)
{
    static const char *const ok[] = {"kind", "t_s", "to_strain", "to_stress_kPa", NULL};
    cf_status st;
    if ((st = cf_scene_only_keys(c, pr, "protocol", ok)))
        return st;
    json_t *t = json_object_get(pr, "t_s"), *vs = json_object_get(pr, "to_strain"),
           *vf = json_object_get(pr, "to_stress_kPa");
    json_t *v = vs ? vs : vf;
    if ((vs != NULL) == (vf != NULL))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'protocol' (history) needs exactly one of "
                            "'protocol.to_strain' or 'protocol.to_stress_kPa' (lists)",
                            c->name);
    if (!json_is_array(t) || !json_is_array(v) || json_array_size(t) < 2 ||
        json_array_size(t) != json_array_size(v) || json_array_size(t) > MAX_SAMPLES_PER_SEGMENT)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: keys 'protocol.t_s' and 'protocol.%s' must be lists of the same "
                            "length, 2 to %d values",
                            c->name, vs ? "to_strain" : "to_stress_kPa", MAX_SAMPLES_PER_SEGMENT);
    sc->kind = CF_PROTO_HISTORY;
    sc->drive = vs ? CF_DRIVE_DISPLACEMENT : CF_DRIVE_FORCE;
    cf_law law;
    const double solid = cf_law_init(&law, &sc->spring, NULL) == CF_OK
                             ? law.travel_mm / law.p.H_mm
                             : 1.0;
    sc->target = 0;
    for (size_t i = 0; i < json_array_size(t); i++) {
        json_t *ti = json_array_get(t, i), *vi = json_array_get(v, i);
        double tv = json_number_value(ti), vv = json_number_value(vi);
        if (!json_is_number(ti) || !isfinite(tv) || (i > 0 && !(tv > sc->path_t_s[i - 1])) ||
            (i == 0 && tv < 0))
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'protocol.t_s[%zu]' = %g: times must be >= 0 and "
                                "increase",
                                c->name, i, tv);
        if (!json_is_number(vi) || !isfinite(vv) || (vs && !(fabs(vv) < solid)))
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'protocol.%s[%zu]' = %g: %s", c->name,
                                vs ? "to_strain" : "to_stress_kPa", i, vv,
                                vs ? "a strain short of the spring's solid strain"
                                   : "a finite stress");
        if (push(sc, cap, tv, vs ? vv : vv * 1e-3))
            return cf_error_set(c->err, CF_E_INTERNAL, "out of memory for the loading path");
        if (fabs(sc->path_v[i]) > fabs(sc->target))
            sc->target = sc->path_v[i];
    }
    return CF_OK;
}

/* The drive and target of a ramp, cycles or hold protocol: exactly one of to_strain (a strain
** short of the spring's solid strain) or to_stress_kPa; sc->drive and sc->target (MPa). */
static cf_status protocol_target(ctx *c, json_t *pr, cf_scene *sc)
{
    json_t *ts = json_object_get(pr, "to_strain"), *tf = json_object_get(pr, "to_stress_kPa");
    if ((ts != NULL) == (tf != NULL))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'protocol' needs exactly one of 'protocol.to_strain' "
                            "(displacement drive) or 'protocol.to_stress_kPa' (force drive)",
                            c->name);
    cf_status st;
    double target;
    if (ts) {
        sc->drive = CF_DRIVE_DISPLACEMENT;
        if ((st = cf_scene_number(c, pr, "protocol", "to_strain", 1, 0, -0.999, 0, 0.999, &target)))
            return st;
        /* A compressive strain at or past the spring's solid strain cannot be reached. */
        cf_law law;
        if (cf_law_init(&law, &sc->spring, NULL) == CF_OK &&
            fabs(target) >= law.travel_mm / law.p.H_mm)
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'protocol.to_strain' = %g: at or beyond the spring's "
                                "solid strain %.6g",
                                c->name, target, law.travel_mm / law.p.H_mm);
    } else {
        sc->drive = CF_DRIVE_FORCE;
        if ((st = cf_scene_number(c, pr, "protocol", "to_stress_kPa", 1, 0, -1e9, 0, 1e9, &target)))
            return st;
        target *= 1e-3;
    }
    sc->target = target;
    return CF_OK;
}

static cf_status path_oom(ctx *c)
{
    return cf_error_set(c->err, CF_E_INTERNAL, "out of memory for the loading path");
}

/* ramp: from rest to the target in duration_s. */
static cf_status ramp_protocol(ctx *c, json_t *pr, cf_scene *sc, size_t *cap)
{
    static const char *const ok[] = {"kind", "to_strain", "to_stress_kPa", "duration_s", NULL};
    double dur;
    cf_status st;
    if ((st = cf_scene_only_keys(c, pr, "protocol", ok)) ||
        (st = cf_scene_number(c, pr, "protocol", "duration_s", 0, 1, 0, 1, 1e9, &dur)))
        return st;
    sc->kind = CF_PROTO_RAMP;
    if (push(sc, cap, 0, 0) || push(sc, cap, dur, sc->target))
        return path_oom(c);
    return CF_OK;
}

/* cycles: count load-unload cycles of period_s, each to the target and back to rest. */
static cf_status cycles_protocol(ctx *c, json_t *pr, cf_scene *sc, size_t *cap)
{
    static const char *const ok[] = {"kind", "to_strain", "to_stress_kPa", "period_s", "count",
                                     NULL};
    double period, count;
    cf_status st;
    if ((st = cf_scene_only_keys(c, pr, "protocol", ok)) ||
        (st = cf_scene_number(c, pr, "protocol", "period_s", 1, 0, 0, 1, 1e9, &period)) ||
        (st = cf_scene_number(c, pr, "protocol", "count", 0, 1, 1, 0, MAX_CYCLES, &count)))
        return st;
    if (count != floor(count))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'protocol.count' = %g: must be a "
                            "whole number", c->name, count);
    sc->kind = CF_PROTO_CYCLES;
    sc->cycles = (int)count;
    if (push(sc, cap, 0, 0))
        return path_oom(c);
    for (int k = 0; k < sc->cycles; k++)
        if (push(sc, cap, (k + 0.5) * period, sc->target) || push(sc, cap, (k + 1) * period, 0))
            return path_oom(c);
    return CF_OK;
}

/* hold: a ramp to the target in ramp_s, then the target held for hold_s. */
static cf_status hold_protocol(ctx *c, json_t *pr, cf_scene *sc, size_t *cap)
{
    static const char *const ok[] = {"kind", "to_strain", "to_stress_kPa", "ramp_s", "hold_s",
                                     NULL};
    double ramp, hold;
    cf_status st;
    if ((st = cf_scene_only_keys(c, pr, "protocol", ok)) ||
        (st = cf_scene_number(c, pr, "protocol", "ramp_s", 1, 0, 0, 1, 1e9, &ramp)) ||
        (st = cf_scene_number(c, pr, "protocol", "hold_s", 1, 0, 0, 1, 1e9, &hold)))
        return st;
    sc->kind = CF_PROTO_HOLD;
    if (push(sc, cap, 0, 0) || push(sc, cap, ramp, sc->target) ||
        push(sc, cap, ramp + hold, sc->target))
        return path_oom(c);
    return CF_OK;
}

/* Samples: every path segment split in samples_per_segment intervals. */
static cf_status path_samples(ctx *c, cf_scene *sc, double samples_per_segment)
{
    size_t per = (size_t)samples_per_segment;
    if ((double)(sc->npath - 1) * (double)per + 1 > CF_SCENE_MAX_SAMPLES)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'samples_per_segment' = %zu: %zu path segments would give "
                            "%.3g samples, more than the %d a scene may have",
                            c->name, per, sc->npath - 1, (double)(sc->npath - 1) * (double)per + 1,
                            CF_SCENE_MAX_SAMPLES);
    sc->nsamples = (sc->npath - 1) * per + 1;
    sc->sample_t_s = malloc(sc->nsamples * sizeof(double));
    if (!sc->sample_t_s)
        return path_oom(c);
    size_t k = 0;
    sc->sample_t_s[k++] = sc->path_t_s[0];
    for (size_t i = 1; i < sc->npath; i++)
        for (size_t j = 1; j <= per; j++)
            sc->sample_t_s[k++] = sc->path_t_s[i - 1] +
                                  (sc->path_t_s[i] - sc->path_t_s[i - 1]) * (double)j / per;
    return CF_OK;
}

/* The protocol: its kind's path (history, or ramp, cycles or hold to a target), then the
** samples along it. */
static cf_status protocol_section(ctx *c, json_t *pr, cf_scene *sc, double samples_per_segment)
{
    static const char *const allowed[] = {"kind", "to_strain", "to_stress_kPa", "duration_s",
                                          "period_s", "count", "ramp_s", "hold_s", "t_s", NULL};
    cf_status st;
    if ((st = cf_scene_only_keys(c, pr, "protocol", allowed)))
        return st;
    const char *kind = json_string_value(json_object_get(pr, "kind"));
    if (!kind)
        return cf_error_set(c->err, CF_E_DATA, "%s: missing key 'protocol.kind' (ramp, cycles, "
                            "hold or history)", c->name);
    size_t cap = 0;
    if (strcmp(kind, "history") == 0)
        st = history_protocol(c, pr, sc, &cap);
    else if ((st = protocol_target(c, pr, sc)) != CF_OK)
        return st;
    else if (strcmp(kind, "ramp") == 0)
        st = ramp_protocol(c, pr, sc, &cap);
    else if (strcmp(kind, "cycles") == 0)
        st = cycles_protocol(c, pr, sc, &cap);
    else if (strcmp(kind, "hold") == 0)
        st = hold_protocol(c, pr, sc, &cap);
    else
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'protocol.kind' = '%s': expected ramp, cycles, hold or history",
                            c->name, kind);
    return st != CF_OK ? st : path_samples(c, sc, samples_per_segment);
}

/* "haptic" (scene_haptic.h): a body's probe path in time. */
static cf_status haptic_key(ctx *c, json_t *root, cf_scene *sc)
{
    json_t *h = json_object_get(root, "haptic");
    if (h && !sc->has_body)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'haptic' needs a 'body'", c->name);
    return h ? cf_scene_haptic_parse(h, c->name, sc, c->err) : CF_OK;
}

static cf_status parse_root(ctx *c, json_t *root, cf_scene *sc)
{
    static const char *const allowed[] = {"spring", "spring_extension", "lattice",
                                          "density_t_per_mm3", "protocol", "effects",
                                          "integrator", "law_method", "table_intervals",
                                          "samples_per_segment", "comment", "body", "fixed",
                                          "displaced", "loaded", "probe", "haptic", "groups",
                                          "fibres", NULL};
    cf_status st;
    if (!json_is_object(root))
        return cf_error_set(c->err, CF_E_DATA, "%s: a scene must be a JSON object", c->name);
    if ((st = cf_scene_only_keys(c, root, "", allowed)))
        return st;
    sc->cfg = cf_msm_default();
    sc->method = CF_LAW_CLOSED;
    sc->table_intervals = CF_LAW_TABLE_DEFAULT;
    json_t *sp, *lt, *pr, *ef, *in, *ex;
    if ((st = cf_scene_fibre_fit(c, root, sc)) || (!sc->fibre_fit && ((st = cf_scene_object(
            c, root, "spring", 1, &sp)) || (st = spring_section(c, sp, sc)))))
        return st;
    if ((st = cf_scene_object(c, root, "spring_extension", 0, &ex)) ||
        (ex && (st = extension_section(c, ex, sc))))
        return st;
    if ((st = cf_scene_body(c, root, sc)) || (st = haptic_key(c, root, sc)))
        return st;
    if ((st = cf_scene_object(c, root, "lattice", 0, &lt)) || (st = lattice_section(c, lt, sc)) ||
        (st = cf_scene_groups(c, root, sc)) || (st = cf_scene_fibres(c, root, sc)))
        return st;
    if ((st = cf_scene_number(c, root, "", "density_t_per_mm3", 0, 1e-9, 0, 1, 1, 
                     &sc->cfg.lattice.density_t_per_mm3)))
        return st;
    if ((st = cf_scene_object(c, root, "effects", 0, &ef)) || (st = effects_section(c, ef, sc)))
        return st;
    json_t *lm = json_object_get(root, "law_method");
    if (lm) {
        cf_error merr = {0};
        if (!json_is_string(lm) || cf_law_method_parse(json_string_value(lm), &sc->method, &merr))
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key 'law_method' = '%s': expected exact, closed, "
                                "closed+newton or table",
                                c->name, json_is_string(lm) ? json_string_value(lm) : "?");
    }
    double ti;
    if ((st = cf_scene_number(c, root, "", "table_intervals", 0, CF_LAW_TABLE_DEFAULT, 2, 0, 1e7, &ti)))
        return st;
    sc->table_intervals = (size_t)ti;
    if ((st = cf_scene_object(c, root, "integrator", 0, &in)))
        return st;
    if (in) {
        static const char *const ik[] = {"dt_s", "substeps", NULL};
        double sub;
        if ((st = cf_scene_only_keys(c, in, "integrator", ik)) ||
            (st = cf_scene_number(c, in, "integrator", "dt_s", 0, 0, 0, 0, 1e6, &sc->cfg.dt_s)) ||
            (st = cf_scene_number(c, in, "integrator", "substeps", 0, 10, 1, 0, 1e6, &sub)))
            return st;
        sc->cfg.quasi_substeps = (int)sub;
    }
    double per;
    if ((st = cf_scene_number(c, root, "", "samples_per_segment", 0, 50, 1, 0, MAX_SAMPLES_PER_SEGMENT,
                     &per)))
        return st;
    if (sc->has_body) /* the probe is the loading */
        return cf_scene_body_dynamics(c, root, sc);
    if ((st = cf_scene_object(c, root, "protocol", 1, &pr)) ||
        (st = protocol_section(c, pr, sc, floor(per))))
        return st;
    return CF_OK;
}

void cf_scene_free(cf_scene *sc)
{
    if (!sc)
        return;
    free(sc->path_t_s);
    free(sc->path_v);
    free(sc->sample_t_s);
    free(sc->haptic_t_ms);
    free(sc->haptic_depth_mm);
    sc->path_t_s = sc->path_v = sc->sample_t_s = sc->haptic_t_ms = sc->haptic_depth_mm = NULL;
}

static cf_status finish(ctx *c, json_t *root, json_error_t *jerr, cf_scene *sc)
{
    char why[JSON_ERROR_TEXT_LENGTH];
    if (!root)
        return cf_error_set(c->err, CF_E_DATA, "%s:%d:%d: not valid JSON: %s", c->name,
                            jerr->line, jerr->column, cf_json_reason(jerr, why, sizeof why));
    cf_status st = parse_root(c, root, sc);
    json_decref(root);
    if (st != CF_OK)
        cf_scene_free(sc);
    return st;
}

cf_status cf_scene_law(const cf_scene *sc, cf_law *law, cf_law *ext, cf_error *err)
{
    memset(ext, 0, sizeof *ext);
    cf_status s = cf_law_init(law, &sc->spring, err);
    if (s == CF_OK && sc->method == CF_LAW_TABLE)
        s = cf_law_table_build(law, sc->table_intervals, err);
    if (s == CF_OK && sc->has_extension) {
        if ((s = cf_law_init(ext, &sc->extension, err)) == CF_OK && sc->method == CF_LAW_TABLE)
            s = cf_law_table_build(ext, sc->table_intervals, err);
        if (s == CF_OK)
            s = cf_law_pair(law, ext, err);
    }
    return s;
}

cf_status cf_scene_parse(const char *json_text, const char *name, cf_scene *sc, cf_error *err)
{
    memset(sc, 0, sizeof *sc);
    ctx c;
    memset(&c, 0, sizeof c);
    c.name = name;
    c.err = err;
    json_error_t jerr;
    json_t *root = json_loads(json_text, JSON_REJECT_DUPLICATES, &jerr);
    return finish(&c, root, &jerr, sc);
}

cf_status cf_scene_load(const char *path, cf_scene *sc, cf_error *err)
{
    memset(sc, 0, sizeof *sc);
    ctx c;
    memset(&c, 0, sizeof c);
    c.name = path;
    c.err = err;
    FILE *f = cf_input_open(path, "scene", err);
    if (!f)
        return CF_E_NOINPUT;
    json_error_t jerr;
    errno = 0;
    json_t *root = json_loadf(f, JSON_REJECT_DUPLICATES, &jerr);
    int unreadable = ferror(f), e = errno;
    fclose(f);
    if (!root && unreadable) /* a read error, not bad JSON */
        return cf_error_set(err, CF_E_NOINPUT, "%s: cannot read scene: %s", path,
                            strerror(e ? e : EIO));
    return finish(&c, root, &jerr, sc);
}

cf_msm_path cf_scene_path(const cf_scene *sc)
{
    cf_msm_path p = {sc->drive, sc->npath, sc->path_t_s, sc->path_v};
    return p;
}
