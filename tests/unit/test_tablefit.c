/*
** The table-fit handle (conifit/tablefit.h, src/pipeline/tablefit.c): NULL and malformed arguments
** refused with a status and a message (a missing file, a time series, an unknown law, a type bit
** that is no type), never a crash, and *out left NULL; a fit of a shipped table equal to the
** pipeline's own (springs, RMSE in the table's unit, each identifiable quantity by its key and its
** standard error); one type when one is asked; the fit file it prepares holds the quantities the
** accessors give, and the table itself is refused as its target.
*/
#include "testutil.h"

#include <jansson.h>

#include "conifit/tablefit.h"
#include "fit/lawkind.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"

static void refused(cf_status got, cf_status want, const cf_error *e, const char *needle)
{
    assert_int_equal(got, want);
    assert_int_equal(e->status, want);
    if (needle && !strstr(e->msg, needle))
        fail_msg("message '%s' does not name '%s'", e->msg, needle);
}

static void bad_arguments_are_refused(void **state)
{
    (void)state;
    cf_error e = {0};
    cf_tablefit *f = (cf_tablefit *)1;
    refused(cf_tablefit_run("data/telescoping.csv", NULL, NULL, &e), CF_E_USAGE, &e, "NULL");
    refused(cf_tablefit_run(NULL, NULL, &f, &e), CF_E_USAGE, &e, "table path");
    assert_null(f);
    f = (cf_tablefit *)1;
    refused(cf_tablefit_run("no/such.csv", NULL, &f, &e), CF_E_NOINPUT, &e, "no/such.csv");
    assert_null(f);
    refused(cf_tablefit_run("data/series/synthetic_relaxation.csv", NULL, &f, &e), CF_E_DATA, &e,
            "time series");
    assert_null(f);
    cf_tablefit_options o = cf_tablefit_default_options();
    o.law = "helical";
    refused(cf_tablefit_run("data/telescoping.csv", &o, &f, &e), CF_E_USAGE, &e, "helical");
    o = cf_tablefit_default_options();
    o.types = 4;
    refused(cf_tablefit_run("data/telescoping.csv", &o, &f, &e), CF_E_USAGE, &e, "0x4");
    o.types = 0;
    refused(cf_tablefit_run("data/telescoping.csv", &o, &f, &e), CF_E_USAGE, &e, "types");
    assert_null(f);
    /* the accessors on NULL and on a bad index */
    assert_int_equal(cf_tablefit_count(NULL), 0);
    assert_int_equal(cf_tablefit_better(NULL), -1);
    assert_null(cf_tablefit_spring(NULL, 0));
    assert_null(cf_tablefit_quantity_key(NULL, 0, 0));
    assert_true(isnan(cf_tablefit_rmse(NULL, 0)));
    double se = 0;
    assert_true(isnan(cf_tablefit_quantity(NULL, 0, "rho", &se)));
    assert_true(se == -1);
    assert_int_equal(cf_tablefit_type(NULL, 0), CF_SPRING_TYPE_NONE); /* never a real type */
    assert_string_equal(cf_spring_type_name(CF_SPRING_TYPE_NONE), "none");
    refused(cf_tablefit_prepare(NULL, "x.json", NULL, &e), CF_E_USAGE, &e, "handle");
    cf_tablefit_free(NULL);
}

/* The value of identifiable quantity key of the fit of type `type` in fit-file text json. */
static double file_quantity(const char *json, const char *type, const char *key)
{
    json_error_t je;
    json_t *root = json_loads(json, 0, &je);
    assert_non_null(root);
    double v = NAN;
    json_t *fits = json_object_get(root, "fits"), *fit;
    size_t i;
    json_array_foreach(fits, i, fit)
    {
        if (strcmp(json_string_value(json_object_get(fit, "type")), type) != 0)
            continue;
        json_t *q = json_object_get(json_object_get(json_object_get(fit, "identifiable"), key),
                                    "value");
        if (q)
            v = json_number_value(q);
    }
    json_decref(root);
    return v;
}

