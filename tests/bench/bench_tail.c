/*
** Benchmark section: the spring with a cylindrical tail (law family conical-tail). The time of one
** evaluation of each evaluator and its largest error against `exact`, beside the plain spring of
** the same coils; and the lattice's explicit step with tailed springs (the spring's polynomial, and
** the scalar law through cf_law_force_many) against the plain spring's (its polynomial, and the
** law's batch call).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "model/lattice.h"
#include "model/law_internal.h"
#include "model/lattice_step.h"

/* The export tests' telescoping spring, and the same cone in 30 mm with one tail coil in 10 mm
** (rho = 1/3, tau = 0.25, beta = 0.5; u_T 11.0, u_C 36.25, solid at 38 mm). */
static const cf_spring plain_spring = {10, 30, 4, 1, 80000, 40};
static const cf_spring tail_spring = {10, 30, 4, 1, 80000, 40, 1, 10};

typedef struct tvariant {
    const char *name;
    cf_law_method method;
} tvariant;

static const tvariant tvars[] = {{"exact", CF_LAW_EXACT},
                                 {"closed", CF_LAW_CLOSED},
                                 {"closed+newton", CF_LAW_CLOSED_NEWTON},
                                 {"table 256", CF_LAW_TABLE}};
#define NTV (sizeof tvars / sizeof tvars[0])

/* Region 2 of the law, uniform in u and crowded at both of its ends. */
static size_t region2(const cf_law *law, double *u, size_t n)
{
    const double a = law->u_T_mm, b = law->u_C_mm;
    for (size_t k = 0; k < n; k++) {
        const double x = (double)(k + 1) / (double)(n + 1);
        const double xx = (k % 3 == 0) ? x : (k % 3 == 1) ? 1 - pow(1 - x, 4) : pow(x, 4);
        u[k] = a + (b - a) * xx;
    }
    return n;
}

/* Median ns per evaluation of cf_law_force over u. */
static bench_stats time_eval(const cf_law *law, cf_law_method m, const double *u, size_t n,
                             int repeats)
{
    double t[15];
    for (int r = 0; r < repeats; r++) {
        double acc = 0, t0 = bench_cpu_now();
        for (size_t i = 0; i < n; i++)
            acc += cf_law_force(law, m, u[i], NULL, NULL);
        t[r] = (bench_cpu_now() - t0) / (double)n * 1e9;
        bench_sink += acc;
    }
    return bench_summarise(t, repeats);
}

/* Largest |F - F_exact| over u, as a fraction of F_C. */
static double max_error(const cf_law *law, cf_law_method m, const double *u, size_t n)
{
    double worst = 0;
    for (size_t i = 0; i < n; i++) {
        const double F = cf_law_force(law, m, u[i], NULL, NULL);
        const double E = cf_law_force(law, CF_LAW_EXACT, u[i], NULL, NULL);
        worst = fmax(worst, fabs(F - E) / law->F_C_N);
    }
    return worst;
}

static void evaluators(bench_ctx *ctx)
{
    const size_t n = ctx->quick ? 2000 : 20000;
    const int repeats = ctx->quick ? 3 : 7;
    double *u = malloc(n * sizeof *u);
    if (!u)
        return;
    fprintf(ctx->md, "| evaluator | plain: ns per evaluation | plain: max error / F_C | "
                     "tail: ns per evaluation | tail: max error / F_C |\n|---|---|---|---|---|\n");
    cf_law law[2];
    const cf_spring *ps[2] = {&plain_spring, &tail_spring};
    for (int k = 0; k < 2; k++)
        if (cf_law_init(&law[k], ps[k], NULL) != CF_OK ||
            cf_law_table_build(&law[k], CF_LAW_TABLE_DEFAULT, NULL) != CF_OK) {
            free(u);
            return;
        }
    for (size_t v = 0; v < NTV; v++) {
        fprintf(ctx->md, "| %s |", tvars[v].name);
        for (int k = 0; k < 2; k++) {
            region2(&law[k], u, n);
            const bench_stats s = time_eval(&law[k], tvars[v].method, u, n, repeats);
            fprintf(ctx->md, " %.1f [%.1f–%.1f] | %.2g |", s.median, s.min, s.max,
                    max_error(&law[k], tvars[v].method, u, n));
        }
        fprintf(ctx->md, "\n");
    }
    cf_law_free(&law[0]);
    cf_law_free(&law[1]);
    free(u);
}

/* The lattice of n^3 cells of law scaled by 1 - 0.5 about the origin, with a small seeded jitter:
** every spring in region 2 at a slightly different compression. */
static void squeeze(cf_lattice *lat)
{
    unsigned long s = 7;
    for (size_t p = 0; p < lat->nn; p++) {
        double *c[3] = {&lat->x[p], &lat->y[p], &lat->z[p]};
        const double R[3] = {lat->X[p], lat->Y[p], lat->Z[p]};
        for (int a = 0; a < 3; a++) {
            s = s * 6364136223846793005UL + 1442695040888963407UL;
            const double r = (double)(s >> 11) / 9007199254740992.0 - 0.5;
            *c[a] = R[a] * 0.5 + 0.01 * lat->H_mm * r;
        }
    }
}

