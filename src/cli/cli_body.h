/*
** `simulate` on a scene with a tissue body (body.h): the probe pressed into the body step by step,
** the depth-force CSV, the ParaView files and the summary.
*/
#ifndef CF_CLI_BODY_H
#define CF_CLI_BODY_H

#include "conifit/budget.h"
#include "conifit/scene.h"

/* Runs sc (sc->has_body) and writes out (CSV, "-" for standard output) and, when vtu_dir is not
** NULL, vtu_dir/body_NNNN.vtu, springs_NNNN.vtu and body.pvd. Returns the exit status. */
int cf_cli_simulate_body(const cf_scene *sc, const char *scene_path, const char *out,
                         const char *vtu_dir, const cf_budget *budget, int quiet);

#endif
