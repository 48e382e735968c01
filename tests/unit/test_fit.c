/*
** Tests of the fitter (src/fit/fit.c) and the baselines (src/fit/baseline.c): recovery of known springs
** from synthetic tables (noiseless and noisy), constraints checked at every reported solution,
** fixed parameters, determinism, and the published tables against an independent
** three-parameter least-squares fit.
*/
/* conifit: vector-level: the spring fit, whose first stage runs the family's lanes */
#include <float.h>
#include <math.h>

#include "testutil.h"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_multifit_nlinear.h>

#include "fit/baseline.h"
#include "fit/fit.h"
#include "model/law_internal.h"
#include "io/measure.h"

/* ---- synthetic tables ------------------------------------------------------------------------ */

typedef struct table {
    size_t n;
    double x[400], y[400];
} table;

/* Box-Muller normal deviates from a fixed LCG, so the noisy tables are the same on every run. */
static double normal(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    double u1 = ((double)(*s >> 11) + 0.5) * 0x1.0p-53;
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    double u2 = ((double)(*s >> 11) + 0.5) * 0x1.0p-53;
    return sqrt(-2 * log(u1)) * cos(2 * M_PI * u2);
}

/* sigma = F(eps H)/H^2 at n strains evenly spaced up to frac of the solid strain; noise is a
** relative standard deviation of the largest stress. */
static void synth_pw(const cf_spring *p, size_t n, double frac, double noise, uint64_t seed,
                     double pw, table *t)
{
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, p, &err) != CF_OK)
        fail_msg("bad test spring: %s", err.msg);
    double es = law.travel_mm / p->H_mm;
    double smax = law.F_C_N / (p->H_mm * p->H_mm);
    t->n = n;
    for (size_t i = 0; i < n; i++) {
        t->x[i] = frac * es * (1 - pow(1 - (double)i / (double)(n - 1), pw));
        t->y[i] = cf_law_force(&law, CF_LAW_EXACT, t->x[i] * p->H_mm, NULL, NULL) /
                  (p->H_mm * p->H_mm);
        if (noise > 0)
            t->y[i] += noise * smax * normal(&seed);
    }
}

/* Strains evenly spaced. */
static void synth(const cf_spring *p, size_t n, double frac, double noise, uint64_t seed,
                  table *t)
{
    synth_pw(p, n, frac, noise, seed, 1.0, t);
}

static cf_table data_of(const table *t)
{
    cf_table d = {.count = t->n, .x = (double *)t->x, .y = (double *)t->y};
    return d;
}

static void fit_ok(const cf_table *d, const cf_fit_options *o, cf_spring_type type,
                   cf_fit_result *r)
{
    cf_error err = {0};
    if (cf_fit_run(d, o, type, r, &err) != CF_OK)
        fail_msg("cf_fit_run failed: %s", err.msg);
}

/* The reported solution must satisfy its constraints, checked here from the parameters alone. */
static void assert_constraints_hold(const cf_fit_result *r, const cf_table *d,
                                    const cf_fit_options *o)
{
    const cf_spring *p = &r->params;
    cf_law law;
    assert_int_equal(cf_law_init(&law, p, NULL), CF_OK);
    assert_int_equal(law.type, r->type);
    assert_true(p->D1_mm / p->d_mm >= 3 * (1 - 1e-9));
    assert_true(p->D1_mm / p->d_mm <= o->index_max * (1 + 1e-9));
    assert_true(p->n >= 2 * (1 - 1e-12));
    assert_true(p->D2_mm >= p->D1_mm);
    double xmax = 0;
    for (size_t i = 0; i < d->count; i++)
        xmax = fmax(xmax, fabs(d->x[i]));
    double umax = cf_table_is_force(d) ? xmax : xmax * p->H_mm;
    assert_true(law.travel_mm > umax);
    if (r->type == CF_TELESCOPING)
        assert_true((p->D2_mm - p->D1_mm) / 2 >= p->n * p->d_mm);
    else
        assert_true((p->D2_mm - p->D1_mm) / 2 < p->n * p->d_mm);
    assert_true(r->feasible);
    /* the limits of a spring one could build (fit.h): rho, n, D2/H, G */
    assert_true(p->D1_mm / p->D2_mm >= o->rho_min * (1 - 1e-6));
    assert_true(p->n <= o->upper[CF_P_N] * (1 + 1e-12));
    assert_true(p->D2_mm <= o->D2_over_H_max * p->H_mm * (1 + 1e-9));
    if (!o->fixed[CF_P_G])
        assert_true(p->G_MPa <= o->upper[CF_P_G] * (1 + 1e-12));
    for (int k = 0; k < CF_P_COUNT; k++) {
        double v = ((const double *)p)[k];
        if (o->fixed[k])
            assert_close(v, o->fixed_value[k], 1e-12 * o->fixed_value[k]);
    }
}

