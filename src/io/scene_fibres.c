/*
** Fibre groups of a scene (scene_internal.h, "fibres"; src/notes/simulate.md, "Fibre groups"):
** each entry is one spring per lattice cell along a material axis, acting in fibre tension only
** (model/fibre.h). The entry's reading is shared by every kind of scene that takes fibres.
*/
#include "io/scene.h"

#include <math.h>
#include <string.h>

#include "base/safetext.h"
#include "io/scene_internal.h"
#include "model/calibration.h"

/* Most springs per cell a fibre group may have (a stress scale, not a count to build). */
#define MAX_DENSITY 1e6
/* Largest recruitment strain a fibre group takes (fibre.h: below 1). */
#define MAX_SLACK 0.99

cf_status cf_scene_fibre_entry(ctx *c, json_t *e, const char *where, cf_scene_fibre *f)
{
    static const char *const keys[] = {"axis", "spring", "density", "recruitment_strain", NULL};
    cf_status st;
    if (!json_is_object(e))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, where);
    if ((st = cf_scene_only_keys(c, e, where, keys)))
        return st;
    memset(f, 0, sizeof *f);
    double a[3];
    if ((st = cf_scene_vec3(c, e, where, "axis", a)))
        return st;
    const double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(n > 1e-12) || !isfinite(n))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key '%s.axis' = [%g, %g, %g]: a direction must not be zero",
                            c->name, where, a[0], a[1], a[2]);
    for (int i = 0; i < 3; i++)
        f->axis[i] = a[i] / n;
    if (!json_object_get(e, "density"))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.density' is required (springs per "
                            "cell)", c->name, where);
    if ((st = cf_scene_number(c, e, where, "density", 1, 0, 0, 1, MAX_DENSITY, &f->density)) ||
        (st = cf_scene_number(c, e, where, "recruitment_strain", 0, 0, 0, 0, MAX_SLACK,
                              &f->slack)))
        return st;
    return cf_scene_fibre_spring(c, e, where, &f->spring, f->source);
}

cf_status cf_scene_fibre_fit(ctx *c, json_t *root, cf_scene *sc)
{
    static const char *const keys[] = {"fit", "cross_axis", NULL};
    json_t *fs = json_object_get(root, "fibres");
    sc->fibre_fit = 0;
    if (!json_is_object(fs))
        return CF_OK;
    cf_status st = cf_scene_only_keys(c, fs, "fibres", keys);
    if (st)
        return st;
    const char *path = json_string_value(json_object_get(fs, "fit"));
    const char *cross = json_string_value(json_object_get(fs, "cross_axis"));
    if (!path)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres.fit' must name a fit file (or "
                            "'fibres' be an array of groups)", c->name);
    if (!cross || (strcmp(cross, "s") != 0 && strcmp(cross, "n") != 0))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres.cross_axis' must be \"s\" or "
                            "\"n\" (the biaxial tables' second direction the fit took)", c->name);
    const char *other = json_object_get(root, "spring")             ? "spring"
                        : json_object_get(root, "spring_extension") ? "spring_extension"
                                                                    : NULL;
    if (other)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': the fibre fit of 'fibres.fit' "
                            "gives the lattice's spring; give one of them", c->name, other);
    cf_fitted_fibre ff;
    cf_error ferr = {0};
    if ((st = cf_fitfile_load_fibre(path, cross, &ff, &ferr)))
        return cf_error_set(c->err, st, "%s: key 'fibres.fit': %s", c->name, ferr.msg);
    sc->spring = cf_ident_member(&ff.matrix);
    char text[700];
    snprintf(text, sizeof text, "%s (fibre lattice, cross axis %s): matrix", path, cross);
    cf_safe_text(sc->spring_source, sizeof sc->spring_source, text, strlen(text));
    for (int k = 0; k < ff.ngroups; k++) {
        cf_scene_fibre *f = &sc->fibres[k];
        memset(f, 0, sizeof *f);
        const int a = ff.axis[k] == 'f' ? 0 : ff.axis[k] == 's' ? 1 : 2;
        f->axis[a] = 1;
        f->density = 1;
        f->slack = ff.slack[k];
        f->spring = cf_ident_member(&ff.group[k]);
        snprintf(text, sizeof text, "%s: group %c", path, ff.axis[k]);
        cf_safe_text(f->source, sizeof f->source, text, strlen(text));
    }
    sc->nfibres = (size_t)ff.ngroups;
    sc->fibre_fit_kappa_MPa = ff.kappa_MPa;
    memcpy(sc->fibre_fit_family, ff.family, sizeof sc->fibre_fit_family);
    sc->fibre_fit = 1;
    return CF_OK;
}

