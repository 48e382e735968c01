/*
** A body scene's fibre groups (scene_internal.h, "fibres"; src/notes/simulate.md, "Fibres in a
** body"): each entry a direction rule, a spring and a density,
**   {"helix": {"normal": [0, 0, 1], "from_deg": -60, "to_deg": 60, "reference": [1, 0, 0]},
**    "spring": {"params": {...}} or {"fit": file}, "density": 1}.
*/
#include "io/scene.h"

#include <math.h>
#include <string.h>

#include "io/scene_internal.h"

/* The entry's "helix" at where into f. */
static cf_status helix(ctx *c, json_t *h, const char *where, cf_scene_body_fibre *f)
{
    static const char *const ok[] = {"normal", "reference", "from_deg", "to_deg", NULL};
    cf_status st;
    if (!json_is_object(h))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object {\"normal\", "
                            "\"reference\", \"from_deg\", \"to_deg\"}", c->name, where);
    if ((st = cf_scene_only_keys(c, h, where, ok)) ||
        (st = cf_scene_vec3(c, h, where, "normal", f->normal)) ||
        (st = cf_scene_vec3(c, h, where, "reference", f->reference)) ||
        (st = cf_scene_number(c, h, where, "from_deg", 1, 0, -360, 0, 360, &f->from_deg)) ||
        (st = cf_scene_number(c, h, where, "to_deg", 1, 0, -360, 0, 360, &f->to_deg)))
        return st;
    const double *n = f->normal, *r = f->reference;
    const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double rr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(nn > 0))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.normal' = [%g, %g, %g]: must not be "
                            "zero", c->name, where, n[0], n[1], n[2]);
    const double cr = (n[0] * r[0] + n[1] * r[1] + n[2] * r[2]) / (nn * rr);
    if (!(rr > 0) || !(fabs(cr) < 1 - 1e-12))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.reference' = [%g, %g, %g]: must not be "
                            "zero or along the normal (the angle is measured from it in the "
                            "plane normal to the normal)", c->name, where, r[0], r[1], r[2]);
    return CF_OK;
}

/* Entry i of "fibres". */
static cf_status fibre_entry(ctx *c, json_t *e, size_t i, cf_scene *sc)
{
    static const char *const ok[] = {"helix", "spring", "density", "recruitment_strain", NULL};
    char where[48], hw[64], sw[64];
    snprintf(where, sizeof where, "fibres[%zu]", i);
    snprintf(hw, sizeof hw, "%s.helix", where);
    snprintf(sw, sizeof sw, "%s.spring", where);
    cf_status st;
    if (!json_is_object(e))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, where);
    if ((st = cf_scene_only_keys(c, e, where, ok)))
        return st;
    cf_scene_body_fibre *f = &sc->body_fibres[sc->body_nfibres];
    memset(f, 0, sizeof *f);
    json_t *h = json_object_get(e, "helix"), *sp = json_object_get(e, "spring");
    if (!h)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' is required (the fibre direction's "
                            "rule)", c->name, hw);
    if (!sp)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' is required", c->name, sw);
    if ((st = helix(c, h, hw, f)) ||
        (st = cf_scene_number(c, e, where, "density", 0, 1, 0, 1, 1e6, &f->density)) ||
        (st = cf_scene_number(c, e, where, "recruitment_strain", 0, 0, 0, 0, 0.99, &f->slack)))
        return st;
    if ((st = cf_scene_fibre_spring(c, e, where, &f->spring, f->source)))
        return st;
    sc->body_nfibres++;
    return CF_OK;
}

cf_status cf_scene_body_fibres(ctx *c, json_t *root, cf_scene *sc)
{
    json_t *fs = json_object_get(root, "fibres");
    sc->body_nfibres = 0;
    if (!fs)
        return CF_OK;
    if (!sc->has_body)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres' needs a 'body' (a lattice "
                            "scene's fibre groups are not read here)", c->name);
    if (sc->has_extension)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres': the scene's element is "
                            "double-acting; fibres go with a single spring's body", c->name);
    if (!json_is_array(fs) || json_array_size(fs) == 0)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres' must be a non-empty array of "
                            "{\"helix\", \"spring\", \"density\"} objects", c->name);
    if (json_array_size(fs) > CF_FIBRE_MAX)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fibres' has %zu entries: a body has at "
                            "most %d", c->name, json_array_size(fs), CF_FIBRE_MAX);
    for (size_t i = 0; i < json_array_size(fs); i++) {
        cf_status st = fibre_entry(c, json_array_get(fs, i), i, sc);
        if (st)
            return st;
    }
    return CF_OK;
}
