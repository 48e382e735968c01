/*
** Scene files (scene.h): a tissue body's keys, "body", "fixed" and "probe" (src/notes/simulate.md,
** "Bodies").
*/
#include <math.h>
#include <string.h>
#include <strings.h>

#include "io/scene_internal.h"
#include "model/calibration.h"

/* A plane selector, "below" or "above": {"axis": "x"|"y"|"z", "value_mm": V} (the coordinate
** against V) or {"normal": [nx, ny, nz], "point_mm": [x, y, z]} (the side of the plane through the
** point, along the normal). */
static cf_status plane(ctx *c, json_t *v, const char *where, cf_select *s)
{
    static const char *const ok[] = {"axis", "value_mm", "normal", "point_mm", NULL};
    cf_status st;
    if (!json_is_object(v))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, where);
    if ((st = cf_scene_only_keys(c, v, where, ok)))
        return st;
    json_t *ax = json_object_get(v, "axis");
    if (ax) {
        const char *an = json_is_string(ax) ? json_string_value(ax) : "";
        if (strlen(an) != 1 || !strchr("xyz", an[0]))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.axis' = '%s': expected x, y or z",
                                c->name, where, an);
        if (json_object_get(v, "normal") || json_object_get(v, "point_mm"))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' takes 'axis' and 'value_mm' or "
                                "'normal' and 'point_mm'", c->name, where);
        s->n[an[0] - 'x'] = 1;
        return cf_scene_number(c, v, where, "value_mm", 1, 0, -1e12, 0, 1e12, &s->value_mm);
    }
    double p[3];
    if (json_object_get(v, "value_mm"))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.value_mm' goes with 'axis'", c->name,
                            where);
    if ((st = cf_scene_vec3(c, v, where, "normal", s->n)) ||
        (st = cf_scene_vec3(c, v, where, "point_mm", p)))
        return st;
    double len = sqrt(s->n[0] * s->n[0] + s->n[1] * s->n[1] + s->n[2] * s->n[2]);
    if (!(len > 0) || !isfinite(len))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.normal' = [%g, %g, %g]: must not be "
                            "zero", c->name, where, s->n[0], s->n[1], s->n[2]);
    for (int a = 0; a < 3; a++)
        s->n[a] /= len;
    s->value_mm = s->n[0] * p[0] + s->n[1] * p[1] + s->n[2] * p[2];
    return CF_OK;
}

/* "group": a name, a number, or {"name": NAME} / {"tag": NUMBER} with an optional "dim". */
static cf_status group(ctx *c, json_t *v, const char *where, cf_select *s)
{
    static const char *const ok[] = {"name", "tag", "dim", NULL};
    cf_status st;
    s->group_tag = -1;
    s->group_dim = -1;
    json_t *name = v, *tag = v;
    if (json_is_object(v)) {
        if ((st = cf_scene_only_keys(c, v, where, ok)))
            return st;
        name = json_object_get(v, "name");
        tag = json_object_get(v, "tag");
        if ((name != NULL) == (tag != NULL))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' takes one of 'name' or 'tag'",
                                c->name, where);
        if (json_object_get(v, "dim")) {
            double d;
            if ((st = cf_scene_number(c, v, where, "dim", 1, 0, 0, 0, 3, &d)))
                return st;
            if (d != floor(d))
                return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.dim' = %g: expected 0, 1, 2 "
                                    "or 3", c->name, where, d);
            s->group_dim = (int)d;
        }
    }
    if (name && json_is_string(name)) {
        if (strlen(json_string_value(name)) >= sizeof s->group_name || !*json_string_value(name))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': a group's name has 1 to %zu "
                                "characters", c->name, where, sizeof s->group_name - 1);
        snprintf(s->group_name, sizeof s->group_name, "%s", json_string_value(name));
        return CF_OK;
    }
    if (tag && json_is_integer(tag) && json_integer_value(tag) >= 0 &&
        json_integer_value(tag) <= 2147483647) {
        s->group_tag = (int)json_integer_value(tag);
        return CF_OK;
    }
    return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be a physical group's name or "
                        "number (a whole number >= 0)", c->name, where);
}

