/*
** The pipeline (pipeline.h) and the spring description (spring.h):
**  - golden: refitting every table of data/ through cf_pipeline_fit reproduces the committed
**    fits/NAME.json (made by `make fits`) to a stated tolerance;
**  - the JSON keys of the spring description are the ones written to a fit file and read back;
**  - a table made in code goes through the same call;
**  - the batch pool runs every task once, on any number of threads;
**  - the joint fit fits each asked type and names each through the progress callback.
*/
#include "testutil.h"

#include <dirent.h>
#include <glob.h>

#include <jansson.h>

#include "io/fitfile.h"
#include "pipeline/pipeline.h"
#include "pipeline/pipeline_joint.h"
#include "conifit/spring.h"
#include "pipeline/pool.h"

/* Tolerances of the golden comparison, relative to the committed value. The fit is deterministic
** for a given build (seeded, no threads inside a fit); another compiler or optimisation level may
** change the last bits of each floating-point step. What the data determine (the identifiable
** quantities, RMSE, R^2) is compared to 1e-6; the six design parameters are one member of a
** family placed by NLopt to its own tolerance, and a different start (another random stream)
** moves them by about 2e-6, so they are compared to 1e-4, which still catches any change in
** what is fitted. Quantities that are zero at rounding level (RMSE of a noiseless table) are
** compared absolutely, to 1e-9 of the table's largest |stress|. */
#define GOLDEN_REL 1e-6
#define GOLDEN_PARAM_REL 1e-4
#define GOLDEN_ABS_OF_YMAX 1e-9

static double jnum(json_t *o, const char *path)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    json_t *cur = o;
    for (char *tok = strtok(buf, "."); tok && cur; tok = strtok(NULL, "."))
        cur = json_object_get(cur, tok);
    if (!json_is_number(cur))
        fail_msg("key %s missing or not a number", path);
    return json_number_value(cur);
}

static void golden_close_rel(const char *file, const char *what, double got, double want,
                             double rel, double abs)
{
    double tol = fmax(rel * fabs(want), abs);
    if (!(fabs(got - want) <= tol))
        fail_msg("%s: %s = %.17g, committed %.17g (tolerance %.3g)", file, what, got, want, tol);
}

static void golden_close(const char *file, const char *what, double got, double want, double abs)
{
    golden_close_rel(file, what, got, want, GOLDEN_REL, abs);
}

