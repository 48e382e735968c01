/*
** A lattice scene's spring groups (scene_internal.h, "groups"; src/notes/simulate.md, "Spring
** groups"): each entry names a family of the lattice's springs and the spring whose law it takes.
*/
#include "io/scene.h"

#include <math.h>
#include <string.h>

#include "base/safetext.h"
#include "io/scene_internal.h"

static const char *const family_names[CF_FAMILY_COUNT] = {"edge", "face", "body"};

cf_status cf_scene_group_spring(ctx *c, json_t *sp, const char *where, cf_scene_group *g)
{
    static const char *const allowed[] = {"fit", "type", "params", NULL};
    const char *pkeys[CF_P_ALL + 1];
    for (int k = 0; k < CF_P_ALL; k++)
        pkeys[k] = cf_spring_param_info(k)->key;
    pkeys[CF_P_ALL] = NULL;
    cf_status st;
    if (!json_is_object(sp))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, where);
    if ((st = cf_scene_only_keys(c, sp, where, allowed)))
        return st;
    json_t *fit = json_object_get(sp, "fit"), *params = json_object_get(sp, "params");
    json_t *type = json_object_get(sp, "type");
    if ((fit != NULL) == (params != NULL))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' needs exactly one of 'fit' or 'params'",
                            c->name, where);
    if (type && (!fit || !json_is_string(type)))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key '%s.type' must be a string and goes only with 'fit'", c->name,
                            where);
    if (fit) {
        if (!json_is_string(fit))
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s.fit' must be a file name", c->name,
                                where);
        const char *tn = type ? json_string_value(type) : NULL;
        cf_fitted_spring fs;
        cf_error ferr = {0};
        if ((st = cf_fitfile_load_element(json_string_value(fit), tn, &fs, &ferr)))
            return cf_error_set(c->err, st, "%s: key '%s.fit': %s", c->name, where, ferr.msg);
        if (fs.has_extension)
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key '%s.fit' = '%s': a double-acting element; a group takes "
                                "a single spring's law",
                                c->name, where, json_string_value(fit));
        g->spring = fs.params;
        char named[sizeof g->source];
        snprintf(named, sizeof named, "%s:%s", json_string_value(fit), cf_spring_type_name(fs.type));
        cf_safe_text(g->source, sizeof g->source, named, strlen(named));
        return CF_OK;
    }
    char pw[96];
    snprintf(pw, sizeof pw, "%s.params", where);
    if (!json_is_object(params))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, pw);
    if ((st = cf_scene_only_keys(c, params, pw, pkeys)))
        return st;
    for (int k = 0; k < CF_P_ALL; k++) {
        double v;
        const int cone = k < CF_P_COUNT;
        if ((st = cf_scene_number(c, params, pw, pkeys[k], cone, 0, 0, cone, INFINITY, &v)))
            return st;
        cf_spring_set(&g->spring, k, v);
    }
    snprintf(g->source, sizeof g->source, "params");
    return CF_OK;
}

/* The family of lattice group entry e at where (unknown, repeated or empty refused) into *f. */
static cf_status group_family(ctx *c, json_t *e, const char *where, const cf_scene *sc, int *f)
{
    json_t *fam = json_object_get(e, "springs");
    if (!json_is_string(fam))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key '%s.springs' must be one of \"edge\", \"face\", \"body\"",
                            c->name, where);
    *f = -1;
    for (int k = 0; k < CF_FAMILY_COUNT; k++)
        if (strcmp(json_string_value(fam), family_names[k]) == 0)
            *f = k;
    char safe[64];
    cf_safe_text(safe, sizeof safe, json_string_value(fam), strlen(json_string_value(fam)));
    if (*f < 0)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key '%s.springs' = '%s': unknown group; a lattice's groups are "
                            "edge, face and body",
                            c->name, where, safe);
    for (size_t k = 0; k < sc->ngroups; k++)
        if (sc->groups[k].family == *f)
            return cf_error_set(c->err, CF_E_DATA,
                                "%s: key '%s.springs' = '%s': that group is already groups[%zu] "
                                "(a spring takes one group's law)",
                                c->name, where, safe, k);
    if (!(sc->cfg.lattice.weight[*f] > 0))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key '%s.springs' = '%s': the group is empty (the lattice's '%s' "
                            "weight is 0)",
                            c->name, where, safe, safe);
    return CF_OK;
}