/* What a region's use takes: nothing for fixed (all three components held), force_N for
** loaded, by_mm for displaced (three numbers, null for a component left free). */
static cf_status region_value(ctx *c, json_t *v, const char *key, cf_region_use use,
                              cf_scene_region *r)
{
    cf_status st;
    if (use == CF_REGION_FIXED) {
        r->comps = 7;
    } else if (use == CF_REGION_LOADED) {
        if ((st = cf_scene_vec3(c, v, key, "force_N", r->vec)))
            return st;
    } else {
        /* by_mm: three numbers, null for a component left free */
        json_t *a = json_object_get(v, "by_mm");
        if (!a || !json_is_array(a) || json_array_size(a) != 3)
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.by_mm' must be an array of 3 "
                                "numbers (null for a free component)", c->name, key);
        for (size_t i = 0; i < 3; i++) {
            json_t *e = json_array_get(a, i);
            if (json_is_null(e))
                continue;
            if (!json_is_number(e) || !isfinite(json_number_value(e)) ||
                fabs(json_number_value(e)) > 1e12)
                return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.by_mm' must be an array of 3 "
                                    "finite numbers or null", c->name, key);
            r->vec[i] = json_number_value(e);
            r->comps |= 1u << i;
        }
        if (!r->comps)
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.by_mm' prescribes no component",
                                c->name, key);
    }
    return CF_OK;
}

/* The selector of the region at key: exactly one of below, above, box, sphere and group, the
** only other key allowed being other (NULL: none). */
cf_status cf_scene_selector(ctx *c, json_t *v, const char *key, const char *other, cf_select *s)
{
    static const char *const sel[] = {"below", "above", "box", "sphere", "group"};
    cf_status st = CF_OK;
    if (!json_is_object(v))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object (a region)",
                            c->name, key);
    const char *k;
    json_t *x, *selv = NULL;
    int found = -1;
    json_object_foreach(v, k, x)
    {
        int kind = -1;
        for (int i = 0; i < 5; i++)
            if (strcmp(k, sel[i]) == 0)
                kind = i;
        if (kind >= 0) {
            if (found >= 0)
                return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' has two selectors, '%s' and "
                                    "'%s': a region takes one", c->name, key, sel[found], k);
            found = kind;
            selv = x;
        } else if (!other || strcmp(k, other) != 0)
            return cf_error_set(c->err, CF_E_DATA, "%s: unknown key '%s.%s'", c->name, key, k);
    }
    if (found < 0)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' needs a selector: below, above, box, "
                            "sphere or group", c->name, key);
    char where[96];
    snprintf(where, sizeof where, "%s.%s", key, sel[found]);
    s->kind = (cf_select_kind)found;
    switch (s->kind) {
    case CF_SELECT_BELOW:
    case CF_SELECT_ABOVE:
        st = plane(c, selv, where, s);
        break;
    case CF_SELECT_BOX: {
        static const char *const ok[] = {"min_mm", "max_mm", NULL};
        if (!json_is_object(selv))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, where);
        if ((st = cf_scene_only_keys(c, selv, where, ok)) ||
            (st = cf_scene_vec3(c, selv, where, "min_mm", s->lo_mm)) ||
            (st = cf_scene_vec3(c, selv, where, "max_mm", s->hi_mm)))
            return st;
        for (int a = 0; a < 3; a++)
            if (!(s->hi_mm[a] >= s->lo_mm[a]))
                return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': max_mm[%d] = %g is below "
                                    "min_mm[%d] = %g", c->name, where, a, s->hi_mm[a], a,
                                    s->lo_mm[a]);
        break;
    }
    case CF_SELECT_SPHERE: {
        static const char *const ok[] = {"center_mm", "radius_mm", NULL};
        if (!json_is_object(selv))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, where);
        if ((st = cf_scene_only_keys(c, selv, where, ok)) ||
            (st = cf_scene_vec3(c, selv, where, "center_mm", s->center_mm)) ||
            (st = cf_scene_number(c, selv, where, "radius_mm", 1, 0, 0, 1, 1e12,
                                  &s->radius_mm)))
            return st;
        break;
    }
    default:
        st = group(c, selv, where, s);
        break;
    }
    return st;
}