/* pw > 1 crowds the strains towards the end of the table (x = frac e_s (1 - (1 - t)^pw)). */
static void assert_recovers(const cf_spring *truth, cf_spring_type type, double frac, double pw)
{
    table t;
    synth_pw(truth, 120, frac, 0, 0, pw, &t);
    cf_table d = data_of(&t);
    cf_fit_options o = cf_fit_default_options();
    cf_fit_result r;
    fit_ok(&d, &o, type, &r);
    const cf_ident id = cf_ident_of(truth, 0);
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        assert_close(r.ident.v[k], id.v[k], 1e-6 * id.v[k]);
    double smax = fabs(t.y[t.n - 1]);
    assert_true(r.rmse <= 1e-12 * smax);
    assert_constraints_hold(&r, &d, &o);
}

/* Telescoping spring D1 = 10, D2 = 30, n = 4, d = 1 (rho = 1/3). */
static void fit_recovers_telescoping_spring_from_noiseless_table(void **state)
{
    (void)state;
    cf_spring p = {10, 30, 4, 1, 80000, 40};
    assert_recovers(&p, CF_TELESCOPING, 0.98, 1);
}

/* Non-telescoping spring D1 = 10, D2 = 14, n = 5, d = 1.5 (rho = 0.714). */
static void fit_recovers_non_telescoping_spring_from_noiseless_table(void **state)
{
    (void)state;
    cf_spring p = {10, 14, 5, 1.5, 80000, 30};
    assert_recovers(&p, CF_NON_TELESCOPING, 0.99, 1);
}

/* Nearly cylindrical: rho = 0.999 (non-telescoping necessarily). Its nonlinear region is the
** last 0.15 % of the travel, so the table runs to 99.99 % of it with
** the strains crowded towards the end. */
static void fit_recovers_nearly_cylindrical_spring(void **state)
{
    (void)state;
    cf_spring p = {9.99, 10, 6, 1.2, 80000, 25};
    assert_recovers(&p, CF_NON_TELESCOPING, 0.9999, 6);
}

/* Strongly conical: rho = 0.05, telescoping. */
static void fit_recovers_strongly_conical_spring(void **state)
{
    (void)state;
    cf_spring p = {3, 60, 3, 0.5, 80000, 20};
    assert_recovers(&p, CF_TELESCOPING, 0.97, 1);
}

/* Both types fit a table that only the non-telescoping geometry generated: the three quantities
** are the same law, so the telescoping fit matches as well when rho is within its range. */
static void both_types_fit_the_same_law_when_rho_allows(void **state)
{
    (void)state;
    cf_spring p = {10, 30, 4, 1, 80000, 40};
    table t;
    synth(&p, 100, 0.95, 0, 0, &t);
    cf_table d = data_of(&t);
    cf_fit_options o = cf_fit_default_options();
    cf_fit_result r;
    fit_ok(&d, &o, CF_NON_TELESCOPING, &r);
    assert_close(r.ident.rho, 1.0 / 3.0, 1e-6);
    assert_true(r.rmse <= 1e-12 * t.y[t.n - 1]);
    assert_constraints_hold(&r, &d, &o);
}

/* With noise the truth lies within 3 standard errors of the estimate. */
static void noisy_fit_brackets_truth_within_three_standard_errors(void **state)
{
    (void)state;
    const cf_spring springs[2] = {{10, 30, 4, 1, 80000, 40}, {10, 14, 5, 1.5, 80000, 30}};
    const cf_spring_type types[2] = {CF_TELESCOPING, CF_NON_TELESCOPING};
    for (int s = 0; s < 2; s++) {
        table t;
        synth(&springs[s], 200, 0.97, 0.002, 12345 + (uint64_t)s, &t);
        cf_table d = data_of(&t);
        cf_fit_options o = cf_fit_default_options();
        cf_fit_result r;
        fit_ok(&d, &o, types[s], &r);
        const cf_ident id = cf_ident_of(&springs[s], 0);
        for (int k = 0; k < CF_IDENT_COUNT; k++) {
            assert_true(r.ident_se.v[k] > 0);
            assert_true(r.ident_se.v[k] < 0.2 * id.v[k]); /* the uncertainty says something */
            assert_close(r.ident.v[k], id.v[k], 3 * r.ident_se.v[k]);
        }
        assert_constraints_hold(&r, &d, &o);
    }
}

