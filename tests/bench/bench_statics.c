/*
** Benchmark section 9: statics at scale. The shipped uniaxial scene (data/scenes/uniaxial.json:
** its spring, the default lattice, compression to a strain of 0.45 in 45 static solves), resized
** to n³ cells: wall time and peak memory of the whole curve, each size in a forked child (peak
** resident set from wait4), the sparse solver against the banded LDL^T it replaced and the curve
** against Newton with a fresh tangent at every iteration at small sizes, and the growth exponents.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench.h"
#include "model/msm.h"

enum { NSTRAIN = 45, NOUT = 5 + NSTRAIN };

/* How a run solves: cf_msm_uniaxial on the sparse factorisations (reused: chord and Krylov
** steps), on the banded LDL^T, or cf_msm_run (a fresh sparse factorisation every iteration). */
enum { RUN_SPARSE, RUN_BANDED, RUN_FRESH };

typedef struct sresult {
    double seconds;
    double cpu_seconds; /* user + system time of the child (wait4) */
    double factorisations, chord, indefinite, neg_max;
    int ok;
    long maxrss_kb;
    double stress[NSTRAIN]; /* the curve, MPa, in the table's sign */
} sresult;

/* The curve by cf_msm_run with a displacement drive: Newton with a fresh tangent at every
** iteration (the static solver of scenes); stresses in the table's sign into s. */
static int fresh_curve(const cf_law *law, const cf_msm_config *cfg, double *s, cf_msm_stats *st)
{
    cf_lattice lat;
    if (cf_lattice_create(&lat, law, CF_LAW_CLOSED, &cfg->lattice, NULL) != CF_OK)
        return 0;
    const double t[2] = {0, 1}, v[2] = {0, 0.01 * NSTRAIN};
    const cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 2, t, v};
    double ts[NSTRAIN];
    cf_msm_sample out[NSTRAIN];
    for (int i = 0; i < NSTRAIN; i++)
        ts[i] = (i + 1) / (double)NSTRAIN;
    const int ok = cf_msm_run(&lat, NULL, cfg, &path, ts, NSTRAIN, out, NULL, st, NULL) == CF_OK;
    for (int i = 0; ok && i < NSTRAIN; i++)
        s[i] = -out[i].stress_MPa;
    cf_lattice_free(&lat);
    return ok;
}

/* Runs the resized scene in a child; fills r (ok = 0 on failure). */
static void run_scene(int n, int mode, sresult *r)
{
    memset(r, 0, sizeof *r);
    int fd[2];
    if (pipe(fd) != 0)
        return;
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return;
    }
    if (pid == 0) {
        close(fd[0]);
        const cf_spring p = {6, 15, 2.5, 2, 26, 10};
        cf_law law;
        cf_msm_config cfg = cf_msm_default();
        cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = n;
        cfg.banded_only = mode == RUN_BANDED;
        double e[NSTRAIN];
        for (int i = 0; i < NSTRAIN; i++)
            e[i] = -0.01 * (i + 1);
        cf_msm_stats st;
        double out[NOUT] = {-1, 0, 0, 0, 0};
        if (cf_law_init(&law, &p, NULL) == CF_OK) {
            double t0 = bench_now();
            if (mode == RUN_FRESH ? fresh_curve(&law, &cfg, out + 5, &st)
                                  : cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, e, NSTRAIN, out + 5,
                                                    &st, NULL) == CF_OK) {
                out[0] = bench_now() - t0;
                out[1] = (double)st.linear_iters;
                out[2] = (double)st.indefinite_tangents;
                out[3] = (double)st.neg_pivots_max;
                out[4] = (double)st.chord_iters;
            }
        }
        ssize_t w = write(fd[1], out, sizeof out);
        _exit(w == (ssize_t)sizeof out ? 0 : 1);
    }
    close(fd[1]);
    double in[NOUT] = {-1, 0, 0, 0, 0};
    ssize_t got = read(fd[0], in, sizeof in);
    close(fd[0]);
    int status;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
        got != (ssize_t)sizeof in || in[0] < 0)
        return;
    r->ok = 1;
    r->seconds = in[0];
    r->factorisations = in[1];
    r->indefinite = in[2];
    r->neg_max = in[3];
    r->chord = in[4];
    memcpy(r->stress, in + 5, sizeof r->stress);
    r->cpu_seconds = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                     (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    r->maxrss_kb = ru.ru_maxrss;
}

