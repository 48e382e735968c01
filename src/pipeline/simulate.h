/*
** Running a lattice scene as one library call (simulate.c): the scene's law and lattice, its
** budget checked before anything runs, the run, and the law's own curve beside it. Used by
** `conifit simulate` and by the flat call cf_flat_simulate alike.
*/
#ifndef CF_PIPELINE_SIMULATE_H
#define CF_PIPELINE_SIMULATE_H

#include <stddef.h>

#include "io/budget.h"
#include "model/msm.h"
#include "io/scene.h"

typedef struct cf_sim_run {
    cf_law law, ext;          /* the scene's law (and a double-acting element's extension) */
    cf_law group[CF_FAMILY_COUNT]; /* the laws of the scene's spring groups (zeroed where the
                                 ** group takes the scene's law) */
    cf_law fibre_law[CF_FIBRE_MAX]; /* the laws of the scene's fibre groups (zeroed beyond) */
    cf_fibre_group fibre[CF_FIBRE_MAX]; /* those groups, the lattice's cfg.fibre */
    cf_lattice lat;           /* the lattice run */
    cf_msm_sample *samples;   /* one per scene sample */
    double *spring_MPa;       /* the law's own uniaxial stress at each sample's strain, MPa */
    size_t count;
    cf_msm_stats stats;
} cf_sim_run;

/* Runs lattice scene sc (named name in messages) within budget: its size and step limits (and,
** with recovery, the recovery test's) checked before the run (CF_E_DATA naming the key), the
** scene's progress callback called during it (a scene with a body: CF_E_USAGE, the command runs
** those). On CF_OK *run holds the samples; free it with
** cf_sim_run_free whatever the status. */
cf_status cf_pipeline_simulate(const cf_scene *sc, const char *name, const cf_budget *budget,
                               int recovery, cf_sim_run *run, cf_error *err);
void cf_sim_run_free(cf_sim_run *run);

#endif
