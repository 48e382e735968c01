/*
** Benchmark section: start-up. What a run of the command costs before it does anything
** (`conifit --version`: the loader, the libraries' constructors) and the whole fit of a small
** table, as child processes: CPU time (user + system, from wait4) and wall time, median of
** repeated runs. The sparse solvers and what they pull in (BLAS, LAPACK, the Fortran runtime)
** and Gmsh are opened at their first use (src/model/sparse_dl.c, src/io/mesh.c), so neither run
** loads them; src/notes/performance.md has the numbers from before.
*/
#include <stdlib.h>
#include <stdio.h>
#include <sys/resource.h>
#include <unistd.h>

#include "bench.h"

/* CPU and wall time, ms, of reps runs of argv: medians and spreads. -1 when a run fails. */
static int time_runs(char *const argv[], int reps, bench_stats *cpu, bench_stats *wall)
{
    double *c = malloc((size_t)reps * sizeof *c), *w = malloc((size_t)reps * sizeof *w);
    int ok = c && w;
    for (int r = 0; ok && r < reps; r++) {
        struct rusage ru;
        const double t0 = bench_now();
        ok = bench_exec(argv, &ru) == 0;
        w[r] = 1e3 * (bench_now() - t0);
        c[r] = 1e3 * ((double)ru.ru_utime.tv_sec + (double)ru.ru_stime.tv_sec) +
               1e-3 * ((double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_usec);
    }
    if (ok) {
        *cpu = bench_summarise(c, reps);
        *wall = bench_summarise(w, reps);
    }
    free(c);
    free(w);
    return ok ? 0 : -1;
}

void bench_section_startup(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    const char *env = getenv("CONIFIT");
    char exe[1024], out[1100];
    snprintf(exe, sizeof exe, "%s", env && *env ? env : "build/conifit");
    snprintf(out, sizeof out, "%s/startup-%ld.json", ctx->dir, (long)getpid());
    fprintf(md, "## Start-up\n\n"
                "The command run as a child process (tests/bench/bench_startup.c): CPU time (user + "
                "system) and wall time in ms, median of the runs [min–max]. `--version` is the "
                "start-up alone (the loader and the libraries' constructors); the fits are whole "
                "runs of `conifit fit TABLE -o FILE` (report, baselines, fit file). The sparse "
                "solvers and Gmsh are opened at their first use, so none of these loads them.\n\n"
                "| run | runs | CPU, ms | wall, ms |\n|---|---|---|---|\n");
    static const struct {
        const char *what, *table;
    } cases[] = {{"`conifit --version`", NULL},
                 {"fit of a 17-row table (brain cortex, tension)",
                  "../shared/datasets/brain_cortex_tension.csv"},
                 {"fit of a 47-row table (data/non_telescoping.csv)", "data/non_telescoping.csv"}};
    const int reps = ctx->quick ? 5 : 41;
    double version_cpu = -1;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        if (cases[k].table && access(cases[k].table, R_OK) != 0) {
            fprintf(md, "| %s | – | table absent here, skipped | – |\n", cases[k].what);
            continue;
        }
        char *fit_argv[] = {exe, "fit", (char *)cases[k].table, "-o", out, NULL};
        char *version_argv[] = {exe, "--version", NULL};
        bench_stats c, w;
        if (time_runs(cases[k].table ? fit_argv : version_argv, cases[k].table ? reps / 2 + 1 : reps,
                      &c, &w) != 0) {
            fprintf(md, "| %s | – | the run failed | – |\n", cases[k].what);
            continue;
        }
        if (!cases[k].table)
            version_cpu = c.median;
        fprintf(md, "| %s | %d | **%.2f** [%.2f–%.2f] | %.2f [%.2f–%.2f] |\n", cases[k].what,
                c.repeats, c.median, c.min, c.max, w.median, w.min, w.max);
    }
    remove(out);
    fprintf(md, "\n");
    if (version_cpu >= 0)
        bench_target_add(ctx, "start-up: `conifit --version` within 15 ms of CPU (13-34 ms with the "
                              "sparse solvers linked, by load: src/notes/performance.md)",
                         version_cpu <= 15, "%.2f ms", version_cpu);
}