/* A fixed parameter is honoured and the fit still reaches the law when the family allows it. */
static void fixed_parameters_are_held_and_fit_still_exact(void **state)
{
    (void)state;
    cf_spring p = {10, 30, 4, 1, 80000, 40};
    table t;
    synth(&p, 100, 0.95, 0, 0, &t);
    cf_table d = data_of(&t);
    cf_fit_options o = cf_fit_default_options();
    o.fixed[CF_P_H] = 1;
    o.fixed_value[CF_P_H] = 5.0;
    o.fixed[CF_P_G] = 1;
    o.fixed_value[CF_P_G] = 10000.0;
    cf_fit_result r;
    fit_ok(&d, &o, CF_TELESCOPING, &r);
    assert_close(r.params.H_mm, 5.0, 0);
    assert_close(r.params.G_MPa, 10000.0, 0);
    assert_true(r.rmse <= 1e-9 * t.y[t.n - 1]);
    assert_constraints_hold(&r, &d, &o);
}

/* Every optimiser gives a feasible fit at rounding level on a noiseless table. */
static void every_optimizer_reaches_the_law(void **state)
{
    (void)state;
    cf_spring p = {10, 14, 5, 1.5, 80000, 30};
    table t;
    synth(&p, 80, 0.95, 0, 0, &t);
    cf_table d = data_of(&t);
    for (int a = 0; a <= CF_OPT_MMA; a++) {
        cf_fit_options o = cf_fit_default_options();
        o.optimizer = (cf_fit_optimizer)a;
        cf_fit_result r;
        fit_ok(&d, &o, CF_NON_TELESCOPING, &r);
        assert_true(r.rmse <= 1e-12 * t.y[t.n - 1]);
        assert_constraints_hold(&r, &d, &o);
    }
}

/* Same seed, same numbers (to the bit); the wall time is the only thing allowed to differ. */
static void fits_are_deterministic_for_a_seed(void **state)
{
    (void)state;
    cf_spring p = {10, 30, 4, 1, 80000, 40};
    table t;
    synth(&p, 100, 0.95, 0.01, 99, &t);
    cf_table d = data_of(&t);
    cf_fit_options o = cf_fit_default_options();
    cf_fit_result a, b;
    fit_ok(&d, &o, CF_TELESCOPING, &a);
    fit_ok(&d, &o, CF_TELESCOPING, &b);
    assert_memory_equal(&a.params, &b.params, sizeof a.params);
    assert_memory_equal(&a.ident, &b.ident, sizeof a.ident);
    assert_memory_equal(&a.ident_se, &b.ident_se, sizeof a.ident_se);
}

/* Bad tables are refused with CF_E_DATA and a message naming the value. */
static void bad_tables_are_refused(void **state)
{
    (void)state;
    double x[5] = {0, 0.1, 0.2, 0.3, 0.4}, y[5] = {0, 1, 2, NAN, 4}, z[5] = {0};
    cf_fit_options o = cf_fit_default_options();
    cf_fit_result r;
    cf_error err = {0};
    cf_table d = {.count = 5, .x = x, .y = y};
    assert_int_equal(cf_fit_run(&d, &o, CF_TELESCOPING, &r, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "point 4"));
    d.y = z;
    assert_int_equal(cf_fit_run(&d, &o, CF_TELESCOPING, &r, &err), CF_E_DATA);
    d.count = 3;
    d.y = x;
    assert_int_equal(cf_fit_run(&d, &o, CF_TELESCOPING, &r, &err), CF_E_DATA);
}

