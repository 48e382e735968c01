/*
** The Levenberg-Marquardt's stopping rules (fit/lm.h): the ceiling that ends a run settling
** above what it has to beat, and leaves alone a run that goes below it.
*/
#include "testutil.h"

#include <gsl/gsl_blas.h>

#include "fit/lm.h"

/* Rosenbrock's valley with a third residual held at 1: the sum of squares falls slowly along the
** valley to its least, 1, at (1, 1). */
static int valley(const gsl_vector *x, void *data, gsl_vector *f)
{
    int *calls = data;
    const double a = gsl_vector_get(x, 0), b = gsl_vector_get(x, 1);
    gsl_vector_set(f, 0, 10 * (b - a * a));
    gsl_vector_set(f, 1, 1 - a);
    gsl_vector_set(f, 2, 1);
    (*calls)++;
    return GSL_SUCCESS;
}

/* From (-1.2, 1) under stop: the sum of squares reached, the position and the residual calls. */
static double run(const cf_lm_stop *stop, double x[2], int *calls)
{
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = valley;
    fdf.n = 3;
    fdf.p = 2;
    fdf.params = calls;
    *calls = 0;
    x[0] = -1.2;
    x[1] = 1;
    int init;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, x, &init);
    assert_non_null(w);
    assert_int_equal(init, GSL_SUCCESS);
    assert_int_equal(cf_lm_iterate(w, stop), 0);
    double s;
    gsl_blas_ddot(gsl_multifit_nlinear_residual(w), gsl_multifit_nlinear_residual(w), &s);
    x[0] = gsl_vector_get(gsl_multifit_nlinear_position(w), 0);
    x[1] = gsl_vector_get(gsl_multifit_nlinear_position(w), 1);
    gsl_multifit_nlinear_free(w);
    return s;
}

static void ceiling_ends_a_losing_run(void **state)
{
    (void)state;
    cf_lm_stop stop = {200, 1e-14, 1e-14, 0, 6, 1e-10, 1e-28, 0, 0, 0};
    double x[2];
    int all, cut, below;
    /* no ceiling: to the least */
    assert_close(run(&stop, x, &all), 1, 1e-12);
    assert_close(x[0], 1, 1e-6);
    assert_close(x[1], 1, 1e-6);
    /* a ceiling under the least (what an earlier start reached, doubled, is less): the run ends
    ** once it gains less than 1e-3 of itself over 3 iterations, above the ceiling and near where
    ** it would have ended, for fewer calls */
    stop.ceiling = 0.9;
    stop.ceiling_iter = 3;
    stop.ceiling_rel = 1e-3;
    double s = run(&stop, x, &cut);
    assert_true(s > 0.9 && s < 1.01);
    assert_true(cut < all);
    /* a ceiling above the least does not end a run that gets under it */
    stop.ceiling = 1.5;
    assert_close(run(&stop, x, &below), 1, 1e-12);
    assert_int_equal(below, all);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ceiling_ends_a_losing_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