/* Entry i of "groups": a lattice's family ("springs") or a body's region ("region"), and its
** spring (a law of the scene spring's free length). */
static cf_status group_entry(ctx *c, json_t *e, size_t i, cf_scene *sc)
{
    static const char *const lattice_keys[] = {"springs", "spring", NULL};
    static const char *const body_keys[] = {"region", "spring", NULL};
    char where[48];
    snprintf(where, sizeof where, "groups[%zu]", i);
    cf_status st;
    if (!json_is_object(e))
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' must be an object", c->name, where);
    if ((st = cf_scene_only_keys(c, e, where, sc->has_body ? body_keys : lattice_keys)))
        return st;
    cf_scene_group *g = &sc->groups[sc->ngroups];
    memset(g, 0, sizeof *g);
    g->family = -1;
    if (sc->has_body) {
        char rw[64];
        snprintf(rw, sizeof rw, "%s.region", where);
        json_t *r = json_object_get(e, "region");
        if (!r)
            return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' is required (a body's group is "
                                "the springs with both ends in a region)", c->name, rw);
        if ((st = cf_scene_selector(c, r, rw, NULL, &g->sel)))
            return st;
    } else if ((st = group_family(c, e, where, sc, &g->family)))
        return st;
    char sw[64];
    snprintf(sw, sizeof sw, "%s.spring", where);
    json_t *sp = json_object_get(e, "spring");
    if (!sp)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' is required", c->name, sw);
    if ((st = cf_scene_group_spring(c, sp, sw, g)))
        return st;
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init(&law, &g->spring, &lerr) != CF_OK)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': %s", c->name, sw, lerr.msg);
    cf_law_free(&law);
    if (!(fabs(g->spring.H_mm - sc->spring.H_mm) <= CF_GROUP_H_REL * sc->spring.H_mm))
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key '%s': free length H = %.10g mm; every group has the scene "
                            "spring's H = %.10g mm (its springs are calibrated with it)",
                            c->name, sw, g->spring.H_mm, sc->spring.H_mm);
    sc->ngroups++;
    return CF_OK;
}

cf_status cf_scene_groups(ctx *c, json_t *root, cf_scene *sc)
{
    json_t *gs = json_object_get(root, "groups");
    sc->ngroups = 0;
    if (!gs)
        return CF_OK;
    if (sc->has_extension)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'groups': the scene's element is double-acting; groups take "
                            "single springs' laws and do not combine with it",
                            c->name);
    if (!json_is_array(gs) || json_array_size(gs) == 0)
        return cf_error_set(c->err, CF_E_DATA,
                            "%s: key 'groups' must be a non-empty array of {\"springs\" (a "
                            "lattice) or \"region\" (a body), \"spring\"} objects",
                            c->name);
    const size_t most = sc->has_body ? CF_SCENE_MAX_GROUPS : CF_FAMILY_COUNT;
    if (json_array_size(gs) > most)
        return cf_error_set(c->err, CF_E_DATA, "%s: key 'groups' has %zu entries: a %s has at most %zu",
                            c->name, json_array_size(gs), sc->has_body ? "body" : "lattice", most);
    for (size_t i = 0; i < json_array_size(gs); i++) {
        cf_status st = group_entry(c, json_array_get(gs, i), i, sc);
        if (st)
            return st;
    }
    return CF_OK;
}

cf_status cf_scene_group_laws(const cf_scene *sc, cf_law group[CF_FAMILY_COUNT],
                              cf_lattice_config *cfg, cf_error *err)
{
    memset(group, 0, CF_FAMILY_COUNT * sizeof *group);
    for (size_t k = 0; k < sc->ngroups && !sc->has_body; k++) {
        cf_law *l = &group[sc->groups[k].family];
        cf_status st = cf_law_init(l, &sc->groups[k].spring, err);
        if (st == CF_OK && sc->method == CF_LAW_TABLE)
            st = cf_law_table_build(l, sc->table_intervals, err);
        if (st != CF_OK)
            return st;
        cfg->group_law[sc->groups[k].family] = l;
    }
    return CF_OK;
}

const char *cf_scene_group_name(int family)
{
    return family >= 0 && family < CF_FAMILY_COUNT ? family_names[family] : "?";
}

cf_status cf_scene_fibre_spring(ctx *c, json_t *e, const char *where, cf_spring *spring,
                                char source[600])
{
    char sw[96];
    snprintf(sw, sizeof sw, "%s.spring", where);
    json_t *sp = json_object_get(e, "spring");
    if (!sp)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s' is required", c->name, sw);
    cf_scene_group g;
    memset(&g, 0, sizeof g);
    cf_status st = cf_scene_group_spring(c, sp, sw, &g);
    if (st)
        return st;
    cf_law law;
    cf_error lerr = {0};
    if (cf_law_init(&law, &g.spring, &lerr) != CF_OK)
        return cf_error_set(c->err, CF_E_DATA, "%s: key '%s': %s", c->name, sw, lerr.msg);
    cf_law_free(&law);
    *spring = g.spring;
    memcpy(source, g.source, 600);
    return CF_OK;
}