/* A strain of 1 or more cannot be reached by any spring (s/H < 1): the fit is reported, marked
** infeasible with the travel constraint named. */
static void strain_beyond_any_spring_is_reported_infeasible(void **state)
{
    (void)state;
    double x[6] = {0, 0.4, 0.8, 1.2, 1.6, 2.0}, y[6] = {0, 1, 2.2, 3.6, 5.2, 7};
    cf_table d = {.count = 6, .x = x, .y = y};
    cf_fit_options o = cf_fit_default_options();
    cf_fit_result r;
    fit_ok(&d, &o, CF_NON_TELESCOPING, &r);
    assert_false(r.feasible);
    assert_true(r.violated & CF_C_TRAVEL);
    assert_true(isfinite(r.rmse));
}

/* ---- baselines ------------------------------------------------------------------------------- */

/* Hand values: a linear table gives E exactly; a Duffing table its k1, k3; a Fung table A, B. */
static void baselines_recover_their_own_laws(void **state)
{
    (void)state;
    double x[20], yl[20], yd[20], yf[20];
    for (int i = 0; i < 20; i++) {
        x[i] = 0.01 * i;
        yl[i] = 3.5 * x[i];
        yd[i] = 2 * x[i] + 400 * x[i] * x[i] * x[i];
        yf[i] = 0.2 * (exp(12 * x[i]) - 1);
    }
    cf_baseline b[CF_BASE_COUNT];
    cf_table d = {.count = 20, .x = x, .y = yl};
    assert_int_equal(cf_baseline_fit_all(&d, b, NULL), CF_OK);
    assert_close(b[CF_BASE_LINEAR].coef[0], 3.5, 1e-12);
    assert_true(b[CF_BASE_LINEAR].rmse < 1e-13);
    d.y = yd;
    assert_int_equal(cf_baseline_fit_all(&d, b, NULL), CF_OK);
    assert_close(b[CF_BASE_DUFFING].coef[0], 2, 1e-9);
    assert_close(b[CF_BASE_DUFFING].coef[1], 400, 1e-7);
    d.y = yf;
    assert_int_equal(cf_baseline_fit_all(&d, b, NULL), CF_OK);
    assert_close(b[CF_BASE_FUNG].coef[0], 0.2, 1e-6);
    assert_close(b[CF_BASE_FUNG].coef[1], 12, 1e-6);
    /* AIC = n ln(RSS/n) + 2k by hand for the linear fit of the Fung table */
    double rss = b[CF_BASE_LINEAR].rss;
    assert_close(b[CF_BASE_LINEAR].aic, 20 * log(rss / 20) + 2, 1e-9);
}

/* ---- published tables: both types fit, and no worse than an independent careful fit ---------- */

/* The independent fit: the same three-parameter law sigma = A F1(x/B; rho) written directly with
** the exact evaluator, bounded by clamping, solved by GSL's LM from a dense deterministic set of
** starts. */
typedef struct ind_ctx {
    const double *x, *y;
    size_t n;
    double rho_lo, rho_hi, b_lo, b_hi;
} ind_ctx;

static void ind_unpack(const ind_ctx *c, const gsl_vector *v, double *rho, double *B, double *A)
{
    *rho = fmin(fmax(gsl_vector_get(v, 0), c->rho_lo), c->rho_hi);
    *B = fmin(fmax(gsl_vector_get(v, 1), c->b_lo), c->b_hi);
    *A = fabs(gsl_vector_get(v, 2));
}

static double ind_model(double rho, double B, double A, double x)
{
    cf_spring p = {rho, 1, 2, 0.5, 256 * rho * rho * rho, 2}; /* travel 1, F_C 1 */
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return NAN;
    return A * cf_law_force(&law, CF_LAW_EXACT, x / B, NULL, NULL);
}

static int ind_f(const gsl_vector *v, void *params, gsl_vector *f)
{
    ind_ctx *c = params;
    double rho, B, A;
    ind_unpack(c, v, &rho, &B, &A);
    for (size_t i = 0; i < c->n; i++)
        gsl_vector_set(f, i, ind_model(rho, B, A, c->x[i]) - c->y[i]);
    return GSL_SUCCESS;
}

