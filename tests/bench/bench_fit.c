/*
** Benchmark section 4: fitting. For each stage-C optimiser and a few parameter tolerances, the RMSE
** each spring type reaches, the model evaluations and the wall time, on every shipped table in
** data/ and on the published tables in ../shared/datasets/ when that folder is present; and the
** time target on a 100-point table.
*/
#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "fit/fit.h"
#include "io/measure.h"
#include "check/validate.h"

static const cf_fit_optimizer optimizers[] = {CF_OPT_SLSQP, CF_OPT_COBYLA, CF_OPT_MMA};
#define NOPT 3
static const double xtols[] = {1e-4, 1e-8, 1e-12};
#define NTOL 3
#define NCFG (NOPT * NTOL)

/* One fit, timed: the result of the last repeat and the time summary. */
typedef struct fit_cell {
    cf_status st;
    double rmse;        /* in the table's own unit */
    long evals;
    int feasible;
    bench_stats ms;
} fit_cell;

static int is_csv(const struct dirent *e)
{
    size_t n = strlen(e->d_name);
    return n > 4 && strcmp(e->d_name + n - 4, ".csv") == 0;
}

/* Fits (data, opt, type) `repeats` times; the result comes from the last run. */
static fit_cell time_fit(const cf_table *d, const cf_fit_options *opt, cf_spring_type type,
                         double y_to_file, int repeats)
{
    fit_cell c = {0};
    double t[16];
    for (int r = 0; r < repeats; r++) {
        cf_fit_result res;
        cf_error err = {0};
        double t0 = bench_now();
        c.st = cf_fit_run(d, opt, type, &res, &err);
        t[r] = (bench_now() - t0) * 1e3;
        if (c.st != CF_OK)
            return c;
        c.rmse = res.rmse * y_to_file;
        c.evals = res.evaluations;
        c.feasible = res.feasible;
        cf_law_free(&res.law);
    }
    c.ms = bench_summarise(t, repeats);
    return c;
}

static void print_cell(FILE *md, const fit_cell *c)
{
    if (c->st != CF_OK)
        fprintf(md, " failed (%s) | – | – |", cf_strerror(c->st));
    else
        fprintf(md, " %.3g%s | %ld | %.1f [%.1f–%.1f] |", c->rmse, c->feasible ? "" : " (infeasible)",
                c->evals, c->ms.median, c->ms.min, c->ms.max);
}

/* Summary accumulators per optimiser/tolerance. */
typedef struct cfg_sum {
    double ms_total;   /* sum of median times, ms */
    long evals_total;
    int best_count;    /* fits within 1 % of the best RMSE any configuration reached on that table */
    int fits, failed;
    double worst_ratio; /* largest RMSE / best RMSE */
} cfg_sum;

/* Benchmarks every table in folder dir (label for the report); returns the number of tables. */
static int bench_folder(bench_ctx *ctx, const char *dir, const char *label, int repeats,
                        cfg_sum sum[NCFG], FILE *dat)
{
    struct dirent **names = NULL;
    int n = scandir(dir, &names, is_csv, alphasort);
    if (n < 0)
        return -1;
    for (int f = 0; f < n; f++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, names[f]->d_name);
        cf_table m;
        cf_error err = {0};
        cf_measure_options mo = cf_measure_default_options();
        if (cf_measure_load(path, &mo, &m, &err) != CF_OK) {
            fprintf(ctx->md, "| %s/%s | could not be read: %s | | | | | | | |\n", label,
                    names[f]->d_name, err.msg);
            free(names[f]);
            continue;
        }
        cf_table d = m; /* the same arrays; m owns them */
        fit_cell cell[NCFG][2];
        double best[2] = {INFINITY, INFINITY};
        for (int o = 0; o < NOPT; o++)
            for (int k = 0; k < NTOL; k++) {
                cf_fit_options opt = cf_fit_default_options();
                opt.optimizer = optimizers[o];
                opt.xtol_rel = xtols[k];
                for (int t = 0; t < 2; t++) {
                    fit_cell *c = &cell[o * NTOL + k][t];
                    *c = time_fit(&d, &opt, (cf_spring_type)t, m.y_to_file, repeats);
                    if (c->st == CF_OK && c->feasible)
                        best[t] = fmin(best[t], c->rmse);
                }
            }
        for (int c = 0; c < NCFG; c++) {
            fprintf(ctx->md, "| %s/%s (%zu) | %s | %.0e |", label, names[f]->d_name, m.count,
                    cf_fit_optimizer_name(optimizers[c / NTOL]), xtols[c % NTOL]);
            for (int t = 0; t < 2; t++) {
                const fit_cell *fc = &cell[c][t];
                print_cell(ctx->md, fc);
                sum[c].fits++;
                if (fc->st != CF_OK || !fc->feasible) {
                    sum[c].failed++;
                    continue;
                }
                sum[c].ms_total += fc->ms.median;
                sum[c].evals_total += fc->evals;
                double ratio = best[t] > 0 ? fc->rmse / best[t] : 1.0;
                if (fc->rmse <= best[t] * 1.01 || fc->rmse == best[t])
                    sum[c].best_count++;
                sum[c].worst_ratio = fmax(sum[c].worst_ratio, ratio);
                if (dat)
                    fprintf(dat, "%d %.6g %.6g\n", c / NTOL, fc->ms.median,
                            fmax(ratio - 1.0, 1e-6));
            }
            fprintf(ctx->md, " %s |\n", m.y_unit);
        }
        cf_table_free(&m);
        free(names[f]);
    }
    free(names);
    return n;
}

