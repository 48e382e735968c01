/*
** The baseline models (fit/baseline.c): linear, Duffing (GSL least squares on [x, x^3]), Fung
** (scan plus GSL's Brent minimiser on the profile RSS), Yeoh (least squares in the table's test
** mode) and one-term Ogden (scan and Brent on alpha): each recovers its own law, softening as
** well as stiffening, compression tables as well as tension, in every mode; a degenerate design
** stays finite; a table Yeoh and Ogden have no form for is reported as not fitted, with why; AIC
** stays finite at an exact fit. Yeoh and Ogden are checked against stresses computed here in long
** double straight from their strain energies, and on a published table against normal equations
** solved here.
*/
#include "testutil.h"

#include <float.h>

#include "fit/baseline.h"
#include "io/measure.h"

static void fung_recovers_stiffening_and_softening_in_both_signs(void **state)
{
    (void)state;
    const double Bs[4] = {12, -3, 0.5, 40};
    for (int sign = -1; sign <= 1; sign += 2)
        for (int k = 0; k < 4; k++) {
            double x[30], y[30];
            for (int i = 0; i < 30; i++) {
                x[i] = sign * 0.01 * i;
                y[i] = 0.2 * expm1(Bs[k] * x[i]);
            }
            cf_table t = {.count = 30, .x = x, .y = y};
            cf_baseline b[CF_BASE_COUNT];
            assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
            if (!(fabs(b[CF_BASE_FUNG].coef[1] - Bs[k]) <= 1e-6 * fabs(Bs[k])))
                fail_msg("B = %g (sign %d): fitted %.17g", Bs[k], sign, b[CF_BASE_FUNG].coef[1]);
            assert_close(b[CF_BASE_FUNG].coef[0], 0.2, 1e-6);
            /* a minimiser of RSS(B) finds B to about sqrt(machine epsilon) relative (RSS is
            ** quadratic at its minimum), so the fit is exact to about 1e-8 of the stress */
            assert_true(b[CF_BASE_FUNG].rmse < 1e-7 * fabs(y[29]));
        }
}

static void duffing_recovers_its_law_and_survives_a_degenerate_table(void **state)
{
    (void)state;
    double x[25], y[25];
    for (int i = 0; i < 25; i++) {
        x[i] = -0.3 + 0.025 * i;
        y[i] = 1.5 * x[i] - 20 * x[i] * x[i] * x[i]; /* softening */
    }
    cf_table t = {.count = 25, .x = x, .y = y};
    cf_baseline b[CF_BASE_COUNT];
    assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
    assert_close(b[CF_BASE_DUFFING].coef[0], 1.5, 1e-10);
    assert_close(b[CF_BASE_DUFFING].coef[1], -20, 1e-8);
    /* every point at |x| = 1: x and x^3 are the same column, the problem has no unique answer;
    ** the coefficients stay finite and the fit is still exact */
    double xd[6] = {1, -1, 1, -1, 1, -1}, yd[6] = {2, -2, 2, -2, 2, -2};
    cf_table td = {.count = 6, .x = xd, .y = yd};
    assert_int_equal(cf_baseline_fit_all(&td, b, NULL), CF_OK);
    for (int k = 0; k < CF_BASE_COUNT; k++) {
        assert_true(isfinite(b[k].coef[0]) && isfinite(b[k].coef[1]));
        /* strain -1 is stretch 0: Yeoh and Ogden have no form there */
        assert_int_equal(b[k].fitted, k != CF_BASE_YEOH && k != CF_BASE_OGDEN);
        assert_true(!b[k].fitted || (isfinite(b[k].rmse) && isfinite(b[k].aic)));
    }
    assert_close(b[CF_BASE_DUFFING].coef[0] + b[CF_BASE_DUFFING].coef[1], 2, 1e-12);
    assert_true(b[CF_BASE_DUFFING].rmse < 1e-12);
}

