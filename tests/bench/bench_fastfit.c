/*
** Section 11 of the benchmark: fits at the cost of the law. A stress-strain table that is no
** conical spring (stress 3e + 40e^3 kPa, strain 0 to 0.3, 1 % Gaussian noise) from 100 to 1e6
** rows, fitted as `conifit fit` fits it without --validate (both types and the baselines), in CPU
** and wall time, with each type's RMSE against the search on every row (subsample_above = 0);
** then `conifit` itself (a child process, its CPU time from wait4) on the published raw tendon
** table with and without `--target lattice` and on the published relaxation series.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "bench.h"
#include "fit/baseline.h"
#include "fit/fit.h"
#include "io/measure.h"

static double cubic(double e, const void *arg)
{
    (void)arg;
    return 3 * e + 40 * e * e * e;
}

/* The table of n rows, 1 % noise of the largest stress (seed 1); 0 on success. */
static int write_cubic(const char *path, size_t n)
{
    return bench_write_table(path, n, 0.3, 0.01 * cubic(0.3, NULL), 1.0, cubic, NULL);
}

typedef struct fast_run {
    double wall_s, cpu_s;
    double rmse[2]; /* each type, MPa */
} fast_run;

/* Fits the loaded table t (both types, baselines); 0 on success. */
static int fit_once(const cf_table *t, size_t subsample_above, fast_run *out)
{
    cf_fit_options o = cf_fit_default_options();
    o.subsample_above = subsample_above;
    cf_error err = {0};
    double w0 = bench_now(), c0 = bench_cpu_now();
    int ok = 1;
    cf_fit_shared shared; /* as the command shares stage A between the types */
    memset(&shared, 0, sizeof shared);
    for (int ty = 0; ty < 2 && ok; ty++) {
        cf_fit_result r;
        ok = cf_fit_run_shared(t, &o, (cf_spring_type)ty, &shared, &r, &err) == CF_OK;
        if (ok)
            out->rmse[ty] = r.rmse;
    }
    cf_baseline b[CF_BASE_COUNT];
    if (ok)
        ok = cf_baseline_fit_all(t, b, NULL) == CF_OK;
    out->cpu_s = bench_cpu_now() - c0;
    out->wall_s = bench_now() - w0;
    return ok ? 0 : -1;
}

/* The first value of key (e.g. "\"rmse\":") in a fit file, or NAN. */
static double file_rmse(const char *path, const char *key)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return NAN;
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    const char *p = strstr(buf, key);
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