/* One region at key: exactly one selector (the table below), and the value its use takes. */
static cf_status region(ctx *c, json_t *v, const char *key, cf_region_use use, cf_scene *sc)
{
    static const char *const vkey[] = {NULL, "by_mm", "force_N"};
    cf_status st;
    if (sc->nregions == CF_SCENE_MAX_REGIONS)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': more than %d regions", c->name, key,
                            CF_SCENE_MAX_REGIONS);
    cf_scene_region *r = &sc->regions[sc->nregions];
    memset(r, 0, sizeof *r);
    r->use = use;
    snprintf(r->key, sizeof r->key, "%s", key);
    if (!json_is_object(v))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object (a region) or an "
                            "array of them", c->name, key);
    if ((st = cf_scene_selector(c, v, key, vkey[use], &r->sel)))
        return st;
    if ((st = region_value(c, v, key, use, r)))
        return st;
    sc->nregions++;
    return CF_OK;
}

/* "fixed", "displaced" and "loaded": each a region or an array of regions. */
static cf_status regions_section(ctx *c, json_t *root, cf_scene *sc)
{
    static const char *const uses[] = {"fixed", "displaced", "loaded"};
    cf_status st;
    for (int u = 0; u < 3; u++) {
        json_t *v = json_object_get(root, uses[u]);
        if (!v)
            continue;
        if (!json_is_array(v)) {
            if ((st = region(c, v, uses[u], (cf_region_use)u, sc)))
                return st;
            continue;
        }
        if (json_array_size(v) == 0)
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' is an empty array", c->name,
                                uses[u]);
        for (size_t i = 0; i < json_array_size(v); i++) {
            char key[48];
            snprintf(key, sizeof key, "%s[%zu]", uses[u], i);
            if ((st = region(c, json_array_get(v, i), key, (cf_region_use)u, sc)))
                return st;
        }
    }
    int held = 0;
    for (size_t k = 0; k < sc->nregions; k++)
        held |= sc->regions[k].use != CF_REGION_LOADED;
    if (!held)
        return cf_error_set(c->err, CF_E_DATA, "%s: missing key 'fixed': a body needs a 'fixed' "
                            "or a 'displaced' region to hold it", c->name);
    return CF_OK;
}

