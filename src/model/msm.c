/*
** Solvers for the mass-spring lattice (see msm.h): the defaults, the loading path and the runner,
** which reaches each sample by static equilibria (msm_newton.c), implicit viscous steps
** (msm_visco.c) or explicit dynamics (msm_dynamic.c). The uniaxial curve and its stability are in
** msm_uniaxial.c, the tangent in msm_tangent.c, which hands it to the linear solver (linsolve.h).
*/
#include "model/msm_internal.h"
#include "base/gslguard.h"

#include <math.h>
#include <string.h>

cf_msm_config cf_msm_default(void)
{
    cf_msm_config c;
    c.lattice = cf_lattice_default();
    c.newton_rtol = 1e-11;
    c.newton_max_iter = 50;
    c.dt_s = 0;
    c.quasi_substeps = 10;
    c.banded_only = 0;
    c.progress = NULL;
    c.progress_ctx = NULL;
    return c;
}


/* ---- runner ---------------------------------------------------------------------------------- */

static cf_status check_path(const cf_msm_path *p, const double *ts, size_t ns, cf_error *err)
{
    if (p->count < 1 || !p->t_s || !p->value)
        return cf_error_set(err, CF_E_DATA, "loading path is empty");
    for (size_t i = 0; i < p->count; i++) {
        if (!isfinite(p->t_s[i]) || !isfinite(p->value[i]))
            return cf_error_set(err, CF_E_DATA, "loading path point %zu is not finite", i);
        if (i > 0 && !(p->t_s[i] >= p->t_s[i - 1]))
            return cf_error_set(err, CF_E_DATA,
                                "loading path time %.6g s at point %zu goes backwards", p->t_s[i],
                                i);
    }
    for (size_t k = 0; k < ns; k++)
        if (!isfinite(ts[k]) || (k > 0 && ts[k] < ts[k - 1]))
            return cf_error_set(err, CF_E_DATA, "sample time %zu = %g is not increasing", k,
                                ts[k]);
    return CF_OK;
}

/* The run's effects and path are ones it can follow: CF_E_DATA naming what is not. */
static cf_status check_run(const cf_msm_effects *fx, const cf_msm_path *path,
                           const double *sample_t_s, size_t nsamples, cf_error *err)
{
    cf_status rc = check_path(path, sample_t_s, nsamples, err);
    if (rc != CF_OK)
        return rc;
    if (fx->maxwell_E_MPa > 0 && !(fx->maxwell_tau_s > 0 && isfinite(fx->maxwell_tau_s)))
        return cf_error_set(err, CF_E_DATA, "maxwell tau_s = %g: must be finite and > 0",
                            fx->maxwell_tau_s);
    if ((rc = cf_msm_prony_check(fx, err)) != CF_OK)
        return rc;
    if (fx->prony_count > 0 && fx->inertia)
        return cf_error_set(err, CF_E_DATA, "Prony terms are solved quasi-statically: they do not "
                            "combine with inertia");
    return CF_OK;
}

/* From time t to sample k at tk, drive value vk: a static equilibrium, implicit quasi-static
** steps, or explicit steps, as the effects ask. */
static cf_status advance_to(solver *s, dyn *d, const cf_msm_path *path, double t, double tk,
                            double vk, size_t k, cf_msm_stats *st, cf_error *err)
{
    const cf_msm_effects *fx = s->fx;
    const int timed = fx->inertia || fx->eta_MPa_s > 0 || fx->maxwell_E_MPa > 0 ||
                      fx->prony_count > 0;
    if (!timed)
        return cf_msm_static_to(s, vk, err);
    if (fx->inertia)
        return tk > t ? cf_msm_explicit_interval(s, d, path, t, tk, st, err) : CF_OK;
    if (tk > t) {
        int n = s->cfg->quasi_substeps > 0 ? s->cfg->quasi_substeps : 1;
        if (s->cfg->dt_s > 0)
            n = (int)fmin(1e9, ceil((tk - t) / s->cfg->dt_s - 1e-9));
        return cf_msm_quasi_advance(s, path, t, tk, n > 0 ? n : 1, 0, err);
    }
    if (k > 0)
        return CF_OK;
    /* The state at the first sample is at rest: the Maxwell and Prony branches are relaxed, so
    ** the springs carry g_inf times the law. */
    if (fx->prony_count > 0) {
        double gsum = 0;
        for (int i = 0; i < fx->prony_count; i++)
            gsum += fx->prony_g[i];
        double ksum = 0;
        for (int i = 0; i < fx->prony_count; i++)
            ksum += fx->prony_k[i];
        s->qlv_scale = -gsum;
        s->qlv_slope = -ksum;
        s->extras = 1;
    }
    cf_status rc = cf_msm_static_to(s, vk, err);
    return rc == CF_OK ? cf_msm_relaxed_share_check(s, err) : rc;
}

