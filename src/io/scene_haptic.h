/*
** The scene's "haptic" section (scene_types.h, src/notes/simulate.md, "Bodies"): the probe's
** path in time for `simulate --haptic`. Private to the io module.
*/
#ifndef CF_IO_SCENE_HAPTIC_H
#define CF_IO_SCENE_HAPTIC_H

#include <jansson.h>

#include "conifit/error.h"
#include "io/scene_types.h"

/* Most updates (milliseconds of simulated time) a haptic path may ask for; the run is further
** bounded by the budget's steps (budget.h). */
#define CF_HAPTIC_MAX_MS 1e7

/* Reads h, the value of the key "haptic": {"path": [[t_ms, depth_mm], ...], "iterations": N}, into
** sc (haptic_n, haptic_t_ms, haptic_depth_mm, allocated here; haptic_iterations). `name` is the
** scene's name in messages. CF_E_DATA naming the key and the value, CF_E_INTERNAL out of memory. */
cf_status cf_scene_haptic_parse(json_t *h, const char *name, cf_scene *sc, cf_error *err);

#endif
