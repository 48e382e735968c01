/*
** Fibre groups of a scene (scene_internal.h, "fibres"; src/notes/simulate.md, "Fibre groups"):
** each entry is one spring per lattice cell along a material axis, acting in fibre tension only
** (model/fibre.h). The entry's reading is shared by every kind of scene that takes fibres.
*/
#include "io/scene.h"

#include <math.h>
#include <string.h>

#include "io/scene_internal.h"

/* Most springs per cell a fibre group may have (a stress scale, not a count to build). */
#define MAX_DENSITY 1e6

cf_status cf_scene_fibre_entry(ctx *c, json_t *e, const char *where, cf_scene_fibre *f)
{
    static const char *const keys[] = {"axis", "spring", "density", NULL};
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
    if ((st = cf_scene_number(c, e, where, "density", 1, 0, 0, 1, MAX_DENSITY, &f->density)))
        return st;
    char sw[96];
    snprintf(sw, sizeof sw, "%s.spring", where);
    json_t *sp = json_object_get(e, "spring");
    if (!sp)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' is required", c->name, sw);
    cf_scene_group g;
    memset(&g, 0, sizeof g);
    if ((st = cf_scene_group_spring(c, sp, sw, &g)))
        return st;
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init(&law, &g.spring, &lerr) != CF_OK)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': %s", c->name, sw, lerr.msg);
    cf_law_free(&law);
    f->spring = g.spring;
    memcpy(f->source, g.source, sizeof f->source);
    return CF_OK;
}

cf_status cf_scene_fibres(ctx *c, json_t *root, cf_scene *sc)
{
    json_t *fs = json_object_get(root, "fibres");
    sc->nfibres = 0;
    if (!fs)
        return CF_OK;
    if (sc->has_body)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres': a tissue body does not take "
                            "fibre groups here (a lattice scene does)", c->name);
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
    }
    cfg->fibre = sc->nfibres ? grp : NULL;
    cfg->nfibre = (int)sc->nfibres;
    return CF_OK;
}
