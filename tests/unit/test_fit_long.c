/*
** Long tables: a fit whose cost grows linearly in the rows with a small slope. Above
** CF_FIT_SUBSAMPLE_ABOVE rows the global searches run on a subsample (fit/subsample.h) and the
** polish on every row; these tests check the subsample itself, that the fit then passes over every
** row only a few dozen times, and that it reaches the fit of the search on every row (the same
** identifiable quantities, errors, intervals and RMSE), with and without the type's limits binding
** and with a fixed parameter; and that the Fung baseline's scan on the subsample finds the
** minimum the scan over every row finds. Speed itself is measured in the benchmark (section 10).
*/
#include <math.h>

#include "testutil.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "fit/baseline.h"
#include "fit/fit.h"
#include "model/law_internal.h"
#include "io/measure.h"
#include "fit/lsq.h"
#include "fit/subsample.h"

/* A stress-strain table of spring p with n rows from strain 0 to frac of its solid strain, with
** Gaussian noise of sd noise x the largest stress (seeded), in a shuffled order when shuffle. */
static void noisy_table(const cf_spring *p, double frac, size_t n, double noise, int shuffle,
                        cf_table *t)
{
    cf_law law;
    assert_int_equal(cf_law_init(&law, p, NULL), CF_OK);
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    assert_non_null(x);
    assert_non_null(y);
    double smax = frac * law.travel_mm / p->H_mm, ymax = 0;
    for (size_t i = 0; i < n; i++) {
        x[i] = smax * (double)i / (double)(n - 1);
        y[i] = cf_law_force(&law, CF_LAW_EXACT, x[i] * p->H_mm, NULL, NULL) / (p->H_mm * p->H_mm);
        ymax = fmax(ymax, fabs(y[i]));
    }
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(r);
    gsl_rng_set(r, 7);
    for (size_t i = 0; i < n; i++)
        y[i] += gsl_ran_gaussian(r, noise * ymax);
    if (shuffle)
        for (size_t i = n - 1; i > 0; i--) {
            size_t j = gsl_rng_uniform_int(r, i + 1);
            double a = x[i], b = y[i];
            x[i] = x[j], y[i] = y[j];
            x[j] = a, y[j] = b;
        }
    gsl_rng_free(r);
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, n, x, y, NULL, t, &err), CF_OK);
    free(x);
    free(y);
}

static const cf_spring telescoping_spring = {8, 20, 2.5, 2, 100, 5}; /* rho 0.4 */

/* What a fit costs, in evaluations of the model (deterministic, unlike times): a 100-row table
** that is no conical spring (3e + 40e^3 kPa to strain 0.3, 1 % noise), both types. Each type's
** limits hold it and its quantities are open, so the constrained search and the profiles run:
** with gradients by central differences and COBYLA they took 13 839 and 18 645 evaluations, with
** the analytic gradients through the identifiable quantities about 5 900 and 8 800. The fits stay
** feasible with profile intervals for every quantity and lie within the F-test of each other. */
static void short_table_fits_in_few_evaluations(void **state)
{
    (void)state;
    enum { N = 100 };
    double x[N], y[N];
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(r);
    gsl_rng_set(r, 1);
    for (size_t i = 0; i < N; i++) {
        x[i] = 0.3 * (double)i / (N - 1);
        y[i] = 1e-3 * (3 * x[i] + 40 * x[i] * x[i] * x[i] + gsl_ran_gaussian(r, 0.01 * 1.98));
    }
    gsl_rng_free(r);
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, N, x, y, NULL, &t, &err), CF_OK);
    cf_fit_options o = cf_fit_default_options();
    cf_fit_result f[2];
    long evals = 0;
    for (int ty = 0; ty < 2; ty++) {
        assert_int_equal(cf_fit_run(&t, &o, (cf_spring_type)ty, &f[ty], &err), CF_OK);
        print_message("%s: %ld evaluations, RMSE %.9g\n", cf_spring_type_name((cf_spring_type)ty),
                      f[ty].evaluations, f[ty].rmse);
        assert_true(f[ty].feasible);
        for (int k = 0; k < 3; k++)
            assert_true(f[ty].interval_ok[k]);
        evals += f[ty].evaluations;
    }
    assert_true(evals < 20000); /* 32 484 before */
    cf_fit_verdict v = cf_fit_compare(&f[0], &f[1], N);
    assert_true(v.tie);
    cf_table_free(&t);
}

