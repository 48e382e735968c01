/*
** Scene files (scene.h): a tissue body's keys, "body", "fixed" and "probe" (src/notes/simulate.md,
** "Bodies").
*/
#include <math.h>
#include <string.h>

#include "io/scene_internal.h"

/* "body", "fixed" and "probe": a tissue body of a mesh pressed by a probe. */
static cf_status body_sections(ctx *c, json_t *root, json_t *bd, cf_scene *sc)
{
    static const char *const bk[] = {"mesh", "unit_mm", "refine", "poisson_ratio",
                                     "volume_modulus_MPa", NULL};
    static const char *const fk[] = {"below", NULL};
    static const char *const fbk[] = {"axis", "value_mm", NULL};
    static const char *const pk[] = {"shape", "radius_mm", "center_mm", "direction", "depth_mm",
                                     "steps", NULL};
    cf_status st;
    if (json_object_get(root, "lattice") || json_object_get(root, "protocol"))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'body' replaces 'lattice' and "
                            "'protocol' (the probe is the loading)", c->name);
    if ((st = cf_scene_only_keys(c, bd, "body", bk)))
        return st;
    json_t *mesh = json_object_get(bd, "mesh");
    if (!json_is_string(mesh))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'body.mesh' must be a file name", c->name);
    snprintf(sc->body_mesh, sizeof sc->body_mesh, "%s", json_string_value(mesh));
    double refine;
    if ((st = cf_scene_number(c, bd, "body", "unit_mm", 1, 1, 0, 1, 1e9, &sc->body_unit_mm)) ||
        (st = cf_scene_number(c, bd, "body", "refine", 0, 0, 0, 0, 4, &refine)))
        return st;
    if (refine != floor(refine))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'body.refine' = %g: must be a whole "
                            "number", c->name, refine);
    sc->body_refine = (int)refine;
    json_t *pr = json_object_get(bd, "poisson_ratio"), *km = json_object_get(bd, "volume_modulus_MPa");
    if (pr && km)
        return cf_error_set(c->err, CF_E_DATA, "%s: keys 'body.poisson_ratio' and "
                            "'body.volume_modulus_MPa' exclude each other", c->name);
    if (pr) {
        sc->body_volume = 2;
        if ((st = cf_scene_number(c, bd, "body", "poisson_ratio", 1, 0, 0.25, 0, 0.4999, &sc->body_volume_value)))
            return st;
    } else if (km) {
        sc->body_volume = 1;
        if ((st = cf_scene_number(c, bd, "body", "volume_modulus_MPa", 1, 0, 0, 0, 1e12, &sc->body_volume_value)))
            return st;
    }
    json_t *fx, *below, *pb;
    if ((st = cf_scene_object(c, root, "fixed", 1, &fx)) || (st = cf_scene_only_keys(c, fx, "fixed", fk)) ||
        (st = cf_scene_object(c, fx, "below", 1, &below)) || (st = cf_scene_only_keys(c, below, "fixed.below", fbk)))
        return st;
    json_t *ax = json_object_get(below, "axis");
    const char *an = json_is_string(ax) ? json_string_value(ax) : "";
    if (strlen(an) != 1 || !strchr("xyz", an[0]))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'fixed.below.axis' = '%s': expected x, y "
                            "or z", c->name, an);
    sc->fixed_axis = an[0] - 'x';
    if ((st = cf_scene_number(c, below, "fixed.below", "value_mm", 1, 0, -1e12, 0, 1e12, &sc->fixed_value_mm)))
        return st;
    if ((st = cf_scene_object(c, root, "probe", 1, &pb)) || (st = cf_scene_only_keys(c, pb, "probe", pk)))
        return st;
    json_t *shape = json_object_get(pb, "shape");
    const char *sn = json_is_string(shape) ? json_string_value(shape) : "";
    if (strcmp(sn, "sphere") == 0)
        sc->probe.shape = CF_PROBE_SPHERE;
    else if (strcmp(sn, "punch") == 0)
        sc->probe.shape = CF_PROBE_PUNCH;
    else
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.shape' = '%s': expected sphere or "
                            "punch", c->name, sn);
    double steps, d[3];
    if ((st = cf_scene_number(c, pb, "probe", "radius_mm", 1, 0, 0, 1, 1e12, &sc->probe.radius_mm)) ||
        (st = cf_scene_number(c, pb, "probe", "depth_mm", 1, 0, 0, 1, 1e12, &sc->probe.depth_mm)) ||
        (st = cf_scene_number(c, pb, "probe", "steps", 0, 10, 1, 0, 100000, &steps)) ||
        (st = cf_scene_vec3(c, pb, "probe", "center_mm", sc->probe.center_mm)) ||
        (st = cf_scene_vec3(c, pb, "probe", "direction", d)))
        return st;
    sc->probe.steps = (int)steps;
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0) || !isfinite(len))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.direction' = [%g, %g, %g]: must "
                            "not be zero", c->name, d[0], d[1], d[2]);
    for (int k = 0; k < 3; k++)
        sc->probe.dir[k] = d[k] / len;
    sc->has_body = 1;
    return CF_OK;
}

cf_status cf_scene_body(ctx *c, json_t *root, cf_scene *sc)
{
    cf_status st;
    json_t *bd;
    if ((st = cf_scene_object(c, root, "body", 0, &bd)))
        return st;
    if (!bd && (json_object_get(root, "fixed") || json_object_get(root, "probe")))
        return cf_error_set(c->err, CF_E_DATA, "%s: keys 'fixed' and 'probe' need a 'body'",
                            c->name);
    if (bd && (sc->has_extension || (c->from_fit && c->fit.volume_modulus_MPa > 0)))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'body': a body's edges take one spring law and its volume "
                            "term from 'body'; %s is not built for bodies",
                            c->name, sc->has_extension ? "a double-acting element"
                                                       : "the fit's lattice volume term");
    return bd ? body_sections(c, root, bd, sc) : CF_OK;
}
