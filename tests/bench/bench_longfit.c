/*
** Section 10 of the benchmark: what a fit of a long table costs. A synthetic table of 1e4, 1e5 and
** 1e6 rows is read from a CSV file and fitted (both spring types and the baselines, as
** `conifit fit` does without --validate); the global searches run on a subsample of the table
** above CF_FIT_SUBSAMPLE_ABOVE rows and the polish on every row, so the time grows linearly in the
** rows. The search on every row (cf_fit_options.subsample_above = 0) is timed beside it at 1e4
** and 1e5 rows.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "fit/baseline.h"
#include "fit/fit.h"
#include "model/law_internal.h"
#include "io/measure.h"

/* Writes the table of the spring 8/20 mm, 2.5 coils, wire 2 mm, G 100 MPa, H 5 mm (telescoping,
** rho 0.4) with 1 % Gaussian noise, n rows from strain 0 to 0.95 of the solid strain, as
** `conifit synth --points n --noise 0.01` does. 0 on success. */
static double spring_stress(double x, const void *arg)
{
    const cf_law *law = arg;
    const double H = law->p.H_mm;
    return cf_law_force(law, CF_LAW_EXACT, x * H, NULL, NULL) / (H * H);
}

static int write_table(const char *path, size_t n)
{
    const cf_spring p = {8, 20, 2.5, 2, 100, 5};
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return -1;
    double smax = 0.95 * law.travel_mm / p.H_mm;
    double ymax = law.F_C_N / (p.H_mm * p.H_mm);
    return bench_write_table(path, n, smax, 0.01 * ymax, 1e3, spring_stress, &law);
}

typedef struct long_run {
    double read_s, fit_s, fit_cpu_s; /* one run: wall times and the fit's CPU time */
    long evals, evals_full;  /* both types */
    double rmse;             /* the telescoping fit, MPa */
} long_run;

/* Reads the table at path and fits both types and the baselines; 0 on success. */
static int run_once(const char *path, size_t subsample_above, long_run *out)
{
    cf_measure_options mo;
    memset(&mo, 0, sizeof mo);
    cf_table t;
    cf_error err = {0};
    double t0 = bench_now();
    if (cf_measure_load(path, &mo, &t, &err) != CF_OK)
        return -1;
    double t1 = bench_now(), c1 = bench_cpu_now();
    cf_fit_options o = cf_fit_default_options();
    o.subsample_above = subsample_above;
    out->evals = out->evals_full = 0;
    int ok = 1;
    for (int ty = 0; ty < 2 && ok; ty++) {
        cf_fit_result r;
        ok = cf_fit_run(&t, &o, (cf_spring_type)ty, &r, &err) == CF_OK;
        if (ok) {
            out->evals += r.evaluations;
            out->evals_full += r.evaluations_full;
            if (ty == 0)
                out->rmse = r.rmse;
        }
    }
    cf_baseline b[CF_BASE_COUNT];
    if (ok)
        ok = cf_baseline_fit_all(&t, b, NULL) == CF_OK;
    out->read_s = t1 - t0;
    out->fit_s = bench_now() - t1;
    out->fit_cpu_s = bench_cpu_now() - c1;
    cf_table_free(&t);
    return ok ? 0 : -1;
}