/* The subsample keeps the range and scale of the table (its extreme rows), spreads its rows evenly
** along x whatever the order of the table, and its weights add up to the table's. */
static void subsample_keeps_range_scale_and_total_weight(void **state)
{
    (void)state;
    cf_table t, s, s2;
    noisy_table(&telescoping_spring, 0.95, 100000, 0.01, 1, &t);
    for (size_t i = 0; i < t.count; i++)
        t.w[i] = 1 + (double)(i % 3);
    cf_error err = {0};
    assert_int_equal(cf_subsample(&t, CF_SUBSAMPLE_ROWS, &s, &err), CF_OK);
    assert_true(s.count <= CF_SUBSAMPLE_ROWS && s.count >= CF_SUBSAMPLE_ROWS - 3);
    double xmin = INFINITY, xmax = -INFINITY, ymax = 0, wt = 0, ws = 0;
    for (size_t i = 0; i < t.count; i++) {
        xmin = fmin(xmin, t.x[i]);
        xmax = fmax(xmax, t.x[i]);
        ymax = fmax(ymax, fabs(t.y[i]));
        wt += t.w[i];
    }
    double sxmin = INFINITY, sxmax = -INFINITY, symax = 0;
    size_t bins[10] = {0};
    for (size_t i = 0; i < s.count; i++) {
        sxmin = fmin(sxmin, s.x[i]);
        sxmax = fmax(sxmax, s.x[i]);
        symax = fmax(symax, fabs(s.y[i]));
        ws += s.w[i];
        size_t b = (size_t)fmin(9, 10 * (s.x[i] - xmin) / (xmax - xmin));
        bins[b]++;
    }
    assert_true(sxmin == xmin && sxmax == xmax && symax == ymax);
    assert_close(ws, wt, 1e-9 * wt);
    for (int b = 0; b < 10; b++) /* evenly along x: a tenth of the rows in each tenth */
        assert_true(bins[b] >= s.count / 10 - 3 && bins[b] <= s.count / 10 + 3);
    /* deterministic */
    assert_int_equal(cf_subsample(&t, CF_SUBSAMPLE_ROWS, &s2, &err), CF_OK);
    assert_int_equal(s2.count, s.count);
    assert_memory_equal(s2.x, s.x, s.count * sizeof(double));
    assert_memory_equal(s2.y, s.y, s.count * sizeof(double));
    cf_table_free(&s2);
    cf_table_free(&s);
    cf_table_free(&t);
}