static void aic_is_finite_at_an_exact_fit_and_counts_parameters(void **state)
{
    (void)state;
    double a = cf_baseline_aic(20, 0.0, 2, 5.0);
    assert_true(isfinite(a));
    /* one more parameter costs 2 at the same RSS */
    assert_close(cf_baseline_aic(20, 1e-3, 3, 5.0) - cf_baseline_aic(20, 1e-3, 2, 5.0), 2, 1e-12);
    assert_string_equal(cf_baseline_name(CF_BASE_LINEAR), "linear");
    assert_string_equal(cf_baseline_name(CF_BASE_FUNG), "fung");
    assert_string_equal(cf_baseline_name(CF_BASE_YEOH), "yeoh");
    assert_string_equal(cf_baseline_name(CF_BASE_OGDEN), "ogden");
}

/* ---- Yeoh and Ogden ---------------------------------------------------------------------- */

/* The stretches of mode m at strain x: the loaded one and the two others (incompressible), or,
** in simple shear, the principal stretches of amount x. */
static void stretches(cf_mode m, long double x, long double l[3])
{
    long double a = 1 + x;
    switch (m) {
    case CF_MODE_SHEAR:
        a = x / 2 + sqrtl(1 + x * x / 4);
        l[0] = a, l[1] = 1 / a, l[2] = 1;
        break;
    case CF_MODE_PLANAR: l[0] = a, l[1] = 1, l[2] = 1 / a; break;
    case CF_MODE_EQUIBIAXIAL: l[0] = a, l[1] = a, l[2] = 1 / (a * a); break;
    default: l[0] = a, l[1] = l[2] = 1 / sqrtl(a); break;
    }
}

/* A strain energy of the stretches, with its parameters. */
typedef long double (*energy_fn)(const long double l[3], const double *p);

static long double yeoh_energy(const long double l[3], const double *p)
{
    long double j = l[0] * l[0] + l[1] * l[1] + l[2] * l[2] - 3;
    return p[0] * j + p[1] * j * j + p[2] * j * j * j;
}

static long double ogden_energy(const long double l[3], const double *p)
{
    long double a = p[1];
    return 2 * p[0] / (a * a) * (powl(l[0], a) + powl(l[1], a) + powl(l[2], a) - 3);
}

/* The nominal stress of mode m at x, straight from the energy: the work conjugate of the
** loading (dW/dx by a central difference of step h in long double, fourth order; halved in
** equibiaxial, where both loaded directions work). */
static double nominal_stress(energy_fn W, const double *p, cf_mode m, double x)
{
    const long double h = 1e-4L;
    long double w[4], l[3];
    const long double at[4] = {-2, -1, 1, 2};
    for (int k = 0; k < 4; k++) {
        stretches(m, x + at[k] * h, l);
        w[k] = W(l, p);
    }
    long double d = (w[0] - 8 * w[1] + 8 * w[2] - w[3]) / (12 * h);
    return (double)(m == CF_MODE_EQUIBIAXIAL ? d / 2 : d);
}

/* A table of n rows of mode m from x0 to x1 of the law W with parameters p, with noise of
** relative size noise (deterministic Gaussian) of the largest |stress|. */
static void law_table(energy_fn W, const double *p, cf_mode m, double x0, double x1, size_t n,
                      double noise, double *x, double *y, cf_table *t)
{
    double ymax = 0;
    for (size_t i = 0; i < n; i++) {
        x[i] = x0 + (x1 - x0) * (double)i / (double)(n - 1);
        y[i] = nominal_stress(W, p, m, x[i]);
        ymax = fmax(ymax, fabs(y[i]));
    }
    unsigned long long s = 12345;
    for (size_t i = 0; noise > 0 && i < n; i++) {
        double u[2];
        for (int k = 0; k < 2; k++) {
            s = s * 6364136223846793005ULL + 1442695040888963407ULL;
            u[k] = ((double)(s >> 11) + 0.5) / 9007199254740992.0;
        }
        y[i] += noise * ymax * sqrt(-2 * log(u[0])) * cos(2 * M_PI * u[1]);
    }
    *t = (cf_table){.count = n, .x = x, .y = y, .mode = m};
}