void bench_section_longfit(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    const size_t rows[3] = {10000, 100000, 1000000};
    const int reps[3] = {ctx->quick ? 1 : 5, ctx->quick ? 1 : 3, ctx->quick ? 1 : 3};
    fprintf(md, "## 10. Long tables: fit time against rows\n\n");
    fprintf(md, "A synthetic stress-strain table (the telescoping spring D1 8, D2 20, n 2.5, d 2 mm, "
                "G 100 MPa, H 5 mm, rho 0.4; strain 0 to 0.95 of its solid strain, evenly spaced; "
                "1 %% Gaussian noise, seed 1), written as a CSV file, read with `cf_measure_load` and "
                "fitted as `conifit fit` fits it without `--validate`: both spring types and the "
                "five baselines. Above %d rows the global searches (stage A's grid and starts, the "
                "Fung and Ogden scans) run on a subsample of at most 1000 rows evenly along the "
                "strain, and "
                "the polish (Levenberg-Marquardt on the three identifiable quantities, the "
                "baselines' refinement, errors) on every row. Median of the repeats, one core, "
                "as wall time and as CPU time (the process's own: on a shared machine the wall time "
                "grows with the load, the CPU time much less); \"passes\" counts evaluations of the model over every row (both types), beside "
                "all evaluations (subsample included).\n\n",
            CF_FIT_SUBSAMPLE_ABOVE);
    fprintf(md, "| rows | repeats | read, s | fit, s (median) | spread, s | fit, CPU s (median) "
                "| passes over every row | all evaluations | RMSE, kPa |\n"
                "|---|---|---|---|---|---|---|---|---|\n");
    char path[1100];
    snprintf(path, sizeof path, "%s/longfit-%ld.csv", ctx->dir, (long)getpid());
    double fit_med[3] = {NAN, NAN, NAN}, cpu_med[3] = {NAN, NAN, NAN};
    for (int k = 0; k < 3; k++) {
        if (write_table(path, rows[k]) != 0) {
            fprintf(md, "| %zu | – | cannot write the table | – | – | – | – | – | – |\n", rows[k]);
            continue;
        }
        double tf[5], tr[5], tc[5];
        long_run lr = {0};
        int done = 0;
        for (int r = 0; r < reps[k]; r++) {
            if (run_once(path, CF_FIT_SUBSAMPLE_ABOVE, &lr) != 0)
                break;
            tf[done] = lr.fit_s;
            tc[done] = lr.fit_cpu_s;
            tr[done++] = lr.read_s;
        }
        if (done == 0) {
            fprintf(md, "| %zu | – | the fit failed | – | – | – | – | – | – |\n", rows[k]);
            continue;
        }
        bench_stats sf = bench_summarise(tf, done), sr = bench_summarise(tr, done),
                    sc = bench_summarise(tc, done);
        fit_med[k] = sf.median;
        cpu_med[k] = sc.median;
        fprintf(md, "| %zu | %d | %.3g | **%.3g** | %.3g to %.3g | %.3g | %ld | %ld | %.4g |\n",
                rows[k], done, sr.median, sf.median, sf.min, sf.max, sc.median, lr.evals_full,
                lr.evals, 1e3 * lr.rmse);
    }
    /* the search on every row, for comparison (one run each) */
    fprintf(md, "\nThe search on every row (`subsample_above = 0`, the path of tables up to %d "
                "rows), one run:\n\n| rows | fit, s | fit, CPU s | passes over every row | RMSE, kPa |\n"
                "|---|---|---|---|---|\n",
            CF_FIT_SUBSAMPLE_ABOVE);
    for (int k = 0; k < (ctx->quick ? 1 : 2); k++) {
        long_run lr = {0};
        if (write_table(path, rows[k]) != 0 || run_once(path, 0, &lr) != 0) {
            fprintf(md, "| %zu | failed | – | – | – |\n", rows[k]);
            continue;
        }
        fprintf(md, "| %zu | %.3g | %.3g | %ld | %.4g |\n", rows[k], lr.fit_s, lr.fit_cpu_s,
                lr.evals_full, 1e3 * lr.rmse);
    }
    remove(path);
    double slope = log(cpu_med[2] / cpu_med[0]) / log(100.0);
    fprintf(md, "\nGrowth from 1e4 to 1e6 rows: CPU time ∝ rows^%.2f.\n\n", slope);
    bench_target_add(ctx, "a 1e5-row table fits in seconds (< 2 s)", cpu_med[1] < 2 ? 1 : 0,
                     "%.3g s CPU, %.3g s wall (both types and baselines)", cpu_med[1], fit_med[1]);
    bench_target_add(ctx, "a 1e6-row table fits well under a minute (< 30 s)",
                     fit_med[2] < 30 ? 1 : 0, "%.3g s CPU, %.3g s wall", cpu_med[2], fit_med[2]);
}