/* The compressive stress at the top of the current state (drive value vk). */
static double sample_stress(solver *s, dyn *d, const cf_msm_path *path, double vk)
{
    cf_lattice *lat = s->lat;
    const cf_msm_effects *fx = s->fx;
    if (fx->inertia && (fx->eta_MPa_s > 0 || s->sigm) && path->drive == CF_DRIVE_DISPLACEMENT) {
        /* Reaction including the dashpots at the current velocities. */
        cf_lattice_forces(lat);
        double H2 = lat->H_mm * lat->H_mm;
        for (size_t q = 0; q < lat->ns; q++) {
            uint32_t i = lat->si[q], j = lat->sj[q];
            d->Ld[q] = ((lat->x[j] - lat->x[i]) * (d->vx[j] - d->vx[i]) +
                        (lat->y[j] - lat->y[i]) * (d->vy[j] - d->vy[i]) +
                        (lat->z[j] - lat->z[i]) * (d->vz[j] - d->vz[i])) /
                       lat->L_mm[q];
            d->Tt[q] = lat->w[q] * H2 * fx->eta_MPa_s / lat->L0_mm[q] * d->Ld[q] +
                       (s->sigm ? lat->w[q] * H2 * s->sigm[q] : 0.0);
        }
        cf_lattice_add_tensions(lat, d->Tt);
        cf_msm_add_external(s);
        return path->drive == CF_DRIVE_FORCE ? vk : cf_msm_top_stress(lat);
    }
    if (s->extras) {
        /* Quasi-static: the reaction of the last step includes its viscous forces. */
        double rn, fsc;
        cf_msm_residual(s, &rn, &fsc);
        return path->drive == CF_DRIVE_FORCE ? vk : cf_msm_top_stress(lat);
    }
    return cf_msm_reported_stress(s);
}

/* The run is one time loop: each sample is reached (advance_to), reported (sample_stress) and
** checked finite; the solver is set up once for the effects asked for. */
cf_status cf_msm_run(cf_lattice *lat, const cf_msm_effects *fxin, const cf_msm_config *cfg,
                     const cf_msm_path *path, const double *sample_t_s, size_t nsamples,
                     cf_msm_sample *out, size_t *done, cf_msm_stats *stats, cf_error *err)
{
    CF_GSL_GUARD;
    cf_msm_effects none = {0};
    const cf_msm_effects *fx = fxin ? fxin : &none;
    cf_msm_stats local = {0};
    cf_msm_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    if (done)
        *done = 0;
    if (lat->cfg.nfibre > 0 && fx->inertia)
        return cf_error_set(err, CF_E_DATA, "a lattice with %d fibre group%s: explicit dynamics "
                            "does not carry fibres yet (its stable step); statics do",
                            lat->cfg.nfibre, lat->cfg.nfibre == 1 ? "" : "s");
    cf_status rc = check_run(fx, path, sample_t_s, nsamples, err);
    if (rc != CF_OK)
        return rc;
    solver s;
    if ((rc = cf_msm_solver_init(&s, lat, fx, cfg, path->drive, st, err)) != CF_OK)
        return rc;
    dyn d = {0};
    if (fx->inertia && (rc = cf_msm_dyn_init(&d, &s, err)) != CF_OK)
        goto end;
    s.load = 0;
    double t = nsamples ? fmin(sample_t_s[0], path->t_s[0]) : 0;
    if (fx->inertia) {
        st->dt_stable_s = cf_msm_stable_step(lat, fx);
        if (cfg->dt_s > 0 && cfg->dt_s > st->dt_stable_s) {
            rc = cf_error_set(err, CF_E_DATA,
                              "integrator.dt_s = %g s is above the stable explicit step %.6g s "
                              "(stiffest spring, lightest mass); use a smaller step or 0 (auto)",
                              cfg->dt_s, st->dt_stable_s);
            goto end;
        }
        s.load = cf_msm_path_value(path, t);
        if (path->drive == CF_DRIVE_DISPLACEMENT)
            cf_msm_place_top(lat, s.load);
    }
    double E0 = fx->inertia ? cf_msm_total_energy(&s, &d) : 0, Escale = 0, dE = 0;
    for (size_t k = 0; k < nsamples; k++) {
        double tk = sample_t_s[k], vk = cf_msm_path_value(path, tk);
        if ((rc = advance_to(&s, &d, path, t, tk, vk, k, st, err)) != CF_OK)
            goto end;
        t = tk;
        s.load = vk;
        out[k].t_s = tk;
        out[k].strain = cf_lattice_top_strain(lat);
        out[k].lateral_stretch = cf_lattice_lateral_stretch(lat);
        out[k].stress_MPa = sample_stress(&s, &d, path, vk);
        out[k].kinetic_mJ = fx->inertia ? cf_msm_kinetic(lat, &d) : 0.0;
        out[k].neg_pivots = fx->inertia ? -1 : s.neg_pivots;
        if (!isfinite(out[k].strain) || !isfinite(out[k].stress_MPa) ||
            !isfinite(out[k].kinetic_mJ)) {
            rc = cf_error_set(err, CF_E_INTERNAL,
                              "the simulation became non-finite at t = %.6g s (energy or "
                              "displacement); the time step is too large for this scene",
                              tk);
            goto end;
        }
        if (fx->inertia && fx->eta_MPa_s == 0 && !s.sigm) {
            /* Drift relative to the largest kinetic energy seen: the energy the load exchanges. */
            dE = fmax(dE, fabs(cf_msm_total_energy(&s, &d) - E0));
            Escale = fmax(Escale, out[k].kinetic_mJ);
            st->max_energy_drift = Escale > 0 ? dE / Escale : 0.0;
        }
        if (done)
            *done = k + 1;
        if (cfg->progress)
            cfg->progress(cfg->progress_ctx, k + 1, nsamples, tk);
    }
end:
    cf_msm_dyn_free(&d);
    cf_msm_solver_free(&s);
    return rc;
}