/* One committed fit file against a fresh pipeline run on its table. */
static void check_golden(const char *json_path)
{
    json_error_t jerr;
    json_t *root = json_load_file(json_path, 0, &jerr);
    if (!root)
        fail_msg("%s: %s", json_path, jerr.text);
    const char *table_path = json_string_value(json_object_get(json_object_get(root, "data"), "file"));
    assert_non_null(table_path);
    cf_table t;
    cf_error err = {0};
    cf_measure_options mo = cf_measure_default_options();
    if (cf_measure_load(table_path, &mo, &t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_pipeline_options po = cf_pipeline_default_options();
    json_t *fits = json_object_get(root, "fits");
    json_t *first = json_array_get(fits, 0);
    po.validate = json_object_get(first, "validation") != NULL;
    cf_fit_report r;
    if (cf_pipeline_fit(&t, &po, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(r.nfits, (int)json_array_size(fits));
    const double u = t.y_to_file, abs_y = GOLDEN_ABS_OF_YMAX * r.ymax * u;
    for (int i = 0; i < r.nfits; i++) {
        json_t *f = json_array_get(fits, (size_t)i);
        const cf_fit_result *res = &r.fits[i];
        assert_string_equal(json_string_value(json_object_get(f, "type")),
                            cf_spring_type_name(res->type));
        for (int k = 0; k < CF_P_COUNT; k++) {
            char key[64];
            snprintf(key, sizeof key, "params.%s", cf_spring_param_info(k)->key);
            golden_close_rel(json_path, key, cf_spring_get(&res->params, k), jnum(f, key),
                             GOLDEN_PARAM_REL, 0);
        }
        static const char *const ident_ss[3] = {"identifiable.rho.value",
                                                "identifiable.solid_strain.value",
                                                "identifiable.stress_scale_MPa.value"};
        static const char *const ident_fd[3] = {"identifiable.rho.value",
                                                "identifiable.travel_mm.value",
                                                "identifiable.F_C_N.value"};
        for (int k = 0; k < 3; k++) {
            const char *key = cf_table_is_force(&t) ? ident_fd[k] : ident_ss[k];
            golden_close(json_path, key, res->ident.v[k], jnum(f, key), 0);
        }
        golden_close(json_path, "rmse", res->rmse * u, jnum(f, "rmse"), abs_y);
        golden_close(json_path, "r2", res->r2, jnum(f, "r2"), 1e-12);
        if (po.validate && r.val[i].done)
            golden_close(json_path, "validation.rmse", r.val[i].rmse * u,
                         jnum(f, "validation.rmse"), abs_y);
    }
    cf_report_free(&r);
    cf_table_free(&t);
    json_decref(root);
}

static void refitting_the_shipped_tables_reproduces_the_committed_fits(void **state)
{
    (void)state;
    glob_t g;
    assert_int_equal(glob("fits/*.json", 0, NULL, &g), 0);
    assert_true(g.gl_pathc >= 7); /* one per table of data/ */
    for (size_t i = 0; i < g.gl_pathc; i++)
        check_golden(g.gl_pathv[i]);
    globfree(&g);
}

/* The keys of the spring description are what the fit file holds and what the reader reads: a
** spring written through the pipeline reads back bit for bit. */
static void spring_description_keys_round_trip_through_a_fit_file(void **state)
{
    (void)state;
    double x[12], y[12];
    cf_spring p = {4, 10, 3, 0.5, 80000, 12};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    for (int i = 0; i < 12; i++) {
        x[i] = 0.04 * i;
        y[i] = cf_law_force(&law, CF_LAW_EXACT, x[i] * p.H_mm, NULL, NULL) / (p.H_mm * p.H_mm);
    }
    cf_table t;
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, 12, x, y, NULL, &t, NULL), CF_OK);
    assert_string_equal(t.y_unit, "MPa");
    assert_false(t.compression);
    cf_pipeline_options po = cf_pipeline_default_options();
    po.types = CF_PIPELINE_TELESCOPING;
    cf_fit_report r;
    cf_error err = {0};
    assert_int_equal(cf_pipeline_fit(&t, &po, &r, &err), CF_OK);
    assert_int_equal(r.nfits, 1);
    assert_true(r.fits[0].rmse < 1e-9 * r.ymax);
    char dir[] = "/tmp/conifit-pipeline-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/fit.json", dir);
    assert_int_equal(cf_pipeline_write(&r, path, NULL, NULL, &err), CF_OK);
    json_t *root = json_load_file(path, 0, NULL);
    assert_non_null(root);
    json_t *params = json_object_get(json_array_get(json_object_get(root, "fits"), 0), "params");
    assert_int_equal(json_object_size(params), CF_P_COUNT);
    for (int k = 0; k < CF_P_COUNT; k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        assert_true(json_is_number(json_object_get(params, sp->key)));
        assert_int_equal(cf_spring_param_find(sp->key), k);
        assert_int_equal(cf_spring_param_find(sp->name), k);
    }
    json_decref(root);
    cf_fitted_spring fs;
    assert_int_equal(cf_fitfile_load(path, NULL, &fs, &err), CF_OK);
    for (int k = 0; k < CF_P_COUNT; k++)
        assert_true(cf_spring_get(&fs.params, k) == cf_spring_get(&r.fits[0].params, k));
    assert_int_equal(cf_spring_param_find("D3"), -1);
    remove(path);
    rmdir(dir);
    cf_report_free(&r);
    cf_table_free(&t);
    cf_law_free(&law);
}

/* The library speaks of parameters and values, never of command-line flags or usage. */
static void library_errors_are_data_errors_not_usage(void **state)
{
    (void)state;
    cf_error err = {0};
    cf_spring_type ty;
    assert_int_equal(cf_spring_type_parse("conical", &ty, &err), CF_E_DATA);
    assert_null(strstr(err.msg, "--"));
    cf_fit_options o = cf_fit_default_options();
    o.index_max = 2;
    double x[6] = {0, 0.1, 0.2, 0.3, 0.4, 0.5}, y[6] = {0, 1, 2, 3, 5, 8};
    cf_table t = {.count = 6, .x = x, .y = y};
    cf_fit_result res;
    assert_int_equal(cf_fit_run(&t, &o, CF_TELESCOPING, &res, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "index_max"));
    assert_null(strstr(err.msg, "--"));
}

static void count_task(void *ctx, int k)
{
    ((int *)ctx)[k]++;
}

/* Every task of the batch runs exactly once, whatever the thread count (more threads than tasks,
** more than the pool's most, none to run). */
static void pool_runs_every_task_once_on_any_number_of_threads(void **state)
{
    (void)state;
    const long threads[] = {1, 3, 64, CF_POOL_MAX_THREADS + 10};
    const int counts[] = {0, 1, 7, 300};
    static int hits[300];
    for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++)
        for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++) {
            memset(hits, 0, sizeof hits);
            cf_pool_run(counts[c], threads[t], count_task, hits);
            for (int k = 0; k < 300; k++)
                if (hits[k] != (k < counts[c]))
                    fail_msg("%d tasks on %ld threads: task %d ran %d times", counts[c],
                             threads[t], k, hits[k]);
        }
}

