/*
** Hysteresis, residual strain and recovery of a scene's run (see hysteresis.h).
*/
#include "conifit/hysteresis.h"

#include <math.h>
#include <string.h>

#include "conifit/lattice.h"

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

cf_status cf_hysteresis_recovery_test(const cf_scene *sc, const cf_law *law,
                                      const cf_msm_sample *s, size_t n,
                                      cf_hysteresis_recovery *r, cf_error *err)
{
    memset(r, 0, sizeof *r);
    if (sc->kind != CF_PROTO_CYCLES || sc->drive != CF_DRIVE_DISPLACEMENT || sc->effects.inertia ||
        !(sc->effects.eta_MPa_s > 0 || sc->effects.maxwell_E_MPa > 0) || sc->npath < 3)
        return CF_OK;
    double peak = 0;
    for (size_t k = 0; k < n; k++)
        peak = fmax(peak, s[k].stress_MPa);
    const double T = sc->path_t_s[2] - sc->path_t_s[0];
    const double hold = 10 * fmax(T, sc->effects.maxwell_E_MPa > 0 ? sc->effects.maxwell_tau_s : 0);
    double t[4] = {0, T / 2, T, T + hold}, v[4] = {0, peak, 0, 0};
    const cf_msm_path path = {CF_DRIVE_FORCE, 4, t, v};
    /* 20 samples over the cycle (the last at zero force), 40 over the hold */
    enum { NCYCLE = 20, NS = 60 };
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
