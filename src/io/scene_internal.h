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
/* The lattice's family weights into L: exactly one of 'weights' {edge, face, body},
** 'calibration' (isotropic, axial) or the shorthands 'diagonals' / 'diagonal_weight'; none:
** isotropic, or the fitted weights of the joint fit the scene's spring names. */
cf_status cf_scene_weights(ctx *c, json_t *lt, cf_lattice_config *L);
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
/* The spring of a group's entry at where (e.g. 'groups[i].spring'): {"fit": file} (a plain
** conical or tailed spring's fit, "type" optional) or {"params": {...}}, into g->spring and
** g->source; a double-acting fit refused. */
cf_status cf_scene_group_spring(ctx *c, json_t *sp, const char *where, cf_scene_group *g);

/* scene_fibres.c: one fibre group's entry e at where ({"axis": [ax, ay, az], "spring": as a
** group's, "density": springs per cell}) into *f: the axis finite and not zero (normalised), the
** density finite in (0, 1e6], the spring a valid law; every refusal names the key and the value.
** The lattice's "fibres" (a body's entries take a helix rule instead: scene_body_fibres.c). */
cf_status cf_scene_fibre_entry(ctx *c, json_t *e, const char *where, cf_scene_fibre *f);
/* scene_groups.c: the "spring" of fibre entry e at where (required; as a group's,
** cf_scene_group_spring, and a valid law) into *spring and source (600 bytes). Shared by the
** lattice's and a body's entries. */
cf_status cf_scene_fibre_spring(ctx *c, json_t *e, const char *where, cf_spring *spring,
                                char source[600]);
/* "fibres": {"fit": FILE, "cross_axis": "s" | "n"} of root (before the spring; nothing, and
** sc->fibre_fit 0, when "fibres" is not an object): the fit file's fibre lattice of that cross
** axis (cf_fitfile_load_fibre) gives the scene's spring (its matrix's canonical member) and its
** fibre groups (density 1, along x, y, z for f, s, n); "spring" or "spring_extension" beside it
** refused. */
cf_status cf_scene_fibre_fit(ctx *c, json_t *root, cf_scene *sc);
/* "fibres" of a scene's root (after "groups"; a body's go to cf_scene_body_fibres): a lattice's
** 1 to CF_FIBRE_MAX entries; after a fibre
** fit (cf_scene_fibre_fit) the lattice's weights and kappa, the fit's (the lattice's own weight
** and volume keys refused beside it). */
cf_status cf_scene_fibres(ctx *c, json_t *root, cf_scene *sc);

/* scene_body_fibres.c: a body's "fibres" of root (after "body"; refused without one): each entry's
** helix rule, spring and density. */
cf_status cf_scene_body_fibres(ctx *c, json_t *root, cf_scene *sc);

#endif