typedef struct progress_log {
    int calls;
    int with_table;
    char last[128];
} progress_log;

static void log_progress(void *ctx, const char *table, const char *what)
{
    progress_log *l = ctx;
    l->calls++;
    l->with_table += table != NULL;
    snprintf(l->last, sizeof l->last, "%s", what);
}

/* Two shipped tables fitted jointly: one fit per type, each announced once with no table; one
** table alone is a joint fit of that table (how a single table gets a double-acting element); no
** table is refused after the announcement, with no fit to release. */
static void joint_fit_fits_each_type_and_reports_its_progress(void **state)
{
    (void)state;
    cf_measure_options mo = cf_measure_default_options();
    cf_table t[2];
    cf_error err = {0};
    assert_int_equal(cf_measure_load("data/telescoping.csv", &mo, &t[0], &err), CF_OK);
    assert_int_equal(cf_measure_load("data/non_telescoping.csv", &mo, &t[1], &err), CF_OK);
    const cf_table *tabs[2] = {&t[0], &t[1]};
    cf_pipeline_options opt = cf_pipeline_default_options();
    progress_log log = {0};
    opt.progress = log_progress;
    opt.progress_ctx = &log;
    cf_joint_report r;
    if (cf_pipeline_fit_joint(tabs, 2, &opt, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(r.nfits, 2);
    assert_int_equal(r.ntables, 2);
    assert_ptr_equal(r.tables, tabs);
    assert_int_equal(log.calls, 2);
    assert_int_equal(log.with_table, 0);
    assert_string_equal(log.last, "fitting the non-telescoping spring to 2 tables jointly");
    for (int k = 0; k < r.nfits; k++)
        cf_joint_free(&r.fits[k]);
    opt.types = CF_PIPELINE_TELESCOPING;
    if (cf_pipeline_fit_joint(tabs, 1, &opt, &r, &err) != CF_OK)
        fail_msg("one table: %s", err.msg);
    assert_int_equal(r.nfits, 1);
    assert_int_equal(r.ntables, 1);
    assert_string_equal(log.last, "fitting the telescoping spring to 1 table jointly");
    cf_joint_report_free(&r);
    assert_int_not_equal(cf_pipeline_fit_joint(tabs, 0, &opt, &r, &err), CF_OK);
    assert_int_equal(r.nfits, 0);
    assert_int_equal(log.calls, 4);
    cf_table_free(&t[0]);
    cf_table_free(&t[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(refitting_the_shipped_tables_reproduces_the_committed_fits),
        cmocka_unit_test(spring_description_keys_round_trip_through_a_fit_file),
        cmocka_unit_test(library_errors_are_data_errors_not_usage),
        cmocka_unit_test(pool_runs_every_task_once_on_any_number_of_threads),
        cmocka_unit_test(joint_fit_fits_each_type_and_reports_its_progress),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
