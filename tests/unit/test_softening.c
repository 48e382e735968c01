/*
** Tests of the softening check (src/fit/softening.c): no softening on the shipped tables, on the
** stiffening published tables or on noisy straight and stiffening curves; softening found on noisy
** concave curves and on the chicken breast tables in compression and shear, over the part of the
** range where they bend down.
*/
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "testutil.h"

#include "io/measure.h"
#include "fit/softening.h"

static cf_softening of_file(const char *path)
{
    cf_table m;
    cf_error err = {0};
    cf_measure_options mo = cf_measure_default_options();
    if (cf_measure_load(path, &mo, &m, &err) != CF_OK)
        fail_msg("%s: %s", path, err.msg);
    cf_softening s = cf_softening_of(&m);
    cf_table_free(&m);
    return s;
}

/* y = f(x) on 60 points of [0, 0.3] (sign sgn) with 1 % relative noise of the largest stress. */
static cf_softening of_curve(int shape, double sgn, unsigned long seed)
{
    double x[60], y[60];
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(r);
    gsl_rng_set(r, seed);
    for (int i = 0; i < 60; i++) {
        const double e = 0.3 * i / 59.0;
        double f = shape == 0 ? e : shape == 1 ? exp(8 * e) - 1 : 1 - exp(-10 * e);
        const double top = shape == 0 ? 0.3 : shape == 1 ? exp(2.4) - 1 : 1 - exp(-3.0);
        x[i] = sgn * e;
        y[i] = sgn * (f + 0.01 * top * gsl_ran_gaussian(r, 1.0));
    }
    gsl_rng_free(r);
    cf_table m;
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, 60, x, y, NULL, &m, NULL),
                     CF_OK);
    cf_softening s = cf_softening_of(&m);
    cf_table_free(&m);
    return s;
}

static void noisy_curves(void **state)
{
    (void)state;
    for (unsigned long seed = 1; seed <= 20; seed++)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            assert_false(of_curve(0, sgn, seed).found); /* straight */
            assert_false(of_curve(1, sgn, seed).found); /* stiffening */
            cf_softening s = of_curve(2, sgn, seed);    /* saturating: concave */
            assert_true(s.found);
            assert_true(s.share >= CF_SOFTENING_SHARE && s.share <= 1);
            assert_true(sgn * s.from >= 0 && sgn * s.to > sgn * s.from);
            assert_true(fabs(s.from) < 0.1); /* it bends most near the start */
        }
}

static void shipped_tables_do_not_soften(void **state)
{
    (void)state;
    const char *files[] = {"data/telescoping.csv",         "data/telescoping_compression.csv",
                           "data/telescoping_noise1pct.csv", "data/non_telescoping.csv",
                           "data/non_telescoping_noise1pct.csv", "data/strongly_conical.csv",
                           "data/nearly_cylindrical.csv"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++)
        if (of_file(files[k]).found)
            fail_msg("%s: found softening", files[k]);
}

static void published_tables(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d)
        skip();
    const char *stiff[] = {"heart_myocardium_shear_fs.csv", "heart_myocardium_biaxial_1to1_fiber.csv",
                           "skin_porcine_stripbiaxial_x.csv", "aortic_valve_circumferential.csv",
                           "brain_cortex_compression.csv", "hydrogel_fibre_reinforced_compression.csv"};
    char path[512];
    for (size_t k = 0; k < sizeof stiff / sizeof stiff[0]; k++) {
        snprintf(path, sizeof path, "%s/%s", d, stiff[k]);
        if (of_file(path).found)
            fail_msg("%s: found softening", stiff[k]);
    }
    const char *soft[] = {"chicken_breast_compression.csv", "chicken_breast_shear.csv"};
    for (size_t k = 0; k < 2; k++) {
        snprintf(path, sizeof path, "%s/%s", d, soft[k]);
        cf_softening s = of_file(path);
        if (!s.found)
            fail_msg("%s: no softening found", soft[k]);
        assert_true(s.share >= 0.5);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(noisy_curves),
        cmocka_unit_test(shipped_tables_do_not_soften),
        cmocka_unit_test(published_tables),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
