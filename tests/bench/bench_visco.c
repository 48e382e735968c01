/*
** Section 8 of the benchmark: what a viscoelastic fit of a time series costs, against the number
** of Prony terms and against the length of the series, and what one model curve costs in the
** homogenised cell (the fit's evaluator) against the full lattice.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "fit/viscofit.h"
#include "model/viscomodel.h"

/* A ramp to 30 % compressive strain in 30 s held to 330 s, n points (a third on the ramp). */
static void series(size_t n, double *t, double *x)
{
    size_t nr = n / 3;
    for (size_t k = 0; k <= nr; k++) {
        t[k] = 30.0 * (double)k / (double)nr;
        x[k] = -0.3 * t[k] / 30.0;
    }
    for (size_t k = nr + 1; k < n; k++) {
        double f = (double)(k - nr) / (double)(n - 1 - nr);
        t[k] = 30 + 300 * f * f;
        x[k] = -0.3;
    }
}

static cf_visco_params truth(int nb)
{
    static const double g[4] = {0.3, 0.2, 0.1, 0.05}, tau[4] = {1.5, 8, 40, 200};
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    p.ident.rho = 0.3;
    p.ident.solid = 0.5;
    p.ident.scale = 0.01;
    p.nbranch = nb;
    for (int i = 0; i < nb; i++) {
        p.g[i] = g[i];
        p.tau_s[i] = tau[i];
    }
    return p;
}

/* Median time (s) of fitting the series of n points made from nb known terms with nb terms
** (nb 0: the first two known terms, fitted with N = 1..4 chosen) and relaxation relax. */
static bench_stats fit_time(const bench_ctx *ctx, size_t n, int nb, cf_visco_relaxation relax,
                            long *evals, double *rmse)
{
    double *t = malloc(n * sizeof(double)), *x = malloc(n * sizeof(double)),
           *y = malloc(n * sizeof(double));
    double dt[5];
    int reps = ctx->quick ? 1 : 3, done = 0;
    cf_visco_params p = truth(nb ? nb : 2);
    cf_visco_fit_options o = cf_visco_fit_default_options();
    o.nbranch = nb;
    o.relaxation = relax;
    cf_visco_series s = {n, t, x};
    cf_error err = {0};
    if (t && x && y) {
        series(n, t, x);
        if (cf_visco_curve(&p, &o.setup, &s, y, NULL, &err) == CF_OK)
            for (int r = 0; r < reps; r++) {
                cf_visco_data d = {n, t, x, y, NULL};
                cf_visco_fit f;
                double t0 = bench_now();
                if (cf_visco_fit_run(&d, &o, &f, &err) != CF_OK)
                    break;
                dt[done++] = bench_now() - t0;
                *evals = f.evaluations;
                *rmse = f.rmse;
                cf_visco_fit_free(&f);
            }
    }
    free(t);
    free(x);
    free(y);
    if (done == 0) {
        bench_stats none = {NAN, NAN, NAN, 0};
        return none;
    }
    return bench_summarise(dt, done);
}

void bench_section_visco(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    fprintf(md, "## 8. Viscoelastic fit: time against Prony terms and series length\n\n");
    fprintf(md, "A ramp to 30 %% compressive strain in 30 s held to 330 s (a third of the points on "
                "the ramp), made by the model from known terms (rho 0.3, s/H 0.5, F_C/H^2 10 kPa; "
                "g 0.3, 0.2, 0.1, 0.05 at tau 1.5, 8, 40, 200 s, the first N of them) and fitted "
                "back with N terms (`--branches N`), quasi-linear (`--relaxation qlv`) or with "
                "relaxation depending on strain (`strain`); the command's default fits N = 1..4 "
                "with both and keeps the lowest AIC among the candidates whose terms are "
                "determined (the row `1-4`, `auto`, on the series of the first two terms). Median "
                "of %d runs, one core; the model is evaluated in the "
                "homogenised cell, 10 implicit steps per interval.\n\n",
            ctx->quick ? 1 : 3);
    fprintf(md, "| N | relaxation | points | fit time (s) | spread (s) | model curves | RMSE "
                "(MPa) |\n");
    fprintf(md, "|---|---|---|---|---|---|---|\n");
    static const char *const relax_name[] = {"qlv", "strain", "auto"};
    static const struct {
        int nb;
        cf_visco_relaxation relax;
        size_t n;
    } rows[] = {{1, CF_RELAX_QLV, 36},    {2, CF_RELAX_QLV, 36},    {3, CF_RELAX_QLV, 36},
                {4, CF_RELAX_QLV, 36},    {2, CF_RELAX_STRAIN, 36}, {0, CF_RELAX_AUTO, 36},
                {2, CF_RELAX_QLV, 18},    {2, CF_RELAX_QLV, 72},    {2, CF_RELAX_QLV, 144}};
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        if (ctx->quick && rows[k].n > 72)
            continue;
        long ev = 0;
        double rm = NAN;
        bench_stats st = fit_time(ctx, rows[k].n, rows[k].nb, rows[k].relax, &ev, &rm);
        char nb[8];
        snprintf(nb, sizeof nb, rows[k].nb ? "%d" : "1-4", rows[k].nb);
        fprintf(md, "| %s | %s | %zu | %.3g | %.3g to %.3g | %ld | %.2g |\n", nb,
                relax_name[rows[k].relax], rows[k].n, st.median, st.min, st.max, ev, rm);
    }
    /* one model curve: the cell against the lattice it stands for */
    size_t n = 36;
    double t[36], x[36], y[36];
    series(n, t, x);
    cf_visco_params p = truth(2);
    cf_visco_series s = {n, t, x};
    cf_visco_setup cell = cf_visco_default(), lat = cell;
    lat.cell = 0;
    cf_error err = {0};
    double dc[9], dl[3];
    int rc = ctx->quick ? 3 : 9, rl = ctx->quick ? 1 : 3;
    for (int r = 0; r < rc; r++) {
        double t0 = bench_now();
        cf_visco_curve(&p, &cell, &s, y, NULL, &err);
        dc[r] = bench_now() - t0;
    }
    for (int r = 0; r < rl; r++) {
        double t0 = bench_now();
        cf_visco_curve(&p, &lat, &s, y, NULL, &err);
        dl[r] = bench_now() - t0;
    }
    bench_stats sc = bench_summarise(dc, rc), sl = bench_summarise(dl, rl);
    fprintf(md, "\nOne model curve of 36 points: %.3g ms in the cell, %.3g ms in the %dx%dx%d "
                "lattice (median of %d and %d runs).\n\n",
            1e3 * sc.median, 1e3 * sl.median, lat.cfg.lattice.nx, lat.cfg.lattice.ny,
            lat.cfg.lattice.nz, rc, rl);
}
