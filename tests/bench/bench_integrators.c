/*
** Benchmark section 3: the integrators of the mass-spring model. The uniaxial compression curve of
** the default 3 x 3 x 3 lattice computed by each solver conifit offers (static equilibria,
** implicit quasi-static steps with dashpots, explicit symplectic dynamics) at several time steps,
** against the static solution, and the time each takes.
*/
#include <math.h>
#include <string.h>

#include "bench.h"
#include "model/msm.h"

#define NSAMP 9
#define STRAIN_MAX 0.45
#define RAMP_S 0.05
#define ETA_MPA_S 1e-7

typedef struct run_out {
    cf_status st;
    double err;      /* max |stress - static| / max |static| */
    bench_stats ms;
    cf_msm_stats stats;
    char msg[CF_ERROR_MSG_LEN];
} run_out;

static run_out run(const cf_law *law, const cf_msm_effects *fx, double dt, const double *ref,
                   int repeats)
{
    run_out o;
    memset(&o, 0, sizeof o);
    const double tp[2] = {0, RAMP_S}, vp[2] = {0, STRAIN_MAX};
    cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 2, tp, vp};
    double ts[NSAMP];
    for (int k = 0; k < NSAMP; k++)
        ts[k] = RAMP_S * (double)(k + 1) / NSAMP;
    cf_msm_config cfg = cf_msm_default();
    cfg.dt_s = dt;
    double t[9];
    for (int r = 0; r < repeats; r++) {
        cf_lattice lat;
        cf_error err = {0};
        if ((o.st = cf_lattice_create(&lat, law, CF_LAW_CLOSED, &cfg.lattice, &err)) != CF_OK) {
            snprintf(o.msg, sizeof o.msg, "%s", err.msg);
            return o;
        }
        cf_msm_sample out[NSAMP];
        size_t done = 0;
        double t0 = bench_now();
        o.st = cf_msm_run(&lat, fx, &cfg, &path, ts, NSAMP, out, &done, &o.stats, &err);
        t[r] = (bench_now() - t0) * 1e3;
        cf_lattice_free(&lat);
        if (o.st != CF_OK) {
            snprintf(o.msg, sizeof o.msg, "%s", err.msg);
            return o;
        }
        if (ref) {
            double e = 0, smax = 0;
            for (int k = 0; k < NSAMP; k++) {
                e = fmax(e, fabs(out[k].stress_MPa - ref[k]));
                smax = fmax(smax, fabs(ref[k]));
            }
            o.err = e / smax;
        }
    }
    o.ms = bench_summarise(t, repeats);
    return o;
}

static void row(FILE *md, const char *name, const char *dt, const run_out *o, int has_err)
{
    if (o->st != CF_OK) {
        fprintf(md, "| %s | %s | failed: %s | – | – |\n", name, dt, o->msg);
        return;
    }
    char e[32];
    snprintf(e, sizeof e, has_err ? "%.2e" : "(reference)", o->err);
    fprintf(md, "| %s | %s | %s | %zu | %.1f [%.1f–%.1f] |\n", name, dt, e,
            o->stats.steps ? o->stats.steps : o->stats.solves, o->ms.median, o->ms.min,
            o->ms.max);
}

void bench_section_integrators(bench_ctx *ctx)
{
    const int repeats = ctx->quick ? 1 : 3;
    const cf_spring p = {8, 20, 2.5, 2, 100, 5};
    cf_law law;
    cf_law_init(&law, &p, NULL);
    fprintf(ctx->md,
            "## 3. Integrators: uniaxial curve against the static solution\n\n"
            "Default lattice (3×3×3 cells, face and body diagonals, bottom sliding), the spring "
            "of `data/telescoping.csv`, closed-form law; the top face is driven from 0 to a "
            "compressive strain of %.2f in %.2f s and the nominal stress sampled at %d equal "
            "strains. Error: largest |σ − σ_static| over the samples, relative to the largest "
            "static stress. The dashpot (η = %.0e MPa·s beside every spring, needed by the "
            "quasi-static solver and damping the dynamics) adds an overstress η·rate = %.1e MPa "
            "that no time step removes. Time: wall time of the whole run, ms, median of %d "
            "[min–max]; \"steps\" counts time steps (static: Newton solves).\n\n"
            "| solver | time step | error vs static | steps | ms |\n|---|---|---|---|---|\n",
            STRAIN_MAX, RAMP_S, NSAMP, ETA_MPA_S, ETA_MPA_S * STRAIN_MAX / RAMP_S, repeats);
    /* the static reference */
    double ref[NSAMP];
    {
        const double tp[2] = {0, RAMP_S}, vp[2] = {0, STRAIN_MAX};
        cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 2, tp, vp};
        double ts[NSAMP];
        for (int k = 0; k < NSAMP; k++)
            ts[k] = RAMP_S * (double)(k + 1) / NSAMP;
        cf_msm_config cfg = cf_msm_default();
        cf_lattice lat;
        cf_msm_sample out[NSAMP];
        size_t done;
        cf_msm_effects none = {0};
        if (cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg.lattice, NULL) != CF_OK ||
            cf_msm_run(&lat, &none, &cfg, &path, ts, NSAMP, out, &done, NULL, NULL) != CF_OK) {
            fprintf(ctx->md, "(static reference failed: section skipped)\n\n");
            cf_law_free(&law);
            return;
        }
        for (int k = 0; k < NSAMP; k++)
            ref[k] = out[k].stress_MPa;
        cf_lattice_free(&lat);
    }
    cf_msm_effects none = {0};
    run_out o = run(&law, &none, 0, NULL, repeats);
    row(ctx->md, "static (Newton, banded LDLT)", "–", &o, 0);
    cf_msm_effects qs = {0};
    qs.eta_MPa_s = ETA_MPA_S;
    static const double qdt[] = {RAMP_S / 10, RAMP_S / 50, RAMP_S / 250};
    for (size_t i = 0; i < sizeof qdt / sizeof qdt[0]; i++) {
        o = run(&law, &qs, qdt[i], ref, repeats);
        char dt[32];
        snprintf(dt, sizeof dt, "%.1e s", qdt[i]);
        row(ctx->md, "quasi-static (backward Euler, dashpots)", dt, &o, 1);
    }
    cf_msm_effects dyn = {0};
    dyn.inertia = 1;
    dyn.eta_MPa_s = ETA_MPA_S;
    o = run(&law, &dyn, 0, ref, repeats);
    char dt[64];
    snprintf(dt, sizeof dt, "automatic (smallest %.2e s)", o.stats.dt_used_min_s);
    row(ctx->md, "explicit dynamics (symplectic Euler)", dt, &o, 1);
    const double auto_dt = o.stats.dt_used_min_s;
    static const double frac[] = {0.5, 0.25};
    for (size_t i = 0; i < 2 && o.st == CF_OK && auto_dt > 0; i++) {
        run_out d = run(&law, &dyn, auto_dt * frac[i], ref, repeats);
        snprintf(dt, sizeof dt, "%.2e s (%.2g× automatic)", auto_dt * frac[i], frac[i]);
        row(ctx->md, "explicit dynamics (symplectic Euler)", dt, &d, 1);
    }
    fprintf(ctx->md, "\n");
    cf_law_free(&law);
}