static double independent_rmse(const double *x, const double *y, size_t n, double rho_lo,
                               double rho_hi, double b_lo, double b_hi)
{
    ind_ctx c = {x, y, n, rho_lo, rho_hi, b_lo, b_hi};
    double ymax = 0;
    for (size_t i = 0; i < n; i++)
        ymax = fmax(ymax, fabs(y[i]));
    double best = INFINITY;
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    gsl_multifit_nlinear_workspace *w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, n, 3);
    gsl_multifit_nlinear_fdf fdf = {ind_f, NULL, NULL, n, 3, &c, 0, 0, 0};
    for (int i = 0; i < 12; i++)
        for (int j = 0; j < 12; j++) {
            double rho = rho_lo + (rho_hi - rho_lo) * pow((i + 0.5) / 12.0, 2);
            double B = b_lo + (b_hi - b_lo) * pow((j + 0.5) / 12.0, 3);
            double v0[3] = {rho, B, ymax};
            gsl_vector_view vv = gsl_vector_view_array(v0, 3);
            if (gsl_multifit_nlinear_init(&vv.vector, &fdf, w) != GSL_SUCCESS)
                continue;
            int info;
            gsl_multifit_nlinear_driver(200, 1e-12, 1e-12, 1e-12, NULL, NULL, &info, w);
            gsl_vector *f = gsl_multifit_nlinear_residual(w);
            double chi2;
            gsl_blas_ddot(f, f, &chi2);
            if (isfinite(chi2))
                best = fmin(best, sqrt(chi2 / (double)n));
        }
    gsl_multifit_nlinear_free(w);
    return best;
}

static void published_tables_fit_both_types_at_least_as_well_as_an_independent_fit(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir)
        skip();
    const char *const *files = tu_published_tables;
    for (size_t f = 0; f < TU_PUBLISHED_COUNT; f++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", dir, files[f]);
        cf_table m;
        cf_error err = {0};
        cf_measure_options mo = cf_measure_default_options();
        if (strstr(files[f], "muscle")) {
            mo.x_col = "strain";
            mo.y_col = "stress";
        }
        if (cf_measure_load(path, &mo, &m, &err) != CF_OK)
            fail_msg("%s: %s", files[f], err.msg);
        cf_table d = m; /* the same arrays; m owns them */
        double xmax = 0;
        for (size_t i = 0; i < m.count; i++)
            xmax = fmax(xmax, fabs(m.x[i]));
        for (int t = 0; t < 2; t++) {
            cf_fit_options o = cf_fit_default_options();
            cf_fit_result r;
            fit_ok(&d, &o, (cf_spring_type)t, &r);
            assert_true(isfinite(r.rmse));
            double need = xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9);
            if (!cf_table_is_force(&d) && need >= 1) {
                /* no spring reaches this strain: reported, and flagged */
                assert_false(r.feasible);
                assert_true(r.violated & CF_C_TRAVEL);
                continue;
            }
            assert_constraints_hold(&r, &d, &o);
            double rho_hi = t == CF_TELESCOPING ? o.index_max / (o.index_max + 4) : 1.0;
            double b_hi = cf_table_is_force(&d) ? 1e3 * need : 1 - 1e-9;
            /* the independent fit knows rho_min but not the type's other limits: it is the bar
            ** only for fits that no limit holds */
            if (r.held & ~CF_C_TRAVEL)
                continue;
            double ref = independent_rmse(m.x, m.y, m.count, o.rho_min, rho_hi, need, b_hi);
            if (!(r.rmse <= ref * (1 + 1e-6)))
                fail_msg("%s (%s): rmse %.17g worse than independent %.17g", files[f],
                         cf_spring_type_name((cf_spring_type)t), r.rmse, ref);
        }
        cf_table_free(&m);
    }
}

/* The two types of one table sharing stage A (cf_fit_run_shared) give what each type's own fit
** gives, to the bit, evaluations included (the second counts the shared stage A); the shared
** optimum is taken only for the table and options it was found with. */
static void shared_stage_a_is_each_types_own_fit(void **state)
{
    (void)state;
    cf_spring p = {8, 20, 2.5, 2, 100, 5};
    table t;
    synth(&p, 60, 0.9, 0.01, 7, &t);
    cf_table d = data_of(&t);
    cf_fit_options o = cf_fit_default_options();
    cf_fit_shared sh;
    memset(&sh, 0, sizeof sh);
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        cf_fit_result own, shared;
        cf_error err = {0};
        fit_ok(&d, &o, (cf_spring_type)ty, &own);
        assert_int_equal(cf_fit_run_shared(&d, &o, (cf_spring_type)ty, &sh, &shared, &err), CF_OK);
        assert_true(sh.have);
        assert_memory_equal(&own.params, &shared.params, sizeof own.params);
        assert_memory_equal(&own.ident, &shared.ident, sizeof own.ident);
        assert_true(own.rss == shared.rss);
        assert_int_equal(own.evaluations, shared.evaluations);
    }
    /* other options: the kept optimum is not reused (the fit is the unshared one) */
    cf_fit_options o2 = o;
    o2.seed = o.seed + 1;
    cf_fit_result own2, shared2;
    cf_error err = {0};
    fit_ok(&d, &o2, CF_TELESCOPING, &own2);
    assert_int_equal(cf_fit_run_shared(&d, &o2, CF_TELESCOPING, &sh, &shared2, &err), CF_OK);
    assert_memory_equal(&own2.params, &shared2.params, sizeof own2.params);
    assert_int_equal(own2.evaluations, shared2.evaluations);
}

