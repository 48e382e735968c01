/*
** The time-dependent model of a fitted tissue (see viscomodel.h): the lattice of msm.h with Prony
** branches, driven by a measured strain history.
*/
#include "conifit/viscomodel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

cf_visco_setup cf_visco_default(void)
{
    cf_visco_setup s;
    s.cfg = cf_msm_default();
    s.cfg.lattice.nx = s.cfg.lattice.ny = s.cfg.lattice.nz = 1;
    s.method = CF_LAW_CLOSED;
    return s;
}

cf_spring cf_spring_member(double rho, double e, double A)
{
    /* non-telescoping with n = 2, d = L_min/2 and D2 = L_min/(1 - rho), so that (D2 - D1)/2 =
    ** L_min/2 stays below n d = L_min */
    const double H = 1.0, Lmin = H * (1 - e), s = H * e, n = 2.0, dw = Lmin / n;
    const double D2 = rho < 1 ? Lmin / (1 - rho) : Lmin, D1 = rho * D2;
    const double FC = A * H * H, d2 = dw * dw;
    cf_spring p = {D1, D2, n, dw, 8 * n * D1 * D1 * D1 * FC / (d2 * d2 * s), H};
    return p;
}

cf_msm_effects cf_visco_effects(const cf_visco_params *p)
{
    cf_msm_effects fx;
    memset(&fx, 0, sizeof fx);
    fx.eta_MPa_s = p->eta_MPa_s;
    fx.prony_count = p->nbranch;
    for (int i = 0; i < p->nbranch && i < CF_PRONY_MAX; i++) {
        fx.prony_g[i] = p->g[i];
        fx.prony_tau_s[i] = p->tau_s[i];
    }
    return fx;
}

static cf_status check_params(const cf_visco_params *p, cf_error *err)
{
    if (!(p->rho > 0 && p->rho <= 1))
        return cf_error_set(err, CF_E_DATA, "rho = %g: must be in (0, 1]", p->rho);
    if (!(p->solid_strain > 0 && p->solid_strain < 1))
        return cf_error_set(err, CF_E_DATA, "solid strain = %g: must be in (0, 1)",
                            p->solid_strain);
    if (!(p->stress_scale_MPa > 0) || !isfinite(p->stress_scale_MPa))
        return cf_error_set(err, CF_E_DATA, "stress scale = %g MPa: must be finite and > 0",
                            p->stress_scale_MPa);
    if (!(p->eta_MPa_s >= 0) || !isfinite(p->eta_MPa_s))
        return cf_error_set(err, CF_E_DATA, "dashpot eta = %g MPa s: must be finite and >= 0",
                            p->eta_MPa_s);
    if (p->nbranch < 0 || p->nbranch > CF_PRONY_MAX)
        return cf_error_set(err, CF_E_DATA, "%d Prony terms: between 0 and %d", p->nbranch,
                            CF_PRONY_MAX);
    cf_msm_effects fx = cf_visco_effects(p);
    return cf_msm_prony_check(&fx, err);
}

static cf_status run(const cf_visco_params *p, const cf_visco_setup *s, const cf_msm_path *path,
                     const double *sample_t_s, size_t nsamples, cf_msm_sample *out,
                     cf_msm_stats *stats, cf_error *err)
{
    cf_status st = check_params(p, err);
    if (st != CF_OK)
        return st;
    cf_spring sp = cf_spring_member(p->rho, p->solid_strain, p->stress_scale_MPa);
    cf_law law;
    if ((st = cf_law_init(&law, &sp, err)) != CF_OK)
        return st;
    if (s->method == CF_LAW_TABLE && (st = cf_law_table_build(&law, CF_LAW_TABLE_DEFAULT, err))) {
        cf_law_free(&law);
        return st;
    }
    cf_lattice lat;
    if ((st = cf_lattice_create(&lat, &law, s->method, &s->cfg.lattice, err)) == CF_OK) {
        cf_msm_effects fx = cf_visco_effects(p);
        cf_msm_config cfg = s->cfg;
        cfg.progress = NULL;
        st = cf_msm_run(&lat, &fx, &cfg, path, sample_t_s, nsamples, out, NULL, stats, err);
        cf_lattice_free(&lat);
    }
    cf_law_free(&law);
    return st;
}

cf_status cf_visco_run(const cf_visco_params *p, const cf_visco_setup *s, const cf_msm_path *path,
                       const double *sample_t_s, size_t nsamples, cf_msm_sample *out,
                       cf_error *err)
{
    return run(p, s, path, sample_t_s, nsamples, out, NULL, err);
}

cf_status cf_visco_curve(const cf_visco_params *p, const cf_visco_setup *s,
                         const cf_visco_series *series, double *stress_MPa, cf_msm_stats *stats,
                         cf_error *err)
{
    const size_t n = series->count;
    if (n < 2)
        return cf_error_set(err, CF_E_DATA, "a time series needs at least 2 points");
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(series->t_s[k]) || !isfinite(series->strain[k]))
            return cf_error_set(err, CF_E_DATA, "point %zu of the series is not finite", k + 1);
        if (k > 0 && !(series->t_s[k] > series->t_s[k - 1]))
            return cf_error_set(err, CF_E_DATA,
                                "time %.17g s at point %zu does not increase (previous %.17g s)",
                                series->t_s[k], k + 1, series->t_s[k - 1]);
    }
    double *v = malloc(n * sizeof(double));
    cf_msm_sample *out = malloc(n * sizeof(cf_msm_sample));
    if (!v || !out) {
        free(v);
        free(out);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a series of %zu points", n);
    }
    for (size_t k = 0; k < n; k++)
        v[k] = -series->strain[k]; /* compressive positive */
    cf_msm_path path = {CF_DRIVE_DISPLACEMENT, n, series->t_s, v};
    cf_status st = run(p, s, &path, series->t_s, n, out, stats, err);
    for (size_t k = 0; st == CF_OK && k < n; k++)
        stress_MPa[k] = -out[k].stress_MPa;
    free(v);
    free(out);
    return st;
}