/* The fit of a long table against the search on every row (subsample_above = 0), with few
** passes over every row. tol_ident > 0: the same quantities (to that relative tolerance, or a
** twentieth of their standard error),
** standard errors and quality. tol_ident = 0: a table that leaves quantities open or holds them on
** a limit, where the optimum is a flat valley or a ridge on the limit: the objectives differ by
** far less than the F-test can tell apart (1 % of its threshold) and the same quantities get
** profile intervals (the point reported may lie elsewhere in the valley, on another limit). */
static void assert_same_fit(const cf_table *t, const cf_fit_options *base, cf_spring_type type,
                            double tol_ident)
{
    cf_fit_options o = *base;
    cf_fit_result a, b;
    cf_error err = {0};
    assert_true(t->count > o.subsample_above);
    assert_int_equal(cf_fit_run(t, &o, type, &a, &err), CF_OK);
    o.subsample_above = 0;
    assert_int_equal(cf_fit_run(t, &o, type, &b, &err), CF_OK);
    /* the search on every row passes over it a thousand times and more; the subsampled one
    ** only to polish (the figure is evaluations of the model over every row) */
    assert_true(b.evaluations_full == b.evaluations && b.evaluations_full > 1000);
    print_message("%zu rows: %ld evaluations over every row (search on every row: %ld); "
                  "RMSE %.9g (%.9g)\n",
                  t->count, a.evaluations_full, b.evaluations_full, a.rmse, b.rmse);
    assert_true(a.evaluations_full < a.evaluations);
    assert_true(a.evaluations_full <= 600); /* measured: 16 to 493 */
    assert_int_equal(a.feasible, b.feasible);
    cf_fit_verdict v = cf_fit_compare(&a, &b, t->count);
    assert_true(isfinite(v.threshold) && v.threshold > 0);
    assert_true(a.objective <= b.objective + 0.01 * v.threshold);
    for (int k = 0; k < 3; k++)
        assert_int_equal(a.interval_ok[k], b.interval_ok[k]);
    if (tol_ident == 0)
        return;
    assert_int_equal(a.held, b.held);
    assert_close(a.rmse, b.rmse, 1e-9 * b.rmse);
    for (int k = 0; k < 3; k++) {
        /* the polish on every row stops at a statistical tolerance (fit_ctx.h, LONG_TOL): within
        ** a twentieth of the standard error where that is larger than tol_ident */
        assert_close(a.ident.v[k], b.ident.v[k],
                     fmax(tol_ident * b.ident.v[k], 0.05 * b.ident_se.v[k]));
        assert_true((a.ident_se.v[k] < 0) == (b.ident_se.v[k] < 0));
        if (b.ident_se.v[k] > 0)
            assert_close(a.ident_se.v[k], b.ident_se.v[k], 1e-4 * b.ident_se.v[k]);
    }
}

static void long_table_fits_as_the_search_on_every_row(void **state)
{
    (void)state;
    cf_table t;
    noisy_table(&telescoping_spring, 0.95, 5000, 0.01, 1, &t);
    cf_fit_options o = cf_fit_default_options();
    assert_same_fit(&t, &o, CF_TELESCOPING, 1e-7);
    cf_table_free(&t);
}

/* rho_min above the table's rho: the optimum lies outside the limits (the constrained search,
** rho on its limit with a profile interval). */
static void long_table_held_by_a_limit_fits_as_the_search_on_every_row(void **state)
{
    (void)state;
    cf_table t;
    noisy_table(&telescoping_spring, 0.95, 5000, 0.01, 0, &t);
    cf_fit_options o = cf_fit_default_options();
    o.rho_min = 0.5;
    assert_same_fit(&t, &o, CF_NON_TELESCOPING, 0);
    cf_table_free(&t);
}

/* A table that ends far from solid: the nonlinear part is short and the quantities are open
** (profile intervals). */
static void long_table_with_open_quantities_fits_as_the_search_on_every_row(void **state)
{
    (void)state;
    cf_table t;
    noisy_table(&telescoping_spring, 0.4, 5000, 0.05, 0, &t);
    cf_fit_options o = cf_fit_default_options();
    assert_same_fit(&t, &o, CF_NON_TELESCOPING, 0);
    cf_table_free(&t);
}

/* A fixed parameter: the polish from several starts, on the subsample, then on every row. */
static void long_table_with_a_fixed_parameter_fits_as_the_search_on_every_row(void **state)
{
    (void)state;
    cf_table t;
    noisy_table(&telescoping_spring, 0.95, 5000, 0.01, 0, &t);
    cf_fit_options o = cf_fit_default_options();
    o.fixed[CF_P_H] = 1;
    o.fixed_value[CF_P_H] = 5;
    assert_same_fit(&t, &o, CF_TELESCOPING, 1e-5);
    cf_table_free(&t);
}