/* Least-squares slope of log y against log x over the points with x >= xmin. */
static double slope(const double *x, const double *y, int m, double xmin)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int k = 0;
    for (int i = 0; i < m; i++)
        if (x[i] >= xmin && y[i] > 0) {
            double lx = log(x[i]), ly = log(y[i]);
            sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
            k++;
        }
    return k >= 2 ? (k * sxy - sx * sy) / (k * sxx - sx * sx) : NAN;
}

/* Measured by bench_statics_early, written by bench_section_statics. The runs fork, and a child
** forked after the parent has used OpenMP threads (section 2 does) can hang in the OpenMP runtime
** that CHOLMOD uses, so they run before any other section. */
static struct {
    int measured;
    double budget;
    sresult res[9], band[3], fresh[4];
    double cells[9], secs[9], mem[9];
    int m, skipped_from;
    double predicted;
} S;
static const int full_sizes[] = {3, 4, 6, 8, 10, 12, 16, 20, 24};
static const int quick_sizes[] = {3, 4, 6};
/* the sizes where the curve is compared with fresh Newton (that path factors at every iteration) */
enum { NFRESH_FULL = 4, NFRESH_QUICK = 3 };

/* Largest |a - b| / |b| over the curve. */
static double curve_dist(const sresult *a, const sresult *b)
{
    double d = 0;
    for (int i = 0; i < NSTRAIN; i++)
        d = fmax(d, fabs(a->stress[i] - b->stress[i]) / fabs(b->stress[i]));
    return d;
}

void bench_statics_early(bench_ctx *ctx)
{
    const int *sizes = ctx->quick ? quick_sizes : full_sizes;
    const int nsz = ctx->quick ? 3 : 9;
    /* the heavy sizes run once (the targets' sizes three times) and only while the predicted time
    ** fits the budget (seconds) */
    const char *b = getenv("CONIFIT_BENCH_STATICS_BUDGET_S");
    const double budget = b ? atof(b) : (ctx->quick ? 30 : 900);
    sresult *res = S.res, *band = S.band;
    double *cells = S.cells, *secs = S.secs, *mem = S.mem;
    int m = 0;
    double spent = 0, expo = 6; /* growth exponent in cells, updated as sizes come in */
    int skipped_from = -1;
    double predicted = 0;
    for (int z = 0; z < nsz; z++) {
        if (m >= 2)
            expo = slope(cells, secs, m, 0) > 0 ? slope(cells, secs, m, 0) : expo;
        if (m > 0) {
            predicted = secs[m - 1] * pow(pow(sizes[z], 3) / cells[m - 1], expo);
            if (spent + predicted > budget) {
                skipped_from = z;
                break;
            }
        }
        const int reps = sizes[z] <= 6 || sizes[z] == 16 || sizes[z] == 24 ? 3 : 1;
        sresult r[3];
        double wall[3], cpu[3];
        int ok = 1;
        for (int q = 0; q < reps; q++) {
            run_scene(sizes[z], RUN_SPARSE, &r[q]);
            ok = ok && r[q].ok;
            wall[q] = r[q].seconds;
            cpu[q] = r[q].cpu_seconds;
        }
        if (!ok)
            break;
        /* medians of the wall and of the CPU times, the rest from the first run */
        res[z] = r[0];
        res[z].seconds = bench_summarise(wall, reps).median;
        res[z].cpu_seconds = bench_summarise(cpu, reps).median;
        for (int q = 0; q < reps; q++)
            spent += r[q].seconds;
        cells[m] = pow(sizes[z], 3);
        secs[m] = res[z].seconds;
        mem[m] = (double)res[z].maxrss_kb;
        m++;
    }
    for (int z = 0; z < (ctx->quick ? NFRESH_QUICK : NFRESH_FULL); z++)
        run_scene(sizes[z], RUN_FRESH, &S.fresh[z]);
    for (int z = 0; z < 3 && z < nsz; z++) {
        sresult r[3];
        for (int q = 0; q < 3; q++)
            run_scene(sizes[z], RUN_BANDED, &r[q]);
        double t[3] = {r[0].seconds, r[1].seconds, r[2].seconds};
        bench_stats bs = bench_summarise(t, 3);
        band[z] = r[0];
        band[z].seconds = r[0].ok && r[1].ok && r[2].ok ? bs.median : -1;
    }
    S.measured = 1;
    S.budget = budget;
    S.m = m;
    S.skipped_from = skipped_from;
    S.predicted = predicted;
}