/* The probe's drive: exactly one of 'probe.depth_mm' (the travel at the last step) or
** 'probe.force_N' (the force it is pressed to at the last step). */
/* 'probe.path': {"t_s": [t0, t1, ...], "center_mm": [[x, y, z], ...]}, the probe's reference
** point in time (in place of 'center_mm' and of a depth or force). */
static cf_status probe_path(ctx *c, json_t *pa, cf_scene *sc)
{
    static const char *const ok[] = {"t_s", "center_mm", NULL};
    cf_status st;
    if (!json_is_object(pa))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.path' must be an object {\"t_s\": "
                            "[...], \"center_mm\": [[x, y, z], ...]}", c->name);
    if ((st = cf_scene_only_keys(c, pa, "probe.path", ok)))
        return st;
    json_t *t = json_object_get(pa, "t_s"), *x = json_object_get(pa, "center_mm");
    const size_t n = json_is_array(t) ? json_array_size(t) : 0;
    if (n < 2 || n > CF_SCENE_MAX_PATH || !json_is_array(x) || json_array_size(x) != n)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.path': 't_s' and 'center_mm' must "
                            "be arrays of the same length, 2 to %d", c->name, CF_SCENE_MAX_PATH);
    for (size_t i = 0; i < n; i++) {
        json_t *ti = json_array_get(t, i), *xi = json_array_get(x, i);
        if (!json_is_number(ti) || !isfinite(json_number_value(ti)) ||
            fabs(json_number_value(ti)) > 1e12 ||
            (i > 0 && !(json_number_value(ti) > sc->probe_path_t_s[i - 1])))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.path.t_s[%zu]': the times must "
                                "be finite and increasing", c->name, i);
        sc->probe_path_t_s[i] = json_number_value(ti);
        if (!json_is_array(xi) || json_array_size(xi) != 3)
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.path.center_mm[%zu]' must be "
                                "an array of 3 numbers", c->name, i);
        for (size_t a = 0; a < 3; a++) {
            json_t *v = json_array_get(xi, a);
            if (!json_is_number(v) || !isfinite(json_number_value(v)) ||
                fabs(json_number_value(v)) > 1e12)
                return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.path.center_mm[%zu]' must "
                                    "be an array of 3 finite numbers", c->name, i);
            sc->probe_path_mm[i][a] = json_number_value(v);
        }
    }
    sc->probe_npath = n;
    memcpy(sc->probe.center_mm, sc->probe_path_mm[0], sizeof sc->probe.center_mm);
    return CF_OK;
}

static cf_status probe_drive(ctx *c, json_t *pb, cf_scene *sc)
{
    cf_probe *p = &sc->probe;
    json_t *d = json_object_get(pb, "depth_mm"), *f = json_object_get(pb, "force_N");
    json_t *pa = json_object_get(pb, "path");
    if (pa) {
        if (d || f || json_object_get(pb, "center_mm"))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.path' takes the place of "
                                "'probe.center_mm', 'probe.depth_mm' and 'probe.force_N'",
                                c->name);
        return probe_path(c, pa, sc);
    }
    if (d && f)
        return cf_error_set(c->err, CF_E_DATA, "%s: keys 'probe.depth_mm' and 'probe.force_N' "
                            "exclude each other: the probe goes to a depth or to a force",
                            c->name);
    if (f)
        return cf_scene_number(c, pb, "probe", "force_N", 1, 0, 0, 1, 1e12, &p->force_N);
    return cf_scene_number(c, pb, "probe", "depth_mm", 1, 0, 0, 1, 1e12, &p->depth_mm);
}

static int ends_with(const char *s, const char *ext)
{
    size_t n = strlen(s), e = strlen(ext);
    return n > e && strcasecmp(s + n - e, ext) == 0;
}

/* body.mesh's kind: a volume mesh (refine allowed), a closed surface (.obj, .stl) that takes
** body.element_size_mm, or a Gmsh script (.geo), refused: Gmsh's language runs commands, and a
** scene's inputs are data. */
static cf_status mesh_kind(ctx *c, json_t *bd, cf_scene *sc)
{
    const char *m = sc->body_mesh;
    cf_status st;
    if (ends_with(m, ".geo") || ends_with(m, ".geo_unrolled"))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'body.mesh' = '%s': a Gmsh script is a "
                            "program (its System calls run commands) and conifit reads data only: "
                            "mesh it with gmsh -3 and give the .msh, or give its closed surface "
                            "as .stl or .obj with 'body.element_size_mm'", c->name, m);
    const int surface = ends_with(m, ".obj") || ends_with(m, ".stl");
    json_t *h = json_object_get(bd, "element_size_mm");
    if (surface && !h)
        return cf_error_set(c->err, CF_E_DATA, "%s: missing key 'body.element_size_mm': '%s' is a "
                            "surface, filled with tetrahedra of that size", c->name, m);
    if (!surface && h)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'body.element_size_mm' goes with a closed "
                            "surface (.obj, .stl) for 'body.mesh', not '%s'", c->name, m);
    if (surface && sc->body_refine)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'body.refine' goes with a volume mesh; "
                            "give a smaller 'body.element_size_mm'", c->name);
    if (surface && (st = cf_scene_number(c, bd, "body", "element_size_mm", 1, 0, 0, 1, 1e9,
                                         &sc->body_element_size_mm)))
        return st;
    return CF_OK;
}