static void a_fit_is_the_pipelines(void **state)
{
    (void)state;
    const char *path = "data/telescoping.csv";
    cf_error e = {0};
    cf_tablefit *f = NULL;
    if (cf_tablefit_run(path, NULL, &f, &e) != CF_OK)
        fail_msg("%s", e.msg);
    assert_non_null(f);

    cf_measure_options mo = cf_measure_default_options();
    cf_table t;
    assert_int_equal(cf_measure_load(path, &mo, &t, &e), CF_OK);
    cf_pipeline_options po = cf_pipeline_default_options();
    cf_fit_report r;
    assert_int_equal(cf_pipeline_fit(&t, &po, &r, &e), CF_OK);

    assert_int_equal(cf_tablefit_count(f), r.nfits);
    assert_int_equal(cf_tablefit_count(f), 2);
    assert_int_equal(cf_tablefit_better(f), cf_report_better(&r));
    assert_string_equal(cf_tablefit_y_unit(f), t.y_unit);
    for (int i = 0; i < r.nfits; i++) {
        const cf_fit_result *d = &r.fits[i];
        assert_int_equal(cf_tablefit_type(f, i), d->type);
        assert_string_equal(cf_tablefit_law(f, i), "conical");
        const cf_spring *p = cf_tablefit_spring(f, i);
        assert_non_null(p);
        for (int k = 0; k < CF_P_COUNT; k++)
            assert_close(cf_spring_get(p, k), cf_spring_get(&d->params, k),
                         1e-12 * fabs(cf_spring_get(&d->params, k)));
        assert_close(cf_tablefit_rmse(f, i), d->rmse * t.y_to_file, 1e-9 * d->rmse * t.y_to_file);
        const cf_law_row *row = cf_fit_kind_of(d);
        assert_int_equal(cf_tablefit_quantity_count(f, i), row->nq);
        assert_int_equal(row->nq, 3);
        assert_null(cf_tablefit_quantity_key(f, i, row->nq));
        for (int k = 0; k < row->nq; k++) {
            const char *key = cf_tablefit_quantity_key(f, i, k);
            assert_string_equal(key, cf_law_q_key(row, k, &t));
            double se;
            const double v = cf_tablefit_quantity(f, i, key, &se);
            assert_close(v, d->q[k], 1e-12 * fabs(d->q[k]));
            if (d->q_se[k] < 0)
                assert_true(se == -1);
            else
                assert_close(se, d->q_se[k], 1e-6 * d->q_se[k] + 1e-300);
            assert_non_null(cf_tablefit_quantity_unit(f, i, key));
        }
        assert_string_equal(cf_tablefit_quantity_unit(f, i, "stress_scale_MPa"), "MPa");
        assert_string_equal(cf_tablefit_quantity_unit(f, i, "rho"), "");
        assert_null(cf_tablefit_quantity_unit(f, i, "F_C_N")); /* a force table's key */
        assert_true(isnan(cf_tablefit_quantity(f, i, "F_C_N", NULL)));
    }
    assert_null(cf_tablefit_spring(f, 2));
    assert_null(cf_tablefit_spring(f, -1));
    assert_int_equal(cf_tablefit_type(f, 2), CF_SPRING_TYPE_NONE);
    assert_int_equal(cf_tablefit_type(f, -1), CF_SPRING_TYPE_NONE);
    cf_report_free(&r);
    cf_table_free(&t);

    /* the fit file: prepared, committed, holding what the accessors give; the table refused */
    char dir[] = "/tmp/cf-tablefit.XXXXXX";
    assert_non_null(mkdtemp(dir));
    char out_path[256];
    snprintf(out_path, sizeof out_path, "%s/fit.json", dir);
    cf_output *out = NULL;
    assert_int_equal(cf_output_new(&out, &e), CF_OK);
    assert_int_not_equal(cf_tablefit_prepare(f, path, out, &e), CF_OK);
    assert_non_null(strstr(e.msg, path));
    refused(cf_tablefit_prepare(f, NULL, out, &e), CF_E_USAGE, &e, "path");
    refused(cf_tablefit_prepare(f, out_path, NULL, &e), CF_E_USAGE, &e, "output");
    if (cf_tablefit_prepare(f, out_path, out, &e) != CF_OK)
        fail_msg("%s", e.msg);
    refused(cf_tablefit_prepare(f, out_path, out, &e), CF_E_USAGE, &e, NULL); /* still held */
    assert_int_equal(cf_output_commit(out, &e), CF_OK);
    cf_output_free(out);
    char *json = tu_slurp(out_path);
    assert_non_null(json);
    for (int i = 0; i < cf_tablefit_count(f); i++) {
        const char *type = cf_spring_type_name(cf_tablefit_type(f, i));
        for (int k = 0; k < cf_tablefit_quantity_count(f, i); k++) {
            const char *key = cf_tablefit_quantity_key(f, i, k);
            const double v = cf_tablefit_quantity(f, i, key, NULL);
            assert_close(file_quantity(json, type, key), v, 1e-15 * fabs(v));
        }
    }
    free(json);
    remove(out_path);
    rmdir(dir);
    cf_tablefit_free(f);
}