void bench_section_statics(bench_ctx *ctx)
{
    if (!S.measured)
        bench_statics_early(ctx);
    const int *sizes = ctx->quick ? quick_sizes : full_sizes;
    const int nsz = ctx->quick ? 3 : 9;
    const double budget = S.budget, predicted = S.predicted;
    const sresult *res = S.res, *band = S.band;
    const double *cells = S.cells, *secs = S.secs, *mem = S.mem;
    const int m = S.m, skipped_from = S.skipped_from;
    const double ex_t = slope(cells, secs, m, 200), ex_m = slope(cells, mem, m, 200);
    fprintf(ctx->md,
            "## 9. Statics at scale\n\n"
            "The shipped uniaxial scene (`data/scenes/uniaxial.json`: its spring, the default "
            "lattice with the isotropic calibration, bottom sliding, compression to a strain of "
            "0.45 in 45 static solves, closed form) resized to n³ cells, through "
            "`cf_msm_uniaxial`. Each run in a forked child: wall time of the whole curve (median "
            "of 3 up to 6³ and at 16³ and 24³, one run otherwise), its CPU time (user + system, "
            "median likewise; below the wall time when other work shares the cores) and its peak "
            "resident set. Newton tangents: sparse Cholesky (CHOLMOD supernodal LLᵀ), indefinite "
            "ones by MUMPS's LDLᵀ. A uniaxial curve reuses factorisations: each load step starts "
            "from the secant prediction (the last converged increment, scaled), then takes chord "
            "steps with the last factored tangent while each cuts the residual 4× at full length, "
            "then Krylov steps (GMRES on the current tangent preconditioned by those factors, "
            "solved as far as the step needs), and factors a fresh tangent only when GMRES needs "
            "more than 16 steps. \"Factorisations\" counts the tangents factored, \"reused\" "
            "the Newton iterations that reused one (chord or Krylov steps), \"indefinite\" the "
            "factored tangents with negative pivots and \"most negative pivots\" the largest "
            "count among them (the curve's later, unstable states are no longer factored, so "
            "these say little about the curve). Budget for the section: %.0f s; sizes whose "
            "predicted time (from the growth so far) does not fit are not run.\n\n"
            "| cells | unknowns (about) | time, s | CPU, s | peak memory, MiB | factorisations | "
            "reused | indefinite | most negative pivots |\n"
            "|---|---|---|---|---|---|---|---|---|\n",
            budget);
    FILE *dat = bench_open_data(ctx, "statics.dat");
    int done = 0;
    for (int z = 0; z < nsz && res[z].ok && (skipped_from < 0 || z < skipped_from); z++) {
        int n = sizes[z];
        fprintf(ctx->md, "| %d³ | %d | %.3g | %.3g | %.1f | %.0f | %.0f | %.0f | %.0f |\n", n,
                3 * (n + 1) * (n + 1) * n, res[z].seconds, res[z].cpu_seconds,
                res[z].maxrss_kb / 1024.0, res[z].factorisations, res[z].chord, res[z].indefinite,
                res[z].neg_max);
        if (dat)
            fprintf(dat, "%d %.6g %.6g\n", n * n * n, res[z].seconds, res[z].maxrss_kb / 1024.0);
        done = z + 1;
    }
    if (dat)
        fclose(dat);
    if (skipped_from >= 0)
        fprintf(ctx->md, "| %d³ | – | not run: predicted %.0f s | – | – | – | – | – | – |\n",
                sizes[skipped_from], predicted);
    fprintf(ctx->md,
            "\n**Growth** (least squares over the sizes from 6³ on): time ∝ cells^%.2f, peak "
            "memory ∝ cells^%.2f (the banded LDLᵀ it replaced grew as cells^6 in time and "
            "cells^5 in memory, since its bandwidth grows as cells^(2/3)).\n\n",
            ex_t, ex_m);
    fprintf(ctx->md, "**Against the banded LDLᵀ** (median of 3, same scene; the banded path "
                     "factors at every Newton iteration):\n\n| cells | sparse, s | banded, s |\n"
                     "|---|---|---|\n");
    for (int z = 0; z < 3 && z < done; z++)
        fprintf(ctx->md, "| %d³ | %.3g | %.3g |\n", sizes[z], res[z].seconds, band[z].seconds);
    fprintf(ctx->md, "\n**Against fresh Newton** (one run each, same scene): the curve of "
                     "`cf_msm_run` with a displacement drive, the static solver of scenes, which "
                     "factors a fresh tangent at every Newton iteration and predicts each load step "
                     "by the affine strain; both stop at the same tolerance (residual 1e-11 of the "
                     "force scale).\n\n| cells | reused factors, s | fresh Newton, s | "
                     "factorisations (reused / fresh) | largest relative stress difference |\n"
                     "|---|---|---|---|---|\n");
    for (int z = 0; z < (ctx->quick ? NFRESH_QUICK : NFRESH_FULL) && z < done; z++)
        if (S.fresh[z].ok)
            fprintf(ctx->md, "| %d³ | %.3g | %.3g | %.0f / %.0f | %.2g |\n", sizes[z],
                    res[z].seconds, S.fresh[z].seconds, res[z].factorisations,
                    S.fresh[z].factorisations, curve_dist(&res[z], &S.fresh[z]));
    fprintf(ctx->md, "\n");
    /* targets */
    for (int q = 0; q < 2; q++) {
        const int want = q ? 24 : 16;
        const double limit = q ? 60 : 30;
        int z = -1;
        for (int k = 0; k < done; k++)
            if (sizes[k] == want)
                z = k;
        char name[120];
        snprintf(name, sizeof name, "uniaxial scene statics at %d³ cells (<= %.0f s CPU)", want,
                 limit);
        if (z >= 0)
            bench_target_add(ctx, name, res[z].cpu_seconds <= limit, "%.3g s CPU, %.3g s wall "
                             "(%.0f MiB, %.0f factorisations, %.0f reused)", res[z].cpu_seconds,
                             res[z].seconds, res[z].maxrss_kb / 1024.0,
                             res[z].factorisations, res[z].chord);
        else if (m > 0)
            bench_target_add(ctx, name, 0, "not run within the benchmark's budget; predicted "
                             "%.0f s from %d³ (%.3g s) and the growth exponent %.2f",
                             secs[m - 1] * pow(pow(want, 3) / cells[m - 1], ex_t > 0 ? ex_t : 2),
                             sizes[m - 1], secs[m - 1], ex_t);
    }
    if (done >= 2 && bench_gnuplot(ctx, "set terminal pngcairo size 800,500\n"
                                        "set output 'statics.png'\n"
                                        "set logscale xy\nset grid\nset key left top\n"
                                        "set xlabel 'cells'\nset ylabel 'time [s] / memory [MiB]'\n"
                                        "set title 'Uniaxial statics: time and peak memory'\n"
                                        "plot 'statics.dat' using 1:2 with linespoints pt 7 "
                                        "title 'time, s', '' using 1:3 with linespoints pt 5 "
                                        "title 'peak memory, MiB'\n") == 0)
        fprintf(ctx->md, "![statics: time and memory against cells](statics.png)\n\n");
}
