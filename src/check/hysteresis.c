/*
** Hysteresis, residual strain and recovery of a scene's run (see hysteresis.h).
*/
#include "check/hysteresis.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/budget.h"
#include "model/lattice.h"

size_t cf_hysteresis_first_unstable(const cf_msm_sample *s, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (s[k].neg_pivots > 0)
            return k;
    return n;
}

double cf_hysteresis_loop_energy(const cf_msm_sample *s, size_t a, size_t b)
{
    double A = 0;
    for (size_t k = a + 1; k <= b; k++)
        A += 0.5 * (s[k].stress_MPa + s[k - 1].stress_MPa) * (s[k].strain - s[k - 1].strain);
    return A * 1e3;
}

cf_hysteresis_cycle cf_hysteresis_cycle_of(const cf_scene *sc, const cf_msm_sample *s, size_t n,
                                           int c)
{
    const size_t per = (n - 1) / (size_t)sc->cycles;
    const size_t a = (size_t)c * per, b = a + per;
    cf_hysteresis_cycle r = {cf_hysteresis_loop_energy(s, a, b), s[b].strain};
    if (sc->drive == CF_DRIVE_FORCE)
        return r;
    /* the unloading branch is the cycle's second half: its first sign change of the stress */
    for (size_t k = a + per / 2; k < b; k++)
        if (s[k].stress_MPa > 0 && s[k + 1].stress_MPa <= 0) {
            const double f = s[k].stress_MPa / (s[k].stress_MPa - s[k + 1].stress_MPa);
            r.zero_strain = s[k].strain + f * (s[k + 1].strain - s[k].strain);
            break;
        }
    return r;
}

/* Whether the recovery test applies to the scene, with its cycle's period *T and its hold. */
static int recovery_plan(const cf_scene *sc, double *T, double *hold)
{
    if (sc->kind != CF_PROTO_CYCLES || sc->drive != CF_DRIVE_DISPLACEMENT || sc->effects.inertia ||
        !(sc->effects.eta_MPa_s > 0 || sc->effects.maxwell_E_MPa > 0) || sc->npath < 3)
        return 0;
    *T = sc->path_t_s[2] - sc->path_t_s[0];
    *hold = 10 * fmax(*T, sc->effects.maxwell_E_MPa > 0 ? sc->effects.maxwell_tau_s : 0);
    return 1;
}

/* The recovery run's samples: 20 over the cycle (the last at zero force), 40 over the hold. */
enum { NCYCLE = 20, NS = 60 };

cf_status cf_hysteresis_recovery_check(const cf_scene *sc, const char *name, const cf_lattice *lat,
                                       const cf_budget *b, cf_scene_cost *c, cf_error *err)
{
    double T, hold;
    if (!recovery_plan(sc, &T, &hold))
        return CF_OK;
    const double dt = sc->cfg.dt_s;
    const double sub = sc->cfg.quasi_substeps > 0 ? sc->cfg.quasi_substeps : 1;
    const double steps = dt > 0 ? (T + hold) / dt + NS : NS * sub;
    const double each = cf_budget_solve_work(3.0 * (double)lat->nn);
    const double can = fmin(b->max_steps - c->steps, (b->max_work - c->work) / each);
    if (steps <= can) {
        c->steps += steps;
        c->work += steps * each;
        return CF_OK;
    }
    const char *key;
    char fits[200];
    const double room = can - NS; /* steps the hold and the cycle may take */
    if (room <= 0) {
        key = "lattice.nx/ny/nz";
        snprintf(fits, sizeof fits, "the run leaves no room for it");
    } else if (dt > 0 && hold > 10 * T && room * dt > 11 * T) {
        key = "effects.viscosity.tau_s";
        snprintf(fits, sizeof fits, "a tau_s of at most %.4g s would fit", (room * dt - T) / 10);
    } else if (dt > 0) {
        key = "integrator.dt_s";
        snprintf(fits, sizeof fits, "a step dt_s of at least %.4g s would fit", (T + hold) / room);
    } else {
        key = "integrator.substeps";
        snprintf(fits, sizeof fits, "at most %.0f substeps would fit", floor(can / NS));
    }
    return cf_error_set(err, CF_E_DATA,
                        "%s: key '%s': the summary's recovery test (zero force held %.4g s) needs "
                        "about %.4g implicit steps, beyond what the run leaves of the step and work "
                        "limits (%.4g steps); %s, or -q leaves out the summary and its test, or "
                        "raise --max-steps and --max-work",
                        name, key, hold, steps, fmax(can, 0), fits);
}

cf_status cf_hysteresis_recovery_test(const cf_scene *sc, const cf_law *law,
                                      const cf_msm_sample *s, size_t n,
                                      cf_hysteresis_recovery *r, cf_error *err)
{
    CF_GSL_GUARD;
    memset(r, 0, sizeof *r);
    double T, hold;
    if (!recovery_plan(sc, &T, &hold))
        return CF_OK;
    double peak = 0;
    for (size_t k = 0; k < n; k++)
        peak = fmax(peak, s[k].stress_MPa);
    double t[4] = {0, T / 2, T, T + hold}, v[4] = {0, peak, 0, 0};
    const cf_msm_path path = {CF_DRIVE_FORCE, 4, t, v};
    double ts[NS];
    cf_msm_sample out[NS];
    for (int k = 0; k < NCYCLE; k++)
        ts[k] = T * (k + 1) / (double)NCYCLE;
    for (int k = NCYCLE; k < NS; k++)
        ts[k] = T + hold * (k - (NCYCLE - 1)) / (double)(NS - NCYCLE);
    cf_lattice lat;
    cf_msm_config cfg = sc->cfg;
    cfg.progress = NULL;
    cf_status st = cf_lattice_create(&lat, law, sc->method, &cfg.lattice, err);
    if (st != CF_OK)
        return st;
    st = cf_msm_run(&lat, &sc->effects, &cfg, &path, ts, NS, out, NULL, NULL, err);
    cf_lattice_free(&lat);
    if (st != CF_OK)
        return st;
    r->ran = 1;
    r->peak_MPa = peak;
    r->hold_s = hold;
    r->zero_strain = out[NCYCLE - 1].strain;
    r->end_strain = out[NS - 1].strain;
    r->recovered = fabs(r->end_strain) <= 1e-3 * fabs(r->zero_strain) + 1e-12;
    return CF_OK;
}
