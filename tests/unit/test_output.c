/*
** The public output handle (conifit/output.h) with the pipeline's writing call:
**  - a fit prepared into a handle is not in place until committed, then reads back as the fit;
**  - an aborted or freed handle leaves nothing in the folder;
**  - NULL and malformed arguments (no handle, no report, no path, a handle that still holds a
**    file, a commit of an empty handle) return CF_E_USAGE with a message and touch no file;
**  - one handle given for both the fit file and the plot, or one file named for both (by the
**    same or another path), is refused the same way: the fit file was lost before.
*/
#include "testutil.h"

#include <dirent.h>

#include "io/fitfile.h"
#include "conifit/output.h"
#include "pipeline/pipeline.h"

TU_SCRATCH_GROUP("output")

/* Entries of dir other than . and .. (temporaries included). */
static int entries(void)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    return n;
}

/* The telescoping table fitted with the defaults (both types, no validation), a target named
** `name` in the scratch folder and a new, empty handle. */
typedef struct case_ {
    cf_table t;
    cf_fit_report r;
    char path[300];
    cf_output *o;
} case_;

static void begin(case_ *c, const char *name)
{
    cf_measure_options mo = cf_measure_default_options();
    cf_pipeline_options po = cf_pipeline_default_options();
    cf_error err = {0};
    assert_int_equal(cf_measure_load("data/telescoping.csv", &mo, &c->t, &err), CF_OK);
    assert_int_equal(cf_pipeline_fit(&c->t, &po, &c->r, &err), CF_OK);
    snprintf(c->path, sizeof c->path, "%s/%s", dir, name);
    c->o = NULL;
    assert_int_equal(cf_output_new(&c->o, &err), CF_OK);
}

static void end(case_ *c)
{
    cf_output_free(c->o);
    unlink(c->path);
    cf_report_free(&c->r);
    cf_table_free(&c->t);
}

static void prepared_fit_appears_only_on_commit(void **state)
{
    (void)state;
    case_ c;
    begin(&c, "fit.json");
    cf_output *o = c.o;
    cf_error err = {0};
    assert_string_equal(cf_output_path(o), "");
    assert_int_equal(cf_pipeline_prepare(&c.r, c.path, NULL, NULL, o, NULL, &err), CF_OK);
    assert_string_equal(cf_output_path(o), c.path);
    assert_int_equal(access(c.path, F_OK), -1);
    assert_int_equal(entries(), 1); /* the hidden temporary */
    assert_int_equal(cf_output_commit(o, &err), CF_OK);
    assert_string_equal(cf_output_path(o), "");
    assert_int_equal(entries(), 1);
    cf_fitted_spring fs;
    assert_int_equal(cf_fitfile_load(c.path, "telescoping", &fs, &err), CF_OK);
    assert_close(fs.params.D1_mm, c.r.fits[0].params.D1_mm, 1e-12);
    assert_close(fs.rmse, c.r.fits[0].rmse, 1e-12);
    /* the handle is empty again: a second commit is refused, a new prepare is accepted */
    assert_int_equal(cf_output_commit(o, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "holds no file"));
    assert_int_equal(cf_pipeline_prepare(&c.r, c.path, NULL, NULL, o, NULL, &err), CF_OK);
    cf_output_abort(o);
    assert_int_equal(entries(), 1);
    end(&c);
}

static void aborted_handle_leaves_nothing(void **state)
{
    (void)state;
    case_ c;
    begin(&c, "dropped.json");
    cf_error err = {0};
    assert_int_equal(cf_report_json_prepare(&c.r, c.path, NULL, c.o, &err), CF_OK);
    assert_int_equal(entries(), 1);
    cf_output_abort(c.o);
    assert_int_equal(entries(), 0);
    cf_output_abort(c.o); /* twice is harmless */
    assert_int_equal(cf_report_json_prepare(&c.r, c.path, NULL, c.o, &err), CF_OK);
    end(&c); /* freeing aborts what was not committed */
    assert_int_equal(entries(), 0);
}