/* A table just past the subsample's size that is no conical spring (stress 3e + 40e^3 kPa, 1 %
** noise, strain to 0.3), as a testing machine writes one: both types fit as the search on every
** row does (the objective within 1 % of the F-test's threshold, the same intervals). */
static void table_past_the_subsample_size_fits_as_the_search_on_every_row(void **state)
{
    (void)state;
    enum { N = 1500 };
    double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y);
    assert_non_null(x);
    assert_non_null(y);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(r);
    gsl_rng_set(r, 3);
    for (int i = 0; i < N; i++) {
        x[i] = 0.3 * i / (N - 1.0);
        y[i] = 1e-3 * (3 * x[i] + 40 * x[i] * x[i] * x[i]) + gsl_ran_gaussian(r, 1e-3 * 0.0198);
    }
    gsl_rng_free(r);
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, N, x, y, NULL, &t, &err), CF_OK);
    free(x);
    free(y);
    cf_fit_options o = cf_fit_default_options();
    assert_true(t.count > o.subsample_above);
    assert_same_fit(&t, &o, CF_TELESCOPING, 0);
    assert_same_fit(&t, &o, CF_NON_TELESCOPING, 0);
    cf_table_free(&t);
}

/* Fung's baseline on a long table: the minimum over the scan's grid on every row, refined. */
static void long_table_fung_baseline_is_the_minimum_of_the_full_scan(void **state)
{
    (void)state;
    cf_table t;
    noisy_table(&telescoping_spring, 0.95, 20000, 0.01, 1, &t);
    assert_true(t.count > CF_FIT_SUBSAMPLE_ABOVE);
    cf_baseline b[CF_BASE_COUNT];
    assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
    const cf_baseline *f = &b[CF_BASE_FUNG];
    double xmax = 0;
    for (size_t i = 0; i < t.count; i++)
        xmax = fmax(xmax, fabs(t.x[i]));
    /* the RSS of the best A for each B of the scan's grid, over every row */
    double bmax = 50.0 / xmax, best = INFINITY;
    for (int i = -400; i <= 400; i++) {
        if (i == 0)
            continue;
        double B = bmax * i / 400, sgy = 0, sgg = 0, syy = 0;
        for (size_t k = 0; k < t.count; k++) {
            double g = expm1(B * t.x[k]);
            sgy += g * t.y[k];
            sgg += g * g;
            syy += t.y[k] * t.y[k];
        }
        best = fmin(best, syy - sgy * sgy / sgg);
    }
    assert_true(f->rss <= best * (1 + 1e-12));
    cf_table_free(&t);
}

/* The F-test quantile behind the tie verdict and the profile intervals is finite at every table
** length (GSL's inverse F returns NaN at 4997 or 1e5 degrees of freedom, which made every
** comparison with it false: no tie, intervals shrunk to the value). */
static void f_quantile_is_finite_for_every_length(void **state)
{
    (void)state;
    const double dof[] = {1, 2, 10, 57, 1066, 4997, 1e4, 99997, 1e5, 1e6, 1e7};
    double prev = INFINITY;
    for (size_t i = 0; i < sizeof dof / sizeof dof[0]; i++) {
        double f = cf_lsq_f95(dof[i]);
        assert_true(isfinite(f) && f >= 3.8414588206941 && f <= prev); /* falls to chi2(1) */
        prev = f;
    }
    assert_close(cf_lsq_f95(10), 4.9646027437307128, 1e-12);
    cf_fit_result a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.feasible = b.feasible = 1;
    a.objective = 1.0;
    b.objective = 1.0 + 1e-6;
    a.objective_zero = b.objective_zero = 1e3;
    cf_fit_verdict v = cf_fit_compare(&a, &b, 5000);
    assert_true(isfinite(v.threshold) && v.tie);
}

int main(void)
{
    gsl_set_error_handler_off();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(f_quantile_is_finite_for_every_length),
        cmocka_unit_test(subsample_keeps_range_scale_and_total_weight),
        cmocka_unit_test(long_table_fits_as_the_search_on_every_row),
        cmocka_unit_test(long_table_held_by_a_limit_fits_as_the_search_on_every_row),
        cmocka_unit_test(long_table_with_a_fixed_parameter_fits_as_the_search_on_every_row),
        cmocka_unit_test(long_table_with_open_quantities_fits_as_the_search_on_every_row),
        cmocka_unit_test(table_past_the_subsample_size_fits_as_the_search_on_every_row),
        cmocka_unit_test(long_table_fung_baseline_is_the_minimum_of_the_full_scan),
        cmocka_unit_test(short_table_fits_in_few_evaluations),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