/* After a fibre fit: the lattice's weights (the fit's cell: each family its weight over the E of
** the fit's family weights, fibre_fit.c) and kappa, the lattice's own keys for them refused. */
static cf_status fit_lattice(ctx *c, json_t *root, cf_scene *sc)
{
    static const char *const own[] = {"weights", "calibration", "diagonals", "diagonal_weight",
                                      "volume_modulus_MPa", "poisson_ratio"};
    json_t *lt = json_object_get(root, "lattice");
    for (size_t k = 0; lt && k < sizeof own / sizeof own[0]; k++)
        if (json_object_get(lt, own[k]))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'lattice.%s': the fibre fit of "
                                "'fibres.fit' gives the lattice's weights and volume term",
                                c->name, own[k]);
    const double *u = sc->fibre_fit_family;
    const double E = cf_cubic_moduli_of(u).E;
    cf_lattice_config *L = &sc->cfg.lattice;
    for (int k = 0; k < CF_FAMILY_COUNT; k++)
        L->weight[k] = u[k] / E;
    L->calibration = CF_CAL_CUSTOM;
    L->volume_modulus_MPa = sc->fibre_fit_kappa_MPa;
    return CF_OK;
}

cf_status cf_scene_fibres(ctx *c, json_t *root, cf_scene *sc)
{
    json_t *fs = json_object_get(root, "fibres");
    if (sc->has_body && !sc->fibre_fit)
        return cf_scene_body_fibres(c, root, sc); /* a body's entries: helix rules */
    if (sc->fibre_fit)
        return sc->has_body ? cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres': a tissue body "
                                           "does not take a fibre fit here", c->name)
                            : fit_lattice(c, root, sc);
    sc->nfibres = 0;
    if (!fs)
        return CF_OK;
    if (!json_is_array(fs) || json_array_size(fs) == 0 || json_array_size(fs) > CF_FIBRE_MAX)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'fibres' must be an array of 1 to %d {\"axis\", \"spring\", "
                            "\"density\"} objects",
                            c->name, CF_FIBRE_MAX);
    for (size_t i = 0; i < json_array_size(fs); i++) {
        char where[32];
        snprintf(where, sizeof where, "fibres[%zu]", i);
        cf_status st = cf_scene_fibre_entry(c, json_array_get(fs, i), where, &sc->fibres[i]);
        if (st)
            return st;
        sc->nfibres++;
    }
    return CF_OK;
}

cf_status cf_scene_fibre_laws(const cf_scene *sc, cf_law law[CF_FIBRE_MAX],
                              cf_fibre_group grp[CF_FIBRE_MAX], cf_lattice_config *cfg,
                              cf_error *err)
{
    memset(law, 0, CF_FIBRE_MAX * sizeof *law);
    memset(grp, 0, CF_FIBRE_MAX * sizeof *grp);
    for (size_t k = 0; k < sc->nfibres; k++) {
        cf_status st = cf_law_init(&law[k], &sc->fibres[k].spring, err);
        if (st == CF_OK && sc->method == CF_LAW_TABLE)
            st = cf_law_table_build(&law[k], sc->table_intervals, err);
        if (st != CF_OK)
            return st;
        grp[k].law = &law[k];
        grp[k].method = sc->method;
        memcpy(grp[k].dir, sc->fibres[k].axis, sizeof grp[k].dir);
        grp[k].density = sc->fibres[k].density;
        grp[k].slack = sc->fibres[k].slack;
    }
    cfg->fibre = sc->nfibres ? grp : NULL;
    cfg->nfibre = (int)sc->nfibres;
    return CF_OK;
}