/* "body", the regions and "probe": a tissue body of a mesh, held, loaded and probed. */
static cf_status body_sections(ctx *c, json_t *root, json_t *bd, cf_scene *sc)
{
    static const char *const bk[] = {"mesh", "unit_mm", "refine", "poisson_ratio",
                                     "volume_modulus_MPa", "steps", "element_size_mm",
                                     "duration_s", "ramp_s", "damping_per_s", "newmark_gamma",
                                     "element_term", NULL};
    static const char *const pk[] = {"shape", "radius_mm", "center_mm", "direction", "depth_mm",
                                     "force_N", "path", "steps", NULL};
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
    if ((st = mesh_kind(c, bd, sc)) ||
        (st = cf_scene_boolean(c, bd, "body", "element_term", &sc->body_element_term)))
        return st;
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
        if ((st = cf_scene_kappa(c, bd, "body", &sc->spring, 0, &sc->body_volume_value)))
            return st;
    }
    if ((st = regions_section(c, root, sc)))
        return st;
    double bsteps;
    json_t *pb;
    if ((st = cf_scene_number(c, bd, "body", "steps", 0, 10, 1, 0, 100000, &bsteps)))
        return st;
    sc->body_steps = (int)bsteps;
    if ((st = cf_scene_object(c, root, "probe", 0, &pb)))
        return st;
    if (!pb) {
        int loads = 0;
        for (size_t k = 0; k < sc->nregions; k++)
            loads |= sc->regions[k].use != CF_REGION_FIXED;
        if (!loads)
            return cf_error_set(c->err, CF_E_DATA, "%s: missing key 'probe': a body needs a probe, "
                                "a 'displaced' or a 'loaded' region", c->name);
        sc->has_body = 1;
        return CF_OK;
    }
    if (json_object_get(bd, "steps"))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'body.steps': with a probe, "
                            "'probe.steps' counts the steps", c->name);
    if ((st = cf_scene_only_keys(c, pb, "probe", pk)))
        return st;
    sc->has_probe = 1;
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
        (st = probe_drive(c, pb, sc)) ||
        (st = cf_scene_number(c, pb, "probe", "steps", 0, 10, 1, 0, 100000, &steps)) ||
        (!sc->probe_npath &&
         (st = cf_scene_vec3(c, pb, "probe", "center_mm", sc->probe.center_mm))) ||
        (st = cf_scene_vec3(c, pb, "probe", "direction", d)))
        return st;
    sc->probe.steps = (int)steps;
    sc->body_steps = (int)steps;
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0) || !isfinite(len))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.direction' = [%g, %g, %g]: must "
                            "not be zero", c->name, d[0], d[1], d[2]);
    for (int k = 0; k < 3; k++)
        sc->probe.dir[k] = d[k] / len;
    sc->has_body = 1;
    return CF_OK;
}