typedef struct mode_case {
    cf_mode mode;
    double x0, x1;
} mode_case;

/* tension, compression (stretch below 1), simple shear, pure shear, equibiaxial */
static const mode_case cases[] = {
    {CF_MODE_UNIAXIAL, 0, 0.6},    {CF_MODE_UNIAXIAL, -0.45, 0}, {CF_MODE_SHEAR, 0, 0.5},
    {CF_MODE_PLANAR, 0, 0.4},      {CF_MODE_EQUIBIAXIAL, 0, 0.3}, {CF_MODE_EQUIBIAXIAL, -0.2, 0},
};
#define NCASES (sizeof cases / sizeof cases[0])

/* Fits the noiseless table of law W (parameters p) in every case and checks that baseline kind
** recovers p to 1e-9 relative (Ogden's alpha by its size in pure and simple shear, which are
** even in it: its sign is not seen there and is reported positive), and that it is the best
** baseline of its own table. */
static void recovers_in_every_mode(energy_fn W, const double *p, cf_baseline_kind kind)
{
    double x[41], y[41];
    const int np = kind == CF_BASE_YEOH ? 3 : 2;
    for (size_t c = 0; c < NCASES; c++) {
        const cf_mode m = cases[c].mode;
        cf_table t;
        law_table(W, p, m, cases[c].x0, cases[c].x1, 41, 0, x, y, &t);
        cf_baseline b[CF_BASE_COUNT];
        assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
        const cf_baseline *B = &b[kind];
        assert_true(B->fitted && B->form == m);
        const int even = kind == CF_BASE_OGDEN && (m == CF_MODE_PLANAR || m == CF_MODE_SHEAR);
        for (int j = 0; j < np; j++) {
            const double want = even && j == 1 ? fabs(p[j]) : p[j];
            if (!(fabs(B->coef[j] - want) <= 1e-9 * fabs(want)))
                fail_msg("%s, %s from %g to %g: coefficient %d = %.17g, want %.17g",
                         cf_baseline_name(kind), cf_mode_name(m), cases[c].x0, cases[c].x1,
                         j + 1, B->coef[j], want);
        }
        /* (another law may meet the table to rounding too) */
        const double top = 1e-12 * fmax(fabs(y[0]), fabs(y[40])), floor = 41 * top * top;
        for (int o = 0; o < CF_BASE_COUNT; o++)
            assert_true(!b[o].fitted || b[o].rss + floor >= B->rss);
    }
}

static void yeoh_recovers_its_coefficients_in_every_mode(void **state)
{
    (void)state;
    /* a stiffening law, and one with the negative C2 of soft tissue */
    const double C[2][3] = {{0.12, 0.05, 0.02}, {0.3, -0.2, 0.4}};
    for (int k = 0; k < 2; k++)
        recovers_in_every_mode(yeoh_energy, C[k], CF_BASE_YEOH);
}

static void ogden_recovers_mu_and_alpha_in_every_mode(void **state)
{
    (void)state;
    /* rubber-like, a negative exponent (brain), a steep tissue exponent */
    const double P[3][2] = {{0.4, 2.5}, {0.8, -4.0}, {0.01, 18.0}};
    for (int k = 0; k < 3; k++)
        recovers_in_every_mode(ogden_energy, P[k], CF_BASE_OGDEN);
}