/* A force table that is a straight line leaves the travel and the solid load free along the
** line's stiffness (the law stays in its first region over the table): the fit takes the compact
** end of that valley whatever the search's tolerance, the transition at the table's largest
** displacement or the solid at 1.5 times it, not a spring some metres long as a search once
** left it. The sum of squares is the line's. */
static void linear_force_table_gets_the_shortest_linear_spring(void **state)
{
    (void)state;
    enum { N = 400 };
    double x[N], y[N], sxy = 0, sxx = 0;
    for (int i = 0; i < N; i++) {
        x[i] = 5.0 * i / (N - 1);                    /* mm */
        y[i] = 0.1 * x[i] + 1e-3 * sin(1.7 * i);      /* N: 0.1 N/mm and a wobble */
        sxy += x[i] * y[i];
        sxx += x[i] * x[i];
    }
    double rss_line = 0;
    for (int i = 0; i < N; i++)
        rss_line += (y[i] - sxy / sxx * x[i]) * (y[i] - sxy / sxx * x[i]);
    cf_table d;
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_FORCE_DISPLACEMENT, N, x, y, NULL, &d, &err),
                     CF_OK);
    cf_fit_options o = cf_fit_default_options();
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        cf_fit_result r;
        fit_ok(&d, &o, (cf_spring_type)ty, &r);
        assert_true(r.feasible);
        if (!(fabs(r.rss - rss_line) <= 1e-6 * rss_line))
            fail_msg("%s: RSS %.12g against the line's %.12g", cf_spring_type_name(r.type), r.rss,
                     rss_line);
        const double xmax = 5.0, uT = r.law.u_T_mm, s = r.law.travel_mm;
        if (!(uT >= xmax * (1 - 1e-6) &&
              (fabs(uT - xmax) <= 1e-6 * xmax || s <= CF_FIT_SOLID_RATIO_WARN * xmax * (1 + 1e-6))))
            fail_msg("%s: transition %.6g mm, travel %.6g mm for a table to %.3g mm",
                     cf_spring_type_name(r.type), uT, s, xmax);
        if (!(r.params.H_mm < 200))
            fail_msg("%s: a spring %.6g mm long", cf_spring_type_name(r.type), r.params.H_mm);
    }
    cf_table_free(&d);
}

int main(void)
{
    gsl_set_error_handler_off();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fit_recovers_telescoping_spring_from_noiseless_table),
        cmocka_unit_test(fit_recovers_non_telescoping_spring_from_noiseless_table),
        cmocka_unit_test(fit_recovers_nearly_cylindrical_spring),
        cmocka_unit_test(fit_recovers_strongly_conical_spring),
        cmocka_unit_test(both_types_fit_the_same_law_when_rho_allows),
        cmocka_unit_test(noisy_fit_brackets_truth_within_three_standard_errors),
        cmocka_unit_test(fixed_parameters_are_held_and_fit_still_exact),
        cmocka_unit_test(every_optimizer_reaches_the_law),
        cmocka_unit_test(fits_are_deterministic_for_a_seed),
        cmocka_unit_test(bad_tables_are_refused),
        cmocka_unit_test(strain_beyond_any_spring_is_reported_infeasible),
        cmocka_unit_test(baselines_recover_their_own_laws),
        cmocka_unit_test(published_tables_fit_both_types_at_least_as_well_as_an_independent_fit),
        cmocka_unit_test(linear_force_table_gets_the_shortest_linear_spring),
        cmocka_unit_test(shared_stage_a_is_each_types_own_fit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
