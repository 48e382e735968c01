/*
** Scenes: a JSON file that says which spring, which lattice, which boundary conditions, which
** loading protocol and which time-dependent effects a simulation uses (schema in
** src/notes/simulate.md, section "Scenes"). Loading validates everything before anything is
** simulated: an unknown key, a missing field, an impossible value or a missing fit file is refused
** with a message that names the key and the value.
*/
#ifndef CF_SCENE_H
#define CF_SCENE_H

#include <stddef.h>

#include "conifit/error.h"
#include "io/scene_types.h"
#include "model/law_internal.h"
#include "model/msm.h"

/* Most samples a scene may report (segments x samples_per_segment + 1); the memory and steps of
** a scene are further bounded by its budget (budget.h). */
#define CF_SCENE_MAX_SAMPLES 10000000

/* Reads and validates the scene at path. CF_E_NOINPUT when it (or its fit file) cannot be read,
** CF_E_DATA for anything invalid; the message names the file, the key and the value. */
cf_status cf_scene_load(const char *path, cf_scene *sc, cf_error *err);

/* The same from JSON text; `name` is used in messages. */
cf_status cf_scene_parse(const char *json_text, const char *name, cf_scene *sc, cf_error *err);

/* The law of the scene's springs into *law (with its table for the table method) and, with
** 'spring_extension', the extension spring into *ext joined to it (law->extension = ext: ext must
** outlive law's use). Release both with cf_law_free. CF_E_DATA / CF_E_INTERNAL as cf_law_init and
** cf_law_table_build. */
cf_status cf_scene_law(const cf_scene *sc, cf_law *law, cf_law *ext, cf_error *err);

/* The laws of the scene's spring groups (scene_groups.c) into group[family] (each with its table
** for the table method; the others zeroed) and cfg->group_law pointed at them: group must outlive
** cfg's use. Release each with cf_law_free (safe on the zeroed ones), whatever the status. */
cf_status cf_scene_group_laws(const cf_scene *sc, cf_law group[CF_FAMILY_COUNT],
                              cf_lattice_config *cfg, cf_error *err);

/* The laws of the scene's fibre groups ("fibres", scene_fibres.c) into law[k] (each with its table
** for the table method), the groups into grp[k] and cfg->fibre, cfg->nfibre pointed at them: law
** and grp must outlive cfg's use. Release each law with cf_law_free (law[] is zeroed first, so
** that is safe whatever the status). */
cf_status cf_scene_fibre_laws(const cf_scene *sc, cf_law law[CF_FIBRE_MAX],
                              cf_fibre_group grp[CF_FIBRE_MAX], cf_lattice_config *cfg,
                              cf_error *err);
/* A lattice group's name in scenes and reports: "edge", "face" or "body" (CF_FAMILY_*). */
const char *cf_scene_group_name(int family);

/* Releases the arrays of sc. Safe on a zeroed scene. */
void cf_scene_free(cf_scene *sc);

/* A body scene's volume term from the fit at fit_path (fs as cf_fitfile_load_element read it):
** its lattice's kappa > 0 becomes the body's (body_volume 3; the isotropic lattice and the body
** share mu and lambda = mu + kappa, scene_body.c), refused with CF_E_DATA beside the scene's own
** 'body.poisson_ratio' or 'body.volume_modulus_MPa' and for a lattice of other than the isotropic
** weights; a fit without one leaves the scene's own (and drops an earlier fit's). name: the
** scene's, for messages. */
struct cf_fitted_spring;
cf_status cf_scene_body_fit_volume(cf_scene *sc, const char *name, const char *fit_path,
                                   const struct cf_fitted_spring *fs, cf_error *err);

/* The loading path of the scene, for cf_msm_run. */
cf_msm_path cf_scene_path(const cf_scene *sc);

#endif