/* The volume term of the fit's lattice as the body's (scene.h). The isotropic lattice
** (calibration.h) and the body (body.h) are both central-spring networks calibrated to the shear
** modulus mu = k0/(2.5 H) with lambda = mu (the Cauchy relation), and both volume terms store
** (kappa/2)(J - 1)^2 per unit volume, which adds kappa to lambda and nothing to mu: the same kappa
** gives the body the lattice's small-strain E and nu, nu = (mu + kappa)/(2 (2 mu + kappa)). A fit
** through a lattice of other weights (its "lattice.weights" not the isotropic ones) has another
** mu and a cubic material, which the body's isotropic network cannot take: refused, with a
** volume term or without (a joint fit's fitted weights). */
cf_status cf_scene_body_fit_volume(cf_scene *sc, const char *name, const char *fit_path,
                                   const struct cf_fitted_spring *fs, cf_error *err)
{
    if (!(fs->volume_modulus_MPa > 0) && cf_fitted_own_weights(fs))
        return cf_error_set(err, CF_E_DATA,
                            "%s: '%s': its springs were fitted in a lattice of fitted weights "
                            "(edge %g, face %g, body %g), a cubic material; a body (an isotropic "
                            "network) takes a fit through the isotropic lattice only",
                            name, fit_path, fs->weight[0], fs->weight[1], fs->weight[2]);
    if (!(fs->volume_modulus_MPa > 0)) {
        if (sc->body_volume == 3) /* a scene's fit replaced by one without a volume term */
            sc->body_volume = 0;
        return CF_OK;
    }
    if (sc->body_volume == 1 || sc->body_volume == 2)
        return cf_error_set(err, CF_E_DATA,
                            "%s: key 'body.%s': '%s' holds its lattice's volume term "
                            "(volume_modulus_MPa = %g), which the body takes; give one or the "
                            "other", name, sc->body_volume == 2 ? "poisson_ratio" : "volume_modulus_MPa",
                            fit_path, fs->volume_modulus_MPa);
    cf_fitted_model m;
    cf_error e = {0};
    double iso[CF_FAMILY_COUNT];
    /* a file that does not record its lattice (an exported spring) is taken at the isotropic
    ** calibration, a lattice scene's default */
    if (cf_fitfile_load_model(fit_path, cf_spring_type_name(fs->type), &m, &e) != CF_OK)
        m.has_weight = 0;
    if (cf_calibration_weights(CF_CAL_ISOTROPIC, iso, &e) != CF_OK)
        return cf_error_set(err, CF_E_INTERNAL, "%s", e.msg);
    for (int f = 0; f < CF_FAMILY_COUNT && m.has_weight; f++)
        if (!(fabs(m.weight[f] - iso[f]) <= 1e-9 * iso[f]))
            return cf_error_set(err, CF_E_DATA,
                                "%s: '%s': its volume term (volume_modulus_MPa = %g) was fitted "
                                "in a lattice of %s weight %g, not the isotropic calibration's "
                                "%g; a body (an isotropic network) takes the volume term of an "
                                "isotropic lattice only",
                                name, fit_path, fs->volume_modulus_MPa, cf_family_name(f),
                                m.weight[f], iso[f]);
    sc->body_volume = 3;
    sc->body_volume_value = fs->volume_modulus_MPa;
    return CF_OK;
}

cf_status cf_scene_body(ctx *c, json_t *root, cf_scene *sc)
{
    cf_status st;
    json_t *bd;
    if ((st = cf_scene_object(c, root, "body", 0, &bd)))
        return st;
    if (!bd && (json_object_get(root, "fixed") || json_object_get(root, "displaced") ||
                json_object_get(root, "loaded") || json_object_get(root, "probe")))
        return cf_error_set(c->err, CF_E_DATA, "%s: keys 'fixed', 'displaced', 'loaded' and "
                            "'probe' need a 'body'", c->name);
    /* a double-acting element (the fit's or 'spring_extension') runs in a body: its edges close
    ** under compression on the spring and under extension on the extension spring; the fit's
    ** volume term (fitted in the isotropic lattice) is the body's, cf_scene_body_fit_volume */
    if (bd && (st = body_sections(c, root, bd, sc)))
        return st;
    return bd && c->from_fit ? cf_scene_body_fit_volume(sc, c->name, sc->fit_path, &c->fit, c->err)
                             : CF_OK;
}

/* The keys of the lattice's effects and integrator that a body does not take, refused by name
** rather than ignored. */
static cf_status body_effects_refused(ctx *c, json_t *root)
{
    static const char *const ef[] = {"damping", "viscosity", "gravity"};
    json_t *e = json_object_get(root, "effects"), *in = json_object_get(root, "integrator");
    for (int k = 0; k < 3 && e; k++)
        if (json_object_get(e, ef[k]))
            return cf_error_set(c->err, CF_E_DATA, "%s: key 'effects.%s': a body takes "
                                "'effects.inertia' only (damping: 'body.damping_per_s')",
                                c->name, ef[k]);
    if (in && json_object_get(in, "substeps"))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'integrator.substeps': a body's dynamic "
                            "run takes 'integrator.dt_s' only", c->name);
    return CF_OK;
}

