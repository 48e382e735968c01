/*
** Benchmark section 1: the force law. Error of each evaluator against `exact` over a dense sweep
** that includes the hard corners, and the time of one evaluation.
*/
#include <math.h>
#include <stdlib.h>

#include "bench.h"
#include "model/law_internal.h"

typedef struct variant {
    const char *name;
    cf_law_method method;
    size_t table;
} variant;

static const variant variants[] = {
    {"exact", CF_LAW_EXACT, 0},       {"closed", CF_LAW_CLOSED, 0},
    {"closed+newton", CF_LAW_CLOSED_NEWTON, 0}, {"table 16", CF_LAW_TABLE, 16},
    {"table 64", CF_LAW_TABLE, 64},   {"table 256", CF_LAW_TABLE, 256},
    {"table 1024", CF_LAW_TABLE, 1024}, {"table 4096", CF_LAW_TABLE, 4096},
};
#define NVAR (sizeof variants / sizeof variants[0])

static const double rhos[] = {1 - 1e-6, 0.9, 0.5, 0.1, 1e-3};
#define NRHO (sizeof rhos / sizeof rhos[0])

static cf_spring spring_for(double rho)
{
    cf_spring p = {rho * 30, 30, 5, fmin(rho * 30 / 4, 0.08), 8e4, 40};
    return p;
}

/* Sweep of region 2 (and the corners): uniform, clustered at both ends, one ulp around u_T. */
static size_t sweep(const cf_law *law, double *u, size_t n)
{
    size_t k = 0;
    const double s = law->travel_mm, uT = law->u_T_mm;
    u[k++] = nextafter(uT, INFINITY);
    u[k++] = s * (1 - 1e-15);
    u[k++] = nextafter(s, 0);
    while (k < n) {
        double x = (double)(k + 1) / (double)(n + 1);
        double xx = (k % 3 == 0) ? x : (k % 3 == 1) ? 1 - pow(1 - x, 4) : x * x * x * x;
        u[k++] = uT + (s - uT) * xx;
    }
    return k;
}

/* Median nanoseconds per evaluation of cf_law_force over the array u. */
static bench_stats time_law(const cf_law *law, cf_law_method m, const double *u, size_t n,
                            int repeats)
{
    double t[15];
    for (int r = 0; r < repeats; r++) {
        double acc = 0, t0 = bench_now();
        for (size_t i = 0; i < n; i++)
            acc += cf_law_force(law, m, u[i], NULL, NULL);
        t[r] = (bench_now() - t0) / (double)n * 1e9;
        bench_sink += acc;
    }
    return bench_summarise(t, repeats);
}

static bench_stats time_linear(const double *u, size_t n, int repeats)
{
    double t[15];
    volatile double kk = 0.25;
    const double k = kk;
    for (int r = 0; r < repeats; r++) {
        double acc = 0, t0 = bench_now();
        for (size_t i = 0; i < n; i++)
            acc += k * u[i];
        t[r] = (bench_now() - t0) / (double)n * 1e9;
        bench_sink += acc;
    }
    return bench_summarise(t, repeats);
}