/* 1 % noise of the largest stress: the coefficients within a few per cent (the leading one, the
** modulus at zero strain, within 2 %), the RMSE that of the noise. */
static void yeoh_and_ogden_recover_noisy_tables(void **state)
{
    (void)state;
    double x[200], y[200];
    const double C[3] = {0.3, -0.2, 0.4}, P[2] = {0.8, 6.0};
    cf_table t;
    cf_baseline b[CF_BASE_COUNT];
    law_table(yeoh_energy, C, CF_MODE_UNIAXIAL, -0.3, 0.6, 200, 0.01, x, y, &t);
    double ymax = fmax(fabs(y[0]), fabs(y[199]));
    assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
    assert_close(b[CF_BASE_YEOH].coef[0], C[0], 0.02 * C[0]);
    assert_true(b[CF_BASE_YEOH].rmse > 0.008 * ymax && b[CF_BASE_YEOH].rmse < 0.012 * ymax);
    law_table(ogden_energy, P, CF_MODE_PLANAR, 0, 0.5, 200, 0.01, x, y, &t);
    ymax = fabs(y[199]);
    assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
    assert_close(b[CF_BASE_OGDEN].coef[0], P[0], 0.02 * P[0]);
    assert_close(b[CF_BASE_OGDEN].coef[1], P[1], 0.05 * P[1]);
    assert_true(b[CF_BASE_OGDEN].rmse > 0.008 * ymax && b[CF_BASE_OGDEN].rmse < 0.012 * ymax);
}

/* A long table: alpha scanned on the subsample, refined on every row, exact all the same. */
static void ogden_on_a_long_table_is_exact(void **state)
{
    (void)state;
    enum { N = 5000 };
    static double x[N], y[N];
    const double P[2] = {0.05, 9.0};
    cf_table t;
    law_table(ogden_energy, P, CF_MODE_UNIAXIAL, -0.3, 0.4, N, 0, x, y, &t);
    cf_baseline b[CF_BASE_COUNT];
    assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
    assert_close(b[CF_BASE_OGDEN].coef[1], P[1], 1e-9 * P[1]);
    assert_close(b[CF_BASE_OGDEN].coef[0], P[0], 1e-9 * P[0]);
}

