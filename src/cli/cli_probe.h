/*
** A body's probe on the command line beyond the static CSV (cli_body.c): the depth-force plot of
** `simulate --plot` and the haptic loop of `simulate --haptic` (cli_haptic.c).
*/
#ifndef CF_CLI_PROBE_H
#define CF_CLI_PROBE_H

#include <stddef.h>

#include "base/atomic.h"
#include "model/body.h"
#include "io/budget.h"
#include "io/scene.h"

/* Draws the probe's force against depth of the n steps (cf_plot_probe) to png as a temporary left
** in *out for the caller to commit with its other outputs. Errors as cf_plot_probe. */
cf_status cf_cli_probe_plot(const cf_scene *sc, const cf_body_step *step, size_t n,
                            const char *png, const char *const *inputs, cf_atomic *out,
                            cf_error *err);

/* `simulate --haptic`: runs sc's body (sc->has_body) along its "haptic" path, one update of
** cf_body_haptic_step per ms, writes out (t_ms,depth_mm,force_N; "-" for standard output) and,
** when png is not NULL, the force against time; the summary (unless quiet) gives the wall time
** per update and the static solve's force at the path's last depth. Returns the exit status:
** 65 for a scene without "haptic", a path over the budget or the static run's bad input. */
int cf_cli_simulate_haptic(const cf_scene *sc, const char *scene_path, const char *out,
                           const char *png, const cf_budget *budget, int quiet);

#endif