/* The 100-point target: a table synthesised from a documented telescoping spring (the one behind
** data/telescoping.csv), strains uniform up to 0.55, exact or with 1 % seeded noise. */
static void synth_table(double *x, double *y, size_t n, double noise)
{
    cf_spring p = {8, 20, 2.5, 2, 100, 5};
    cf_law law;
    cf_law_init(&law, &p, NULL);
    unsigned long s = 12345;
    for (size_t i = 0; i < n; i++) {
        x[i] = 0.55 * (double)(i + 1) / (double)n;
        y[i] = cf_fit_model(&law, 0, x[i]);
        s = s * 6364136223846793005UL + 1442695040888963407UL;
        double r = (double)(s >> 11) / 9007199254740992.0 * 2.0 - 1.0;
        y[i] *= 1.0 + noise * r;
    }
    cf_law_free(&law);
}

/* Single-spring fit against fit through the lattice on one shipped table: the validation RMSE
** each reaches and what it costs, for lattices of 1, 2 and 3 cells a side (face and body
** diagonals, bottom axial). The 3-cell run is long (tens of seconds) and is run once. */
static void through_lattice(bench_ctx *ctx)
{
    const char *path = "data/telescoping_noise1pct.csv";
    cf_table m;
    cf_error err = {0};
    cf_measure_options mo = cf_measure_default_options();
    fprintf(ctx->md, "**Single-spring fit against fit through the lattice** (`conifit fit "
                     "--through-msm`), `%s`, telescoping, lattices of n × n × n cells with face "
                     "and body diagonals, bottom axial. Time of the ordinary fit plus its "
                     "validation, and of the fit through the lattice on top of it; validation "
                     "RMSE in kPa. Median of the runs given [min–max].\n\n",
            path);
    if (cf_measure_load(path, &mo, &m, &err) != CF_OK) {
        fprintf(ctx->md, "(not measured: %s)\n\n", err.msg);
        return;
    }
    cf_table d = m; /* the same arrays; m owns them */
    cf_fit_options opt = cf_fit_default_options();
    fprintf(ctx->md, "| lattice | runs | fit RMSE (one spring) | validation RMSE, ordinary fit | "
                     "fit + validation, s | validation RMSE, through the lattice | through the "
                     "lattice, s | lattice curves |\n|---|---|---|---|---|---|---|---|\n");
    const int nmax = ctx->quick ? 1 : 3;
    for (int n = 1; n <= nmax; n++) {
        const int runs = (n < 3) ? (ctx->quick ? 1 : 3) : 1;
        double t_plain[3], t_msm[3];
        double fit_rmse = NAN, rmse0 = NAN, rmse1 = NAN;
        long evals = 0;
        int ok = 1;
        for (int r = 0; r < runs && ok; r++) {
            cf_validate_setup vs = cf_validate_default();
            vs.cfg.lattice.nx = vs.cfg.lattice.ny = vs.cfg.lattice.nz = n;
            cf_fit_result res;
            cf_validation v = {0};
            cf_through_msm t = {0};
            double t0 = bench_now();
            ok = cf_fit_run(&d, &opt, CF_TELESCOPING, &res, &err) == CF_OK &&
                 cf_validate_run(&res.params, &vs, &d, &v, &err) == CF_OK;
            t_plain[r] = bench_now() - t0;
            if (ok) {
                fit_rmse = res.rmse * m.y_to_file;
                t0 = bench_now();
                ok = cf_lattice_fit(&d, &opt, &vs, &res, &t, &err) == CF_OK &&
                     cf_validate_lattice_fit(&d, &vs, &res, &v, &t, &err) == CF_OK;
                t_msm[r] = bench_now() - t0;
                rmse0 = t.rmse_before * m.y_to_file;
                rmse1 = t.rmse_after * m.y_to_file;
                evals = t.evaluations;
            }
            cf_validation_free(&v);
            cf_law_free(&res.law);
        }
        if (!ok) {
            fprintf(ctx->md, "| %d³ | – | failed: %s |||||\n", n, err.msg);
            continue;
        }
        bench_stats a = bench_summarise(t_plain, runs), b = bench_summarise(t_msm, runs);
        fprintf(ctx->md, "| %d³ | %d | %.3g | %.3g | %.3g [%.3g–%.3g] | %.3g | %.3g [%.3g–%.3g] | "
                         "%ld |\n",
                n, runs, fit_rmse, rmse0, a.median, a.min, a.max, rmse1, b.median, b.min, b.max,
                evals);
    }
    fprintf(ctx->md, "\n");
    cf_table_free(&m);
}