/* Runs argv (a conifit command) in a child: CPU (user + system) and wall seconds; 0 when it
** exited with status 0. */
static int run_child(char *const argv[], double *cpu_s, double *wall_s)
{
    double w0 = bench_now();
    struct rusage ru;
    if (bench_exec(argv, &ru) != 0)
        return -1;
    *wall_s = bench_now() - w0;
    *cpu_s = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
             (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    return 0;
}

enum { NSIZES = 10 };

static void rows_table(bench_ctx *ctx, double cpu[NSIZES], const size_t rows[NSIZES])
{
    FILE *md = ctx->md;
    char path[1100];
    snprintf(path, sizeof path, "%s/fastfit-%ld.csv", ctx->dir, (long)getpid());
    fprintf(md, "| rows | repeats | fit, CPU s (median) | fit, wall s (median) | CPU spread, s | "
                "RMSE telescoping, kPa | RMSE non-telescoping, kPa | largest RMSE change "
                "against the search on every row |\n|---|---|---|---|---|---|---|---|\n");
    for (int k = 0; k < NSIZES; k++) {
        cpu[k] = NAN;
        if (ctx->quick && rows[k] > 10000)
            continue;
        cf_table t;
        cf_measure_options mo;
        memset(&mo, 0, sizeof mo);
        cf_error err = {0};
        if (write_cubic(path, rows[k]) != 0 || cf_measure_load(path, &mo, &t, &err) != CF_OK) {
            fprintf(md, "| %zu | – | cannot write or read the table | – | – | – | – | – |\n",
                    rows[k]);
            continue;
        }
        const int reps = ctx->quick ? 1 : rows[k] <= 3000 ? 9 : rows[k] <= 10000 ? 5 : 3;
        double tc[9], tw[9];
        fast_run fr = {0}, slow = {0};
        int done = 0;
        for (int r = 0; r < reps && fit_once(&t, CF_FIT_SUBSAMPLE_ABOVE, &fr) == 0; r++) {
            tc[done] = fr.cpu_s;
            tw[done++] = fr.wall_s;
        }
        if (done == 0) {
            fprintf(md, "| %zu | – | the fit failed | – | – | – | – | – |\n", rows[k]);
            cf_table_free(&t);
            continue;
        }
        bench_stats sc = bench_summarise(tc, done), sw = bench_summarise(tw, done);
        cpu[k] = sc.median;
        char cmp[96] = "– (no search on every row at this length)";
        if (rows[k] > CF_FIT_SUBSAMPLE_ABOVE && rows[k] <= 100000 &&
            fit_once(&t, 0, &slow) == 0) {
            double worst = 0;
            for (int ty = 0; ty < 2; ty++)
                worst = fmax(worst, fabs(fr.rmse[ty] / slow.rmse[ty] - 1));
            snprintf(cmp, sizeof cmp, "%.2g (every row: %.3g s CPU)", worst, slow.cpu_s);
        } else if (rows[k] <= CF_FIT_SUBSAMPLE_ABOVE) {
            snprintf(cmp, sizeof cmp, "0 (searched on every row)");
        }
        fprintf(md, "| %zu | %d | **%.3g** | %.3g | %.3g to %.3g | %.6g | %.6g | %s |\n", rows[k],
                done, sc.median, sw.median, sc.min, sc.max, 1e3 * fr.rmse[0], 1e3 * fr.rmse[1],
                cmp);
        cf_table_free(&t);
    }
    remove(path);
}

typedef struct cli_case {
    const char *what;
    const char *table;
    const char *extra[4];
    const char *key; /* the RMSE reported: the first of this key in the fit file */
} cli_case;

static void cli_table(bench_ctx *ctx, double cpu[5])
{
    FILE *md = ctx->md;
    const char *env = getenv("CONIFIT");
    char exe[1024], out[1100];
    snprintf(exe, sizeof exe, "%s", env && *env ? env : "build/conifit");
    snprintf(out, sizeof out, "%s/fastfit-%ld.json", ctx->dir, (long)getpid());
    static const cli_case cases[5] = {
        {"raw tendon tension, 2592 rows", "../shared/datasets/tendon_fascicle_tension_raw.csv",
         {0}, "\"rmse\":"},
        {"the same, `--target lattice --validate` (the cell's RMSE)",
         "../shared/datasets/tendon_fascicle_tension_raw.csv",
         {"--target", "lattice", "--validate"}, "\"cell_rmse\":"},
        {"tendon relaxation series, 268 rows (default choice)",
         "../shared/datasets/tendon_fascicle_relaxation.csv", {0}, "\"rmse\":"},
        {"muscle relaxation series, along the fibres",
         "../shared/datasets/muscle_compression_relaxation_fiber30.csv", {0}, "\"rmse\":"},
        {"muscle relaxation series, across the fibres",
         "../shared/datasets/muscle_compression_relaxation_crossfiber30.csv", {0}, "\"rmse\":"},
    };
    fprintf(md, "| run | CPU s | wall s | RMSE (the first fit in the file, its unit) |\n"
                "|---|---|---|---|\n");
    for (int k = 0; k < 5; k++) {
        cpu[k] = NAN;
        if (access(cases[k].table, R_OK) != 0) {
            fprintf(md, "| %s | – | table absent here, skipped | – |\n", cases[k].what);
            continue;
        }
        if (ctx->quick && k >= 2) {
            fprintf(md, "| %s | – | skipped in a quick run | – |\n", cases[k].what);
            continue;
        }
        char *argv[10] = {exe, "fit", (char *)cases[k].table, "-o", out};
        int a = 5;
        for (int e = 0; e < 4 && cases[k].extra[e]; e++)
            argv[a++] = (char *)cases[k].extra[e];
        argv[a] = NULL;
        double c, w;
        if (run_child(argv, &c, &w) != 0) {
            fprintf(md, "| %s | – | the run failed | – |\n", cases[k].what);
            continue;
        }
        cpu[k] = c;
        fprintf(md, "| %s | **%.3g** | %.3g | %.6g |\n", cases[k].what, c, w,
                file_rmse(out, cases[k].key));
    }
    remove(out);
}

void bench_section_fastfit(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    static const size_t rows[NSIZES] = {100,  300,   1000,  1001,   1500,
                                        2000, 10000, 30000, 100000, 1000000};
    fprintf(md, "## 11. Fits at the cost of the law\n\n");
    fprintf(md,
            "A stress-strain table that is no conical spring: stress 3e + 40e^3 kPa, strain 0 to "
            "0.3 evenly spaced, 1 %% Gaussian noise of the largest stress (seed 1), written as "
            "CSV, read with `cf_measure_load` and fitted as `conifit fit` fits it without "
            "`--validate` (both types and the five baselines), on one thread. Above %d rows "
            "every search runs on a subsample of that many rows and the polish on every row; the "
            "law is evaluated in vector lanes throughout. CPU time is the process's own (the "
            "figure a shared machine does not inflate); median of the repeats. The RMSE change "
            "is the larger of the two types' relative differences from the search on every row "
            "(`subsample_above = 0`, one run).\n\n",
            CF_FIT_SUBSAMPLE_ABOVE);
    double cpu[NSIZES];
    rows_table(ctx, cpu, rows);
    /* no cliff: the worst ratio of a length's CPU time to that of any longer length */
    double cliff = 0;
    size_t at = 0;
    for (int k = 0; k < NSIZES; k++)
        for (int j = k + 1; j < NSIZES; j++)
            if (isfinite(cpu[k]) && isfinite(cpu[j]) && cpu[k] / cpu[j] > cliff) {
                cliff = cpu[k] / cpu[j];
                at = rows[k];
            }
    fprintf(md, "\nLargest ratio of a length's CPU time to a longer length's: %.2f (at %zu rows; "
                "above 1 a shorter table costs more).\n\n",
            cliff, at);
    fprintf(md, "`conifit fit TABLE -o OUT.json` as a child process (CPU time from `wait4`, one "
                "run each) on the published tables:\n\n");
    double ccpu[5];
    cli_table(ctx, ccpu);
    fprintf(md, "\n");
    bench_target_add(ctx, "a 100-row table, both types and baselines (<= 10 ms CPU)", cpu[0] <= 0.01,
                     "%.3g ms CPU", 1e3 * cpu[0]);
    bench_target_add(ctx, "a 1e5-row non-conical table, both types and baselines (<= 2 s CPU)",
                     isfinite(cpu[8]) ? cpu[8] <= 2 : -1, "%.3g s CPU", cpu[8]);
    bench_target_add(ctx, "a 1e6-row non-conical table (<= 15 s CPU)",
                     isfinite(cpu[9]) ? cpu[9] <= 15 : -1, "%.3g s CPU", cpu[9]);
    bench_target_add(ctx, "no length from 100 to 1e6 rows costs more than a longer one",
                     cliff <= 1.1, "worst ratio %.2f at %zu rows (1.1 allowed for timing noise)",
                     cliff, at);
    bench_target_add(ctx, "`--target lattice --validate` on the 2592-row raw table (<= 3 s CPU)",
                     isfinite(ccpu[1]) ? ccpu[1] <= 3 : -1, "%.3g s CPU", ccpu[1]);
    bench_target_add(ctx, "the 268-row relaxation series, default fit (<= 10 s CPU)",
                     isfinite(ccpu[2]) ? ccpu[2] <= 10 : -1, "%.3g s CPU", ccpu[2]);
    bench_target_add(ctx, "the shipped muscle series (<= 5 s CPU each)",
                     isfinite(ccpu[3]) && isfinite(ccpu[4]) ? fmax(ccpu[3], ccpu[4]) <= 5 : -1,
                     "%.3g and %.3g s CPU", ccpu[3], ccpu[4]);
}