/* The hydrogel's compression (published, uniaxial, stretch down to 0.5): Yeoh fits it better than
** the straight line and Duffing's cubic; its coefficients and RSS are those of the normal
** equations of the uniaxial Yeoh law, assembled and solved here in long double. */
static void yeoh_beats_duffing_on_the_hydrogel_and_matches_normal_equations(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir) {
        print_message("test_baseline: ../shared/datasets absent: the hydrogel is not fitted\n");
        skip();
    }
    char path[512];
    snprintf(path, sizeof path, "%s/hydrogel_fibre_reinforced_compression.csv", dir);
    cf_table t;
    cf_error err = {0};
    cf_measure_options mo = cf_measure_default_options();
    if (cf_measure_load(path, &mo, &t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_baseline b[CF_BASE_COUNT];
    assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
    const cf_baseline *Y = &b[CF_BASE_YEOH];
    assert_true(Y->fitted);
    assert_true(Y->rss < 0.2 * b[CF_BASE_DUFFING].rss && Y->rss < b[CF_BASE_LINEAR].rss);
    long double A[3][4] = {{0}};
    for (size_t i = 0; i < t.count; i++) {
        long double l = 1 + (long double)t.x[i], j = l * l + 2 / l - 3, s = 2 * (l - 1 / (l * l));
        long double g[3] = {s, 2 * s * j, 3 * s * j * j};
        for (int r = 0; r < 3; r++) {
            for (int c = 0; c < 3; c++)
                A[r][c] += g[r] * g[c];
            A[r][3] += g[r] * t.y[i];
        }
    }
    for (int p = 0; p < 3; p++) /* Gauss-Jordan, the matrix positive definite */
        for (int r = 0; r < 3; r++)
            if (r != p) {
                long double f = A[r][p] / A[p][p];
                for (int c = 0; c < 4; c++)
                    A[r][c] -= f * A[p][c];
            }
    long double C[3], rss = 0;
    for (int r = 0; r < 3; r++)
        C[r] = A[r][3] / A[r][r];
    for (size_t i = 0; i < t.count; i++) {
        long double l = 1 + (long double)t.x[i], j = l * l + 2 / l - 3, s = 2 * (l - 1 / (l * l));
        long double e = s * (C[0] + 2 * C[1] * j + 3 * C[2] * j * j) - t.y[i];
        rss += e * e;
    }
    for (int r = 0; r < 3; r++)
        assert_close(Y->coef[r], (double)C[r], 1e-7 * fabsl(C[r]));
    assert_close(Y->rss, (double)rss, 1e-9 * (double)rss);
    assert_close(Y->rmse, sqrt((double)rss / (double)t.count), 1e-9 * Y->rmse);
    cf_table_free(&t);
}

/* Tables Yeoh and Ogden have no form for: not fitted, with why, and never evaluated; the other
** baselines as ever. */
static void yeoh_and_ogden_are_not_fitted_where_they_have_no_form(void **state)
{
    (void)state;
    double x[10], y[10];
    for (int i = 0; i < 10; i++) {
        x[i] = 0.1 * i;
        y[i] = 2 * x[i] + x[i] * x[i];
    }
    const struct {
        cf_table_kind kind;
        cf_mode mode;
        double x0;
        const char *why;
    } bad[] = {{CF_TABLE_FORCE_DISPLACEMENT, CF_MODE_UNIAXIAL, 0, "force-displacement"},
               {CF_TABLE_FORCE_DISPLACEMENT, CF_MODE_PLANAR, 0, "force-displacement"},
               {CF_TABLE_STRESS_STRAIN, CF_MODE_CONFINED, 0, "confined"},
               {CF_TABLE_STRESS_STRAIN, CF_MODE_UNIAXIAL, -1.05, "stretch"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        x[0] = bad[k].x0;
        cf_table t = {.kind = bad[k].kind, .count = 10, .x = x, .y = y, .mode = bad[k].mode};
        cf_baseline b[CF_BASE_COUNT];
        assert_int_equal(cf_baseline_fit_all(&t, b, NULL), CF_OK);
        for (int j = CF_BASE_YEOH; j <= CF_BASE_OGDEN; j++) {
            assert_false(b[j].fitted);
            assert_non_null(b[j].why);
            if (!strstr(b[j].why, bad[k].why))
                fail_msg("case %zu: %s: '%s' does not say '%s'", k, cf_baseline_name(b[j].kind),
                         b[j].why, bad[k].why);
            assert_true(isnan(cf_baseline_eval(&b[j], 0.5)));
        }
        for (int j = CF_BASE_LINEAR; j <= CF_BASE_FUNG; j++)
            assert_true(b[j].fitted && isfinite(b[j].rmse) && isfinite(b[j].aic));
    }
    /* the same rows as a uniaxial stress-strain table are fitted, and simple shear takes any
    ** amount of shear, negative ones below -1 too */
    x[0] = 0;
    cf_table ok = {.count = 10, .x = x, .y = y};
    cf_baseline b[CF_BASE_COUNT];
    assert_int_equal(cf_baseline_fit_all(&ok, b, NULL), CF_OK);
    assert_true(b[CF_BASE_YEOH].fitted && b[CF_BASE_OGDEN].fitted && b[CF_BASE_YEOH].why == NULL);
    x[0] = -1.5;
    ok.mode = CF_MODE_SHEAR;
    assert_int_equal(cf_baseline_fit_all(&ok, b, NULL), CF_OK);
    assert_true(b[CF_BASE_YEOH].fitted && b[CF_BASE_OGDEN].fitted);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fung_recovers_stiffening_and_softening_in_both_signs),
        cmocka_unit_test(duffing_recovers_its_law_and_survives_a_degenerate_table),
        cmocka_unit_test(aic_is_finite_at_an_exact_fit_and_counts_parameters),
        cmocka_unit_test(yeoh_recovers_its_coefficients_in_every_mode),
        cmocka_unit_test(ogden_recovers_mu_and_alpha_in_every_mode),
        cmocka_unit_test(yeoh_and_ogden_recover_noisy_tables),
        cmocka_unit_test(ogden_on_a_long_table_is_exact),
        cmocka_unit_test(yeoh_beats_duffing_on_the_hydrogel_and_matches_normal_equations),
        cmocka_unit_test(yeoh_and_ogden_are_not_fitted_where_they_have_no_form),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