void bench_section_law(bench_ctx *ctx)
{
    const size_t nerr = ctx->quick ? 20000 : 200000, ntime = ctx->quick ? 100000 : 1000000;
    const int repeats = ctx->quick ? 3 : 9;
    double *u = malloc(nerr * sizeof *u), *ut = malloc(ntime * sizeof *ut);
    double maxerr[NVAR] = {0}, sumsq[NVAR] = {0};
    size_t cnt = 0;
    if (!u || !ut) {
        fprintf(ctx->md, "(law section skipped: out of memory)\n");
        free(u);
        free(ut);
        return;
    }
    /* accuracy: every variant against exact, region 2 of each geometry */
    double per_rho[NRHO][NVAR];
    for (size_t g = 0; g < NRHO; g++) {
        cf_law law;
        cf_spring p = spring_for(rhos[g]);
        cf_law_init(&law, &p, NULL);
        size_t n = sweep(&law, u, nerr);
        for (size_t v = 0; v < NVAR; v++) {
            if (variants[v].table)
                cf_law_table_build(&law, variants[v].table, NULL);
            double worst = 0;
            for (size_t i = 0; i < n; i++) {
                double R = cf_law_force(&law, CF_LAW_EXACT, u[i], NULL, NULL);
                double F = cf_law_force(&law, variants[v].method, u[i], NULL, NULL);
                double e = fabs(F - R) / fabs(R);
                worst = fmax(worst, e);
                sumsq[v] += e * e;
            }
            per_rho[g][v] = worst;
            maxerr[v] = fmax(maxerr[v], worst);
        }
        cnt += n;
        cf_law_free(&law);
    }
    /* time: rho = 0.5, u uniform over region 2 and over the whole range (-s, s) */
    cf_law law;
    cf_spring p = spring_for(0.5);
    cf_law_init(&law, &p, NULL);
    srand(12345);
    for (size_t i = 0; i < ntime; i++) {
        double x = (double)rand() / ((double)RAND_MAX + 1.0);
        ut[i] = law.u_T_mm + (law.travel_mm - law.u_T_mm) * x;
    }
    bench_stats tr2[NVAR], tall[NVAR];
    bench_stats tlin = time_linear(ut, ntime, repeats);
    for (size_t v = 0; v < NVAR; v++) {
        if (variants[v].table)
            cf_law_table_build(&law, variants[v].table, NULL);
        size_t nt = variants[v].method == CF_LAW_EXACT ? ntime / 20 : ntime;
        tr2[v] = time_law(&law, variants[v].method, ut, nt, repeats);
    }
    for (size_t i = 0; i < ntime; i++)
        ut[i] = law.travel_mm * (2.0 * (double)rand() / ((double)RAND_MAX + 1.0) - 1.0);
    for (size_t v = 0; v < NVAR; v++) {
        if (variants[v].table)
            cf_law_table_build(&law, variants[v].table, NULL);
        size_t nt = variants[v].method == CF_LAW_EXACT ? ntime / 20 : ntime;
        tall[v] = time_law(&law, variants[v].method, ut, nt, repeats);
    }
    cf_law_free(&law);

    fprintf(ctx->md,
            "## 1. Force law: accuracy against time\n\n"
            "Error: relative force error |F − F_exact|/|F_exact| over %zu points of region 2 "
            "(uniform, clustered at u_T and at solid, one ulp past u_T, 1e-15 below solid) for "
            "ρ = 1−1e-6, 0.9, 0.5, 0.1, 1e-3 (all constant-pitch springs, G = 80 GPa, H = 40 mm). "
            "Time: ns per `cf_law_force` call at ρ = 0.5, median of %d runs over %zu random "
            "displacements (exact: 1/20 of them), min–max in brackets. The linear spring F = k u "
            "is the floor.\n\n",
            cnt, repeats, ntime);
    fprintf(ctx->md, "| evaluator | max rel. error | RMS rel. error | ns/eval, region 2 | "
                     "ns/eval, whole range |\n|---|---|---|---|---|\n");
    fprintf(ctx->md, "| linear spring (floor) | – | – | %.2f [%.2f–%.2f] | – |\n", tlin.median,
            tlin.min, tlin.max);
    FILE *dat = bench_open_data(ctx, "law_pareto.dat");
    for (size_t v = 0; v < NVAR; v++) {
        double rms = sqrt(sumsq[v] / (double)cnt);
        char e1[32], e2[32];
        snprintf(e1, sizeof e1, v == 0 ? "(reference)" : "%.2e", maxerr[v]);
        snprintf(e2, sizeof e2, v == 0 ? "(reference)" : "%.2e", rms);
        fprintf(ctx->md, "| %s | %s | %s | %.1f [%.1f–%.1f] | %.1f [%.1f–%.1f] |\n",
                variants[v].name, e1, e2, tr2[v].median, tr2[v].min, tr2[v].max,
                tall[v].median, tall[v].min, tall[v].max);
        if (dat)
            fprintf(dat, "%.6g %.6g \"%s\"\n", tr2[v].median, fmax(maxerr[v], 1e-17),
                    variants[v].name);
    }
    if (dat)
        fclose(dat);
    fprintf(ctx->md, "\nMaximum relative error per geometry:\n\n| evaluator |");
    for (size_t g = 0; g < NRHO; g++)
        fprintf(ctx->md, " ρ = %.6g |", rhos[g]);
    fprintf(ctx->md, "\n|---|");
    for (size_t g = 0; g < NRHO; g++)
        fprintf(ctx->md, "---|");
    fprintf(ctx->md, "\n");
    for (size_t v = 1; v < NVAR; v++) {
        fprintf(ctx->md, "| %s |", variants[v].name);
        for (size_t g = 0; g < NRHO; g++)
            fprintf(ctx->md, " %.1e |", per_rho[g][v]);
        fprintf(ctx->md, "\n");
    }
    const double speedup = tr2[0].median / tr2[1].median;
    const double speedup_n = tr2[0].median / tr2[2].median;
    fprintf(ctx->md,
            "\n**Targets.** Closed form within 1e-12 of exact: %s (max %.1e; closed+newton %.1e). "
            "Closed form at least 5× faster than exact: %s (%.1f×; closed+newton %.1f×).\n\n",
            maxerr[1] <= 1e-12 ? "**met**" : "**not met**", maxerr[1], maxerr[2],
            speedup >= 5 ? "**met**" : "**not met**", speedup, speedup_n);
    bench_target_add(ctx, "closed form within 1e-12 of exact (max relative force error)",
                     maxerr[1] <= 1e-12, "%.1e", maxerr[1]);
    bench_target_add(ctx, "closed form at least 5× faster than exact (region 2)", speedup >= 5,
                     "%.1f× (%.1f ns against %.1f ns)", speedup, tr2[1].median, tr2[0].median);
    if (bench_gnuplot(ctx, "set terminal pngcairo size 800,500\n"
                           "set output 'law_pareto.png'\n"
                           "set logscale xy\nset grid\n"
                           "set xlabel 'time per evaluation, region 2 [ns]'\n"
                           "set ylabel 'max relative force error vs exact'\n"
                           "set title 'Force law: accuracy against time'\n"
                           "plot 'law_pareto.dat' using 1:2 with points pt 7 ps 1.5 notitle, "
                           "'' using 1:2:3 with labels offset 0,1 notitle\n") == 0)
        fprintf(ctx->md, "![force law: error against time](law_pareto.png)\n\n");
}
