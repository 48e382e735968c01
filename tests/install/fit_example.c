/*
** A user's program that fits a table through an installed libconifit and writes the fit file
** (tests/install/run.sh builds it with pkg-config, shared and static): fit_example TABLE OUT.json
** fits both spring types with the defaults, as `conifit fit TABLE -o OUT.json` does, through the
** table-fit handle (conifit/tablefit.h), prints each fit's type, spring, law kind, RMSE and
** identifiable quantities read by name, then prepares the fit file into an output handle and
** commits it. Before that it checks that the library refuses a commit without a handle, and a
** fit without a table path, with a message rather than crashing. Exit 1 with the library's
** message on any failure.
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <conifit/output.h>
#include <conifit/tablefit.h>

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
    cf_tablefit *fit = NULL;
    err = (cf_error){0};
    if (cf_tablefit_run(NULL, NULL, &fit, &err) != CF_E_USAGE || fit || !strstr(err.msg, "NULL")) {
        fprintf(stderr, "fit_example: a fit without a table was not refused\n");
        return 1;
    }
    err = (cf_error){0};
    cf_tablefit_options opt = cf_tablefit_default_options();
    if (cf_tablefit_run(argv[1], &opt, &fit, &err) != CF_OK)
        return failed("fitting", &err);
    int n = cf_tablefit_count(fit), better = cf_tablefit_better(fit);
    for (int i = 0; i < n; i++) {
        const cf_spring *p = cf_tablefit_spring(fit, i);
        char text[256];
        printf("%s%s (%s law): %s; RMSE %g %s\n", cf_spring_type_name(cf_tablefit_type(fit, i)),
               i == better ? " [better]" : "", cf_tablefit_law(fit, i),
               cf_spring_text(p, 6, 0, text, sizeof text), cf_tablefit_rmse(fit, i),
               cf_tablefit_y_unit(fit));
        for (int k = 0; k < cf_tablefit_quantity_count(fit, i); k++) {
            const char *key = cf_tablefit_quantity_key(fit, i, k);
            double se;
            double v = cf_tablefit_quantity(fit, i, key, &se);
            if (!isfinite(v)) {
                fprintf(stderr, "fit_example: quantity %s of fit %d is not a number\n", key, i);
                cf_tablefit_free(fit);
                return 1;
            }
            printf("  %s = %.17g %s (standard error %g)\n", key, v,
                   cf_tablefit_quantity_unit(fit, i, key), se);
        }
    }
    if (!isnan(cf_tablefit_quantity(fit, 0, "no_such_quantity", NULL))) {
        fprintf(stderr, "fit_example: an unknown quantity has a value\n");
        cf_tablefit_free(fit);
        return 1;
    }
    cf_output *json = NULL;
    cf_status st = cf_output_new(&json, &err);
    if (st == CF_OK)
        st = cf_tablefit_prepare(fit, argv[2], json, &err);
    if (st == CF_OK)
        st = cf_output_commit(json, &err);
    cf_output_free(json);
    cf_tablefit_free(fit);
    if (st != CF_OK)
        return failed("writing the fit file", &err);
    printf("wrote %s\n", argv[2]);
    return 0;
}
