/*
** A lattice scene run as one call (simulate.h).
*/
#include "pipeline/simulate.h"
#include "base/gslguard.h"

#include <stdlib.h>
#include <string.h>

#include "check/hysteresis.h"

/* The run of scene sc (its groups' laws already in sc->cfg.lattice). */
static cf_status simulate_run(const cf_scene *sc, const char *name, const cf_budget *budget,
                              int recovery, cf_sim_run *run, cf_error *err)
{
    cf_scene_cost cost;
    cf_status s;
    if ((s = cf_budget_check_size(sc, name, budget, &cost, err)) != CF_OK ||
        (s = cf_lattice_create(&run->lat, &run->law, sc->method, &sc->cfg.lattice, err)) != CF_OK ||
        (s = cf_budget_check_steps(sc, name, &run->lat, budget, &cost, err)) != CF_OK ||
        (recovery &&
         (s = cf_hysteresis_recovery_check(sc, name, &run->lat, budget, &cost, err)) != CF_OK))
        return s;
    const size_t n = sc->nsamples;
    run->samples = calloc(n ? n : 1, sizeof *run->samples);
    run->spring_MPa = malloc((n ? n : 1) * sizeof *run->spring_MPa);
    if (!run->samples || !run->spring_MPa)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu samples", n);
    cf_msm_path path = cf_scene_path(sc);
    size_t done = 0;
    if ((s = cf_msm_run(&run->lat, &sc->effects, &sc->cfg, &path, sc->sample_t_s, n, run->samples,
                        &done, &run->stats, err)) != CF_OK)
        return s;
    run->count = n;
    const double H = run->law.p.H_mm;
    for (size_t k = 0; k < n; k++)
        run->spring_MPa[k] =
            cf_law_force(&run->law, sc->method, run->samples[k].strain * H, NULL, NULL) / (H * H);
    return CF_OK;
}

cf_status cf_pipeline_simulate(const cf_scene *sc, const char *name, const cf_budget *budget,
                               int recovery, cf_sim_run *run, cf_error *err)
{
    CF_GSL_GUARD;
    memset(run, 0, sizeof *run);
    cf_status s;
    if (sc->has_body) /* a body's run (static probe, dynamics, haptics) is the command's */
        return cf_error_set(err, CF_E_USAGE,
                            "%s: the scene has a tissue body (key 'body'); this call runs lattice "
                            "scenes only: run a body with conifit simulate",
                            name);
    if ((s = cf_scene_law(sc, &run->law, &run->ext, err)) != CF_OK)
        return s;
    if (sc->ngroups == 0 && sc->nfibres == 0)
        return simulate_run(sc, name, budget, recovery, run, err);
    /* spring and fibre groups: the scene with their laws in the lattice's configuration */
    cf_scene *g = malloc(sizeof *g);
    if (!g)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the scene's groups");
    *g = *sc;
    if ((s = cf_scene_group_laws(sc, run->group, &g->cfg.lattice, err)) == CF_OK &&
        (s = cf_scene_fibre_laws(sc, run->fibre_law, run->fibre, &g->cfg.lattice, err)) == CF_OK)
        s = simulate_run(g, name, budget, recovery, run, err);
    free(g);
    return s;
}

void cf_sim_run_free(cf_sim_run *run)
{
    cf_lattice_free(&run->lat);
    cf_law_free(&run->law);
    cf_law_free(&run->ext);
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        cf_law_free(&run->group[f]);
    for (int f = 0; f < CF_FIBRE_MAX; f++)
        cf_law_free(&run->fibre_law[f]);
    free(run->samples);
    free(run->spring_MPa);
    memset(run, 0, sizeof *run);
}