/* Median ns per spring per step of the stepper (forces and advance, one core); form -2 keeps
** the stepper's own choice, else it is forced. */
static bench_stats time_step(cf_lattice *lat, int form, int repeats, double sample_s, int *used)
{
    bench_stats none = {NAN, NAN, NAN, 0};
    cf_lattice_stepper st;
    if (cf_lattice_stepper_init(&st, lat, NULL, NULL) != CF_OK)
        return none;
    st.threads = 0;
    if (form != -2)
        st.form = form;
    *used = st.form;
    double *v[3] = {calloc(lat->nn, sizeof(double)), calloc(lat->nn, sizeof(double)),
                    calloc(lat->nn, sizeof(double))};
    if (!v[0] || !v[1] || !v[2]) {
        free(v[0]), free(v[1]), free(v[2]);
        cf_lattice_stepper_free(&st);
        return none;
    }
    squeeze(lat);
    const double h = 1e-12; /* the state stays where squeeze() put it */
    double t0 = bench_cpu_now();
    cf_lattice_stepper_forces(&st);
    cf_lattice_stepper_advance(&st, h, v[0], v[1], v[2]);
    const long nstep = (long)(sample_s / fmax(bench_cpu_now() - t0, 1e-9)) + 1;
    double t[15];
    for (int q = 0; q < repeats; q++) {
        t0 = bench_cpu_now();
        for (long i = 0; i < nstep; i++) {
            cf_lattice_stepper_forces(&st);
            cf_lattice_stepper_advance(&st, h, v[0], v[1], v[2]);
        }
        t[q] = (bench_cpu_now() - t0) / (double)nstep / (double)lat->ns * 1e9;
    }
    bench_sink += lat->x[lat->nn / 2];
    free(v[0]), free(v[1]), free(v[2]);
    cf_lattice_stepper_free(&st);
    return bench_summarise(t, repeats);
}

static void step(bench_ctx *ctx)
{
    const int cells = ctx->quick ? 8 : 16, repeats = ctx->quick ? 3 : 7;
    const double sample_s = ctx->quick ? 0.05 : 0.2;
    static const struct {
        const char *name;
        int tail, form;
        cf_law_method method;
    } rows[] = {{"plain spring, closed: the stepper's choice", 0, -2, CF_LAW_CLOSED},
                {"plain spring, closed, the law's batch forced", 0, -1, CF_LAW_CLOSED},
                {"tailed spring, closed: the stepper's choice", 1, -2, CF_LAW_CLOSED},
                {"tailed spring, closed, the scalar law forced", 1, -1, CF_LAW_CLOSED},
                {"plain spring, table 256, the law's batch forced", 0, -1, CF_LAW_TABLE},
                {"tailed spring, table 256: the stepper's choice", 1, -2, CF_LAW_TABLE},
                {"tailed spring, table 256, the scalar law forced", 1, -1, CF_LAW_TABLE}};
    fprintf(ctx->md, "\n| lattice %d³ cells, one core | ns per spring per step | path |\n"
                     "|---|---|---|\n",
            cells);
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        cf_law law;
        if (cf_law_init(&law, rows[r].tail ? &tail_spring : &plain_spring, NULL) != CF_OK)
            return;
        if (rows[r].method == CF_LAW_TABLE &&
            cf_law_table_build(&law, CF_LAW_TABLE_DEFAULT, NULL) != CF_OK)
            return;
        cf_lattice_config cfg = cf_lattice_default();
        cfg.nx = cfg.ny = cfg.nz = cells;
        cf_lattice lat;
        if (cf_lattice_create(&lat, &law, rows[r].method, &cfg, NULL) != CF_OK) {
            cf_law_free(&law);
            return;
        }
        int used = -1;
        const bench_stats s = time_step(&lat, rows[r].form, repeats, sample_s, &used);
        fprintf(ctx->md, "| %s | %.2f [%.2f–%.2f] | %s |\n", rows[r].name, s.median, s.min,
                s.max,
                used == CF_LANE_POLY ? "the spring's polynomial (vector)"
                : used >= 0          ? "the law's vector lanes"
                : rows[r].tail       ? "cf_law_force_many: the scalar law per spring"
                                     : "cf_law_force_many: the law's vector lanes");
        cf_lattice_free(&lat);
        cf_law_free(&law);
    }
}

void bench_section_tail(bench_ctx *ctx)
{
    fprintf(ctx->md,
            "\n## 1b. The spring with a cylindrical tail\n\n"
            "The export tests' telescoping spring (D1 10, D2 30, n 4, d 1, G 80000, H 40 mm) and the "
            "same coils with the cone in 30 mm and one tail coil in 10 mm (rho = 1/3, tau = 0.25, "
            "beta = 0.5). Region 2 of each (u_T to u_C), uniform and crowded at both ends; CPU "
            "time of cf_law_force, median [min–max]; the error against `exact` as a fraction of "
            "F_C. With a tail, `closed` and `closed+newton` are the same bracketed Newton "
            "iteration on the series relation, and the table holds F/F_C.\n\n");
    evaluators(ctx);
    step(ctx);
    fprintf(ctx->md,
            "\nA tailed spring's step runs its own polynomial (src/model/law_poly.c, in the tailed "
            "relation's variable, kept within 1e-13 of the closed form) where it fits, as the "
            "plain spring's does; the rows 'the scalar law forced' put it on cf_law_force_many, "
            "the scalar law per spring, which a spring too conical for the polynomial runs; the "
            "rows 'the law's batch forced' put the plain spring on that same call, where it "
            "still takes the law's vector lanes.\n");
}