static void malformed_arguments_are_usage_errors_with_a_message(void **state)
{
    (void)state;
    case_ c;
    begin(&c, "bad.json");
    cf_error err = {0};
    assert_int_equal(cf_output_new(NULL, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "cf_output_new"));
    assert_int_equal(cf_output_commit(NULL, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "NULL"));
    cf_output_abort(NULL);
    cf_output_free(NULL);
    assert_string_equal(cf_output_path(NULL), "");

    cf_output *o = c.o, *p = NULL;
    assert_int_equal(cf_output_new(&p, &err), CF_OK);
    assert_int_equal(cf_output_commit(o, &err), CF_E_USAGE); /* never prepared */
    err = (cf_error){0};
    assert_int_equal(cf_pipeline_prepare(NULL, c.path, NULL, NULL, o, NULL, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "cf_pipeline_prepare: no report"));
    assert_int_equal(cf_pipeline_prepare(&c.r, c.path, NULL, NULL, NULL, NULL, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "no output handle"));
    assert_int_equal(cf_pipeline_prepare(&c.r, NULL, c.path, NULL, o, NULL, &err), CF_E_USAGE);
    assert_int_equal(cf_report_json_prepare(&c.r, NULL, NULL, o, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "cf_report_json_prepare: no path"));
    assert_int_equal(entries(), 0);

    /* a handle that still holds a file is refused, and its file stays committable */
    assert_int_equal(cf_pipeline_prepare(&c.r, c.path, NULL, NULL, o, NULL, &err), CF_OK);
    assert_int_equal(cf_pipeline_prepare(&c.r, c.path, NULL, NULL, p, o, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "still holds an uncommitted file"));
    assert_int_equal(cf_output_commit(o, &err), CF_OK);
    assert_int_equal(entries(), 1);
    cf_output_free(p);
    end(&c);
}

static void one_handle_or_one_file_for_both_is_refused(void **state)
{
    (void)state;
    case_ c;
    begin(&c, "both.png");
    cf_error err = {0};
    char other[320], json[320];
    snprintf(json, sizeof json, "%s/fit.json", dir);
    /* one handle for two files */
    assert_int_equal(cf_pipeline_prepare(&c.r, json, c.path, NULL, c.o, c.o, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "one output handle given for both files"));
    assert_string_equal(cf_output_path(c.o), "");
    assert_int_equal(entries(), 0);
    /* one file by two spellings of its path, with two handles */
    cf_output *p = NULL;
    assert_int_equal(cf_output_new(&p, &err), CF_OK);
    snprintf(other, sizeof other, "%s/./both.png", dir);
    const char *same[][2] = {{c.path, c.path}, {c.path, other}};
    for (int k = 0; k < 2; k++) {
        err = (cf_error){0};
        assert_int_equal(cf_pipeline_prepare(&c.r, same[k][0], same[k][1], NULL, c.o, p, &err),
                         CF_E_USAGE);
        assert_non_null(strstr(err.msg, "both outputs name one file"));
        assert_int_equal(entries(), 0);
    }
    /* an existing file through a link to its folder */
    assert_int_equal(tu_write_bytes(c.path, "old", 3), 0);
    snprintf(other, sizeof other, "%s/link", dir);
    assert_int_equal(symlink(".", other), 0);
    snprintf(other, sizeof other, "%s/link/both.png", dir);
    assert_int_equal(cf_pipeline_prepare(&c.r, c.path, other, NULL, c.o, p, &err), CF_E_USAGE);
    assert_non_null(strstr(err.msg, "both outputs name one file"));
    assert_int_equal(entries(), 2); /* the old file and the link, nothing else */
    snprintf(other, sizeof other, "%s/link", dir);
    unlink(other);
    /* the same handles for two files are accepted */
    assert_int_equal(cf_pipeline_prepare(&c.r, json, NULL, NULL, c.o, p, &err), CF_OK);
    cf_output_abort(c.o);
    cf_output_free(p);
    end(&c);
    assert_int_equal(entries(), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(prepared_fit_appears_only_on_commit),
        cmocka_unit_test(aborted_handle_leaves_nothing),
        cmocka_unit_test(malformed_arguments_are_usage_errors_with_a_message),
        cmocka_unit_test(one_handle_or_one_file_for_both_is_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
