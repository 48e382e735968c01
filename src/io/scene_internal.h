/*
** What the files that read scenes share (scene.c: the spring, the lattice, the effects and the
** protocol; scene_keys.c: the checked reading of keys; scene_body.c: a tissue body's "body",
** "fixed" and "probe"). Private to the io layer.
*/
#ifndef CF_IO_SCENE_INTERNAL_H
#define CF_IO_SCENE_INTERNAL_H

#include <jansson.h>

#include "io/fitfile.h"
#include "io/scene.h"

typedef struct ctx {
    const char *name;
    cf_error *err;
    cf_fitted_spring fit;  /* the spring's fit file, when it names one (its Prony terms) */
    int from_fit;
} ctx;

/* scene_keys.c: every message names the file (c->name) and the key, 'where.key'. */
/* Refuses keys of obj that are not in the NULL-terminated list. */
cf_status cf_scene_only_keys(ctx *c, json_t *obj, const char *where, const char *const *allowed);
/* A number at obj[key]: required or default; checked finite and within [lo, hi] (or (lo, hi]
** with open_lo). */
cf_status cf_scene_number(ctx *c, json_t *obj, const char *where, const char *key, int required,
                          double dflt, double lo, int open_lo, double hi, double *out);
/* A volume modulus at obj["volume_modulus_MPa"] (dflt when absent): >= 0, at most
** CF_KAPPA_MAX_MPA and, when the key is given, at most CF_KAPPA_MAX_RATIO times spring's k0/H
** (model/calibration.h), the message saying why. */
cf_status cf_scene_kappa(ctx *c, json_t *obj, const char *where, const cf_spring *spring,
                         double dflt, double *out);
/* A boolean at obj[key] (false when absent). */
cf_status cf_scene_boolean(ctx *c, json_t *obj, const char *where, const char *key, int *out);
/* An object at root[key] (NULL when absent and not required). */
cf_status cf_scene_object(ctx *c, json_t *root, const char *key, int required, json_t **out);
/* A JSON array of three finite numbers at obj[key] into v. */
cf_status cf_scene_vec3(ctx *c, json_t *obj, const char *where, const char *key, double v[3]);

/* scene_body.c: "body", "fixed" and "probe" of root (nothing when root has no "body"; "fixed" or
** "probe" without it refused). */
cf_status cf_scene_body(ctx *c, json_t *root, cf_scene *sc);
/* A body's dynamic run: 'effects.inertia', 'density_t_per_mm3', 'integrator.dt_s' and
** 'body.duration_s', 'body.ramp_s', 'body.damping_per_s' (after the effects and the integrator
** are read); the lattice's other effects refused for a body. */
cf_status cf_scene_body_dynamics(ctx *c, json_t *root, cf_scene *sc);

/* The selector of the region at key of a body's scene: exactly one of below, above, box, sphere
** and group, the only other key allowed being other (NULL: none). */
cf_status cf_scene_selector(ctx *c, json_t *v, const char *key, const char *other, cf_select *s);

/* scene_groups.c: "groups" of root, a law per spring family of a lattice (after the lattice's
** weights are read) or per region of a body: unknown families, a family named twice or of weight
** 0, a double-acting element refused (a body's empty or overlapping regions are the body's to
** find, cf_body_set_groups). */
cf_status cf_scene_groups(ctx *c, json_t *root, cf_scene *sc);
/* The spring of a group entry at where: {"fit": file, "type"} (a plain conical or tailed spring's
** fit) or {"params": {...}}, into g->spring and g->source. */
cf_status cf_scene_group_spring(ctx *c, json_t *sp, const char *where, cf_scene_group *g);

/* scene_body_fibres.c: a body's "fibres" of root (after "body"; refused without one): each entry's
** helix rule, spring and density. */
cf_status cf_scene_body_fibres(ctx *c, json_t *root, cf_scene *sc);

#endif
