/*
** The baseline models (fit/baseline.c): linear, Duffing (GSL least squares on [x, x^3]) and Fung
** (scan plus GSL's Brent minimiser on the profile RSS): each recovers its own law, softening as
** well as stiffening, compression tables as well as tension; a degenerate design stays finite;
** AIC stays finite at an exact fit.
*/
#include "testutil.h"

#include <float.h>

#include "conifit/baseline.h"

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
        assert_true(isfinite(b[k].rmse) && isfinite(b[k].aic));
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
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fung_recovers_stiffening_and_softening_in_both_signs),
        cmocka_unit_test(duffing_recovers_its_law_and_survives_a_degenerate_table),
        cmocka_unit_test(aic_is_finite_at_an_exact_fit_and_counts_parameters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
