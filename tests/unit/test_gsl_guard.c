/*
** The library under GSL's default error handler (base/gslguard.h). This program never calls
** gsl_set_error_handler_off: GSL's default handler, which aborts, stays in place, as in a user's
** program or a Python session. A 274-row table makes the fit's F-test ask for F(0.95; 1, 271),
** whose inverse GSL 2.7 does not converge (it reports an error, then returns NaN): the library
** must return, not abort. Also: a handler the program set is put back after every call and still
** receives the program's own errors; threads calling the library at once leave GSL's default
** handler in place when they are done.
*/
#include "testutil.h"

#include <pthread.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>

#include "fit/fit.h"
#include "model/law_internal.h"
#include "conifit/output.h"
#include "pipeline/pipeline.h"
#include "report/report.h"

#define ROWS 274 /* dof 271: GSL 2.7's gsl_cdf_fdist_Pinv(0.95, 1, 271) fails to converge */

/* Two feasible fits of ROWS points whose comparison needs F(0.95; 1, ROWS - 3). */
static cf_fit_verdict compare_two(void)
{
    cf_fit_result a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.feasible = b.feasible = 1;
    a.objective = 1.0;
    b.objective = 1.001;
    a.objective_zero = b.objective_zero = 100.0;
    return cf_fit_compare(&a, &b, ROWS);
}

/* GSL really fails there (else this test would prove nothing). */
static void gsl_fails_at_this_dof(void **state)
{
    (void)state;
    gsl_error_handler_t *was = gsl_set_error_handler_off();
    assert_false(isfinite(gsl_cdf_fdist_Pinv(0.95, 1.0, ROWS - 3)));
    gsl_set_error_handler(was);
}

static void compare_returns_under_the_default_handler(void **state)
{
    (void)state;
    cf_fit_verdict v = compare_two();
    assert_true(isfinite(v.threshold) && v.threshold > 0);
    /* the F quantile fell back to t(0.975; 271)^2 = 3.8753... */
    assert_true(v.threshold > 3.8 * 1.0 / (ROWS - 3) && v.threshold < 3.95 * 1.0 / (ROWS - 3));
    assert_null(gsl_set_error_handler(NULL)); /* the default handler is back */
}

/* A table of ROWS rows from a conical spring's law (a smooth curve, both types fit it) through
** the whole pipeline and the fit file, as tests/install/fit_example.c does. */
static void pipeline_fit_and_file_under_the_default_handler(void **state)
{
    (void)state;
    cf_spring sp = {10, 30, 4, 1, 80000, 50};
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &sp, &err), CF_OK);
    double x[ROWS], y[ROWS];
    for (int i = 0; i < ROWS; i++) {
        double u = 30.0 * (i + 1) / ROWS;
        x[i] = u / 50;
        y[i] = cf_law_force(&law, CF_LAW_CLOSED_NEWTON, u, NULL, NULL) / (50.0 * 50.0) *
               (1 + 0.01 * sin(1.7 * i)); /* a deterministic ripple, as noise */
    }
    cf_law_free(&law);
    cf_table t;
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, ROWS, x, y, NULL, &t, &err),
                     CF_OK);
    cf_pipeline_options po = cf_pipeline_default_options();
    cf_fit_report r;
    assert_int_equal(cf_pipeline_fit(&t, &po, &r, &err), CF_OK);
    assert_int_equal(r.nfits, 2);
    char dir[] = "/tmp/conifit-gslguard-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/fit.json", dir);
    cf_output *out = NULL;
    assert_int_equal(cf_output_new(&out, &err), CF_OK);
    assert_int_equal(cf_pipeline_prepare(&r, path, NULL, NULL, out, NULL, &err), CF_OK);
    assert_int_equal(cf_output_commit(out, &err), CF_OK);
    cf_output_free(out);
    char *text = tu_slurp(path);
    assert_non_null(text);
    assert_non_null(strstr(text, "\"type\""));
    free(text);
    remove(path);
    rmdir(dir);
    cf_report_free(&r);
    cf_table_free(&t);
    assert_null(gsl_set_error_handler(NULL));
}

static int program_errors;
static void program_handler(const char *reason, const char *file, int line, int gsl_errno)
{
    (void)reason, (void)file, (void)line, (void)gsl_errno;
    program_errors++;
}

static void the_programs_handler_is_kept(void **state)
{
    (void)state;
    program_errors = 0;
    gsl_set_error_handler(program_handler);
    compare_two();
    assert_int_equal(program_errors, 0); /* the library's own error did not reach it */
    /* put back, and still called for the program's own errors */
    gsl_cdf_fdist_Pinv(0.95, 1.0, ROWS - 3);
    assert_int_equal(program_errors, 1);
    assert_ptr_equal(gsl_set_error_handler(NULL), program_handler);
}

static void *compare_many(void *arg)
{
    (void)arg;
    for (int i = 0; i < 200; i++)
        if (!isfinite(compare_two().threshold))
            return (void *)1;
    return NULL;
}

static void threads_at_once(void **state)
{
    (void)state;
    pthread_t th[4];
    for (int i = 0; i < 4; i++)
        assert_int_equal(pthread_create(&th[i], NULL, compare_many, NULL), 0);
    for (int i = 0; i < 4; i++) {
        void *ret;
        pthread_join(th[i], &ret);
        assert_null(ret);
    }
    assert_null(gsl_set_error_handler(NULL));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(gsl_fails_at_this_dof),
        cmocka_unit_test(compare_returns_under_the_default_handler),
        cmocka_unit_test(pipeline_fit_and_file_under_the_default_handler),
        cmocka_unit_test(the_programs_handler_is_kept),
        cmocka_unit_test(threads_at_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