void bench_section_fit(bench_ctx *ctx)
{
    const int repeats = ctx->quick ? 1 : 3;
    const int trepeats = ctx->quick ? 3 : 11;
    fprintf(ctx->md,
            "## 4. Fitting: optimiser and tolerance against RMSE, evaluations and time\n\n");

    /* the time target first: both types of a 100-point table, default options */
    enum { NP = 100 };
    double x[NP], y[NP];
    double both_ms[2] = {0, 0};
    bench_stats both[2];
    const char *tname[2] = {"exact", "1 % noise"};
    double rm[2][2];
    for (int v = 0; v < 2; v++) {
        synth_table(x, y, NP, v ? 0.01 : 0.0);
        cf_table d = {.count = NP, .x = x, .y = y};
        cf_fit_options opt = cf_fit_default_options();
        double t[16];
        for (int r = 0; r < trepeats; r++) {
            double t0 = bench_now();
            for (int ty = 0; ty < 2; ty++) {
                cf_fit_result res;
                if (cf_fit_run(&d, &opt, (cf_spring_type)ty, &res, NULL) == CF_OK) {
                    rm[v][ty] = res.rmse * 1e3;
                    cf_law_free(&res.law);
                } else
                    rm[v][ty] = NAN;
            }
            t[r] = (bench_now() - t0) * 1e3;
        }
        both[v] = bench_summarise(t, trepeats);
        both_ms[v] = both[v].median;
    }
    const double fit100_ms = fmax(both_ms[0], both_ms[1]);
    fprintf(ctx->md,
            "**Time target: both spring types of a 100-point table.** Table synthesised from the "
            "telescoping spring behind `data/telescoping.csv` (D1 8, D2 20, n 2.5, d 2 mm, G 100 "
            "MPa, H 5 mm), 100 strains uniform up to 0.55; default options (SLSQP, xtol_rel "
            "1e-12, 8 starts); the telescoping and the non-telescoping fit one after the other, "
            "median of %d runs [min–max]:\n\n"
            "| table | both types, ms | RMSE telescoping, kPa | RMSE non-telescoping, kPa |\n"
            "|---|---|---|---|\n",
            trepeats);
    for (int v = 0; v < 2; v++)
        fprintf(ctx->md, "| 100 points, %s | %.1f [%.1f–%.1f] | %.3g | %.3g |\n", tname[v],
                both[v].median, both[v].min, both[v].max, rm[v][0], rm[v][1]);
    fprintf(ctx->md,
            "\nTarget \"well under 100 ms\" (read here as at most 50 ms): %s (%.1f ms, the "
            "slower of the two).\n\n",
            fit100_ms <= 50 ? "**met**" : "**not met**", fit100_ms);
    bench_target_add(ctx, "both fit types of a 100-point table well under 100 ms (≤ 50 ms)",
                     fit100_ms <= 50, "%.1f ms (exact table %.1f ms, 1 %% noise %.1f ms)",
                     fit100_ms, both_ms[0], both_ms[1]);

    /* the grid of optimisers and tolerances */
    fprintf(ctx->md,
            "**Optimiser and tolerance on every table.** Each table is fitted as a stress-strain "
            "(or force-displacement) table with default options except the stage-C optimiser and "
            "`xtol_rel` (which also sets the Levenberg-Marquardt tolerance of stage A). RMSE in the "
            "table's own unit (last column), the model evaluations over the table (all stages), "
            "and the wall time of one fit in ms: median of %d runs [min–max]. \"(n)\" after a "
            "table is its number of points.\n\n",
            repeats);
    fprintf(ctx->md,
            "| table | optimiser | xtol_rel | telescoping RMSE | evals | ms | non-telescoping "
            "RMSE | evals | ms | unit |\n|---|---|---|---|---|---|---|---|---|---|\n");
    cfg_sum sum[NCFG];
    memset(sum, 0, sizeof sum);
    FILE *dat = bench_open_data(ctx, "fit_tradeoff.dat");
    int nship = bench_folder(ctx, "data", "data", repeats, sum, dat);
    int nshared = bench_folder(ctx, "../shared/datasets", "datasets", repeats, sum, dat);
    if (dat)
        fclose(dat);
    fprintf(ctx->md, "\n");
    if (nship < 0)
        fprintf(ctx->md, "The shipped tables (data/) were not found: run from the repository "
                         "root.\n\n");
    if (nshared < 0)
        fprintf(ctx->md, "The published tables (`../shared/datasets/`) are absent on this "
                         "machine: those rows are skipped.\n\n");
    else
        fprintf(ctx->md, "`datasets/` rows are the published tables of `../shared/datasets/` "
                         "(%d tables; their README gives the sources).\n\n",
                nshared);

    through_lattice(ctx);
    fprintf(ctx->md,
            "Summary over all tables and both types (a fit \"reaches the best\" when its RMSE is "
            "within 1 %% of the lowest RMSE any optimiser/tolerance reached on that table and "
            "type; infeasible or failed fits are counted apart):\n\n"
            "| optimiser | xtol_rel | total time, ms | evaluations | reaches the best | worst "
            "RMSE / best | failed or infeasible |\n|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < NCFG; c++)
        fprintf(ctx->md, "| %s | %.0e | %.0f | %ld | %d of %d | %.3g | %d |\n",
                cf_fit_optimizer_name(optimizers[c / NTOL]), xtols[c % NTOL], sum[c].ms_total,
                sum[c].evals_total, sum[c].best_count, sum[c].fits - sum[c].failed,
                sum[c].worst_ratio, sum[c].failed);
    fprintf(ctx->md, "\n");
    if (bench_gnuplot(ctx,
                      "set terminal pngcairo size 800,500\n"
                      "set output 'fit_tradeoff.png'\n"
                      "set logscale xy\nset grid\nset key top right\n"
                      "set xlabel 'time of one fit [ms]'\n"
                      "set ylabel 'RMSE / best RMSE on that table - 1 (floored at 1e-6)'\n"
                      "set title 'Fitting: every table, type and tolerance'\n"
                      "plot 'fit_tradeoff.dat' using ($1==0?$2:1/0):3 with points pt 7 "
                      "title 'slsqp', '' using ($1==1?$2:1/0):3 with points pt 5 title "
                      "'cobyla', '' using ($1==2?$2:1/0):3 with points pt 9 title 'mma'\n") ==
        0)
        fprintf(ctx->md, "![fitting: RMSE against time](fit_tradeoff.png)\n\n");
}