static void one_type_when_one_is_asked(void **state)
{
    (void)state;
    cf_error e = {0};
    cf_tablefit_options o = cf_tablefit_default_options();
    o.types = CF_TABLEFIT_NON_TELESCOPING;
    cf_tablefit *f = NULL;
    if (cf_tablefit_run("data/non_telescoping.csv", &o, &f, &e) != CF_OK)
        fail_msg("%s", e.msg);
    assert_int_equal(cf_tablefit_count(f), 1);
    assert_int_equal(cf_tablefit_type(f, 0), CF_NON_TELESCOPING);
    assert_true(cf_tablefit_rmse(f, 0) >= 0);
    cf_tablefit_free(f);
}

/* law "double-acting": conifit fit fits the element through the lattice (a joint fit); the handle
** refuses a table that cannot determine both springs with the command's own message (it returned
** CF_OK with plain conical fits), and one that can with CF_E_USAGE saying where it is fitted. */
static void a_double_acting_law_is_refused_as_the_command_refuses_it(void **state)
{
    (void)state;
    cf_tablefit_options o = cf_tablefit_default_options();
    o.law = "double-acting";
    cf_tablefit *f = (cf_tablefit *)1;
    cf_error e = {0};
    refused(cf_tablefit_run("data/telescoping.csv", &o, &f, &e), CF_E_DATA, &e,
            "a double-acting element's compression spring is not determined by the table");
    assert_null(f);
    char out[4096], err[8192];
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "fit data/telescoping.csv --law double-acting -o "
                            "/tmp/conifit-tablefit-never.json"),
                     65);
    char *nl = strchr(err, '\n');
    if (nl)
        *nl = '\0';
    assert_string_equal(err + strlen("conifit: "), e.msg); /* the same message */
    /* a table of both signs determines the pair: the joint fit's, not this handle's */
    char path[] = "/tmp/conifit-tablefit-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *t = fdopen(fd, "w");
    assert_non_null(t);
    fprintf(t, "strain,stress_kPa\n");
    for (int i = -10; i <= 10; i++)
        fprintf(t, "%g,%g\n", 0.02 * i, 5.0 * 0.02 * i * (1 + 0.02 * i * 0.02 * i));
    fclose(t);
    e = (cf_error){0};
    refused(cf_tablefit_run(path, &o, &f, &e), CF_E_USAGE, &e, "conifit fit --law double-acting");
    assert_null(f);
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bad_arguments_are_refused),
        cmocka_unit_test(a_fit_is_the_pipelines),
        cmocka_unit_test(one_type_when_one_is_asked),
        cmocka_unit_test(a_double_acting_law_is_refused_as_the_command_refuses_it),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