cf_status cf_scene_body_dynamics(ctx *c, json_t *root, cf_scene *sc)
{
    static const char *const dyn[] = {"duration_s", "ramp_s", "damping_per_s", "newmark_gamma"};
    json_t *bd = json_object_get(root, "body"), *pb = json_object_get(root, "probe");
    json_t *in = json_object_get(root, "integrator");
    cf_status st;
    if ((st = body_effects_refused(c, root)))
        return st;
    sc->body_dynamic = sc->effects.inertia;
    if (sc->has_extension && (sc->body_dynamic || sc->haptic_n))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': a body with a double-acting "
                            "element (an extension spring) runs static steps only (a probe or "
                            "loaded regions); its %s is not built", c->name,
                            sc->haptic_n ? "haptic" : "effects.inertia",
                            sc->haptic_n ? "haptic loop" : "dynamic run");
    if (!sc->body_dynamic) {
        for (int k = 0; k < 4; k++)
            if (json_object_get(bd, dyn[k]))
                return cf_error_set(c->err, CF_E_DATA, "%s: key 'body.%s' goes with a dynamic "
                                    "run ('effects.inertia' = true)", c->name, dyn[k]);
        if (in || json_object_get(root, "density_t_per_mm3"))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' goes with a body's dynamic run "
                                "('effects.inertia' = true)", c->name,
                                in ? "integrator" : "density_t_per_mm3");
        return CF_OK;
    }
    if (sc->haptic_n)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'haptic': the haptic loop solves each "
                            "update as an equilibrium; it does not take 'effects.inertia'",
                            c->name);
    if (json_object_get(bd, "steps") || (pb && json_object_get(pb, "steps")))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.steps': a dynamic run's steps are "
                            "'integrator.dt_s'", c->name, json_object_get(bd, "steps") ? "body"
                                                                                   : "probe");
    if (sc->probe.force_N > 0 || sc->probe_npath)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'probe.%s': a dynamic run drives the "
                            "probe by 'probe.depth_mm'", c->name,
                            sc->probe_npath ? "path" : "force_N");
    if (!in || !json_object_get(in, "dt_s"))
        return cf_error_set(c->err, CF_E_DATA, "%s: missing key 'integrator.dt_s': a body's "
                            "dynamic run needs its time step", c->name);
    if ((st = cf_scene_number(c, bd, "body", "duration_s", 1, 0, 0, 1, 1e9,
                              &sc->body_duration_s)) ||
        (st = cf_scene_number(c, bd, "body", "ramp_s", 0, sc->body_duration_s, 0, 0, 1e9,
                              &sc->body_ramp_s)) ||
        (st = cf_scene_number(c, bd, "body", "damping_per_s", 0, 0, 0, 0, 1e12,
                              &sc->body_damping_per_s)) ||
        (st = cf_scene_number(c, bd, "body", "newmark_gamma", 0, 0.5, 0.5, 0, 1,
                              &sc->body_newmark_gamma)))
        return st;
    const double dt = sc->cfg.dt_s;
    if (!(dt > 0))
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'integrator.dt_s' = %g: must be > 0",
                            c->name, dt);
    const double n = ceil(sc->body_duration_s / dt * (1 - 1e-12));
    if (n > 1e7)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'integrator.dt_s' = %g: %g steps over "
                            "'body.duration_s' = %g s, more than 10^7", c->name, dt, n,
                            sc->body_duration_s);
    sc->body_steps = (int)fmax(n, 1);
    sc->body_dt_s = sc->body_duration_s / sc->body_steps;
    return CF_OK;
}
