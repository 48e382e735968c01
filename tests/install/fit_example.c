/*
** A user's program that fits a table through an installed libconifit and writes the fit file
** (tests/install/run.sh builds it with pkg-config, shared and static): fit_example TABLE OUT.json
** fits both spring types with the defaults, as `conifit fit TABLE -o OUT.json` does, prepares the
** fit file into an output handle and commits it. Before that it checks that the library refuses
** a commit without a handle with a message rather than crashing. Exit 1 with the library's
** message on any failure.
*/
#include <stdio.h>
#include <string.h>

#include <conifit/output.h>
#include <conifit/pipeline.h>

static int failed(const char *what, const cf_error *err)
{
    fprintf(stderr, "fit_example: %s: %s\n", what, err->msg);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: fit_example TABLE OUT.json\n");
        return 2;
    }
    cf_error err = {0};
    if (cf_output_commit(NULL, &err) != CF_E_USAGE || !strstr(err.msg, "NULL")) {
        fprintf(stderr, "fit_example: a commit without a handle was not refused\n");
        return 1;
    }
    err = (cf_error){0};
    cf_measure_options mo = cf_measure_default_options();
    cf_table t;
    if (cf_measure_load(argv[1], &mo, &t, &err) != CF_OK)
        return failed("loading the table", &err);
    cf_pipeline_options po = cf_pipeline_default_options();
    cf_fit_report r;
    if (cf_pipeline_fit(&t, &po, &r, &err) != CF_OK) {
        cf_table_free(&t);
        return failed("fitting", &err);
    }
    cf_output *json = NULL;
    cf_status st = cf_output_new(&json, &err);
    if (st == CF_OK)
        st = cf_pipeline_prepare(&r, argv[2], NULL, NULL, json, NULL, &err);
    if (st == CF_OK)
        st = cf_output_commit(json, &err);
    cf_output_free(json);
    cf_report_free(&r);
    cf_table_free(&t);
    if (st != CF_OK)
        return failed("writing the fit file", &err);
    printf("wrote %s\n", argv[2]);
    return 0;
}
