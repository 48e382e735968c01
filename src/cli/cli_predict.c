/*
** conifit predict: a saved fit's prediction of tables, fitted to them or not, without refitting
** (pipeline/predict.h).
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/cli_predict.h"
#include "io/measure.h"
#include "pipeline/predict.h"
#include "report/gnuplot.h"

static const char predict_help[] =
    "usage: conifit predict FIT.json TABLE... [-o OUT.csv | -o -] [--plot FILE.png] [options]\n"
    "Evaluates the model a fit file describes at each table's strains in the table's test mode,\n"
    "without refitting, and compares it with the measured stress: for a fit to the spring its\n"
    "single spring's law (uniaxial tables only), for a fit through the lattice (single or\n"
    "--joint) the lattice's homogenised cell with the fit's weights, double-acting element,\n"
    "volume term and tail as stored. Prints per table the RMSE and the measured RMS stress (in\n"
    "the table's stress unit), R^2, the table's term of the joint objective, (RMSE / RMS\n"
    "stress)^2 as a joint fit weights it, and its share of the sum; for a table the fit was\n"
    "fitted to (named in the fit file), the fit's own RMSE and term beside them. Rows past a\n"
    "spring's solid length are left out with a note, as is a loss of the cell's stability.\n\n"
    "  FIT.json                a fit file of conifit fit -o (not a time-series fit, not an\n"
    "                          exported spring)\n"
    "  TABLE                   .csv or .txt table read as conifit fit reads it; its '# mode:'\n"
    "                          comment (or --mode) decides the test mode\n"
    "  -o, --output OUT.csv | -  measured against predicted at every row (each table's own\n"
    "                          units; written atomically), or '-': on standard output (no report)\n"
    "  --plot FILE.png|.svg|.pdf  one panel per table: the measured points and the prediction\n"
    "  --type T                telescoping | non-telescoping: the fit file's spring of that type\n"
    "                          (default: its better type)\n"
    "  --mode M                every table's test mode: uniaxial, shear, planar, equibiaxial or\n"
    "                          confined (wins over a '# mode:' comment; default uniaxial)\n"
    "  --stress-unit U         unit of a stress column without one (Pa, kPa, MPa, ...)\n"
    "  --plane PLANE           where shear and biaxial tables lie in the fibre frame (f, s, n):\n"
    "                          ij for every table or NAME=ij,... by file name, as conifit fit\n"
    "                          takes it (wins over a '# plane:' comment). A joint fit file with a\n"
    "                          fibre lattice (fit --fibres) or Holzapfel-Ogden baselines has them\n"
    "                          predicted too, at every table in the fibre frame, beside the\n"
    "                          isotropic lattice: each table's RMSE and term per model\n";

enum { OPT_PLOT = CF_CLI_OPT_OWN, OPT_TYPE, OPT_MODE, OPT_STRESS_UNIT, OPT_PLANE };

typedef struct predict_args {
    const char *plot;
    const char *type;
    cf_measure_options mopt;
    const char *out;
    int quiet;
} predict_args;

/* One option of predict: 0 to go on, else an exit status. */
static int predict_option(void *ctx, int c, const char *val)
{
    predict_args *a = ctx;
    cf_error err = {0};
    switch (c) {
    case OPT_PLOT:
        if (cf_gp_check_name(val, &err) != CF_OK)
            return cf_cli_usage_error("predict", "option --plot: %s", err.msg);
        a->plot = val;
        return 0;
    case OPT_TYPE: {
        cf_spring_type t;
        if (cf_spring_type_parse(val, &t, &err) != CF_OK)
            return cf_cli_usage_error("predict", "option --type: %s", err.msg);
        a->type = val;
        return 0;
    }
    case OPT_MODE: {
        cf_mode m;
        if (cf_mode_parse(val, &m, &err) != CF_OK)
            return cf_cli_usage_error("predict", "--%s", err.msg);
        a->mopt.mode = val;
        return 0;
    }
    case OPT_STRESS_UNIT: a->mopt.stress_unit = val; return 0;
    case OPT_PLANE: a->mopt.plane = val; return 0;
    default: return cf_cli_usage_error("predict", "unexpected option");
    }
}

/* Returns -1 to go on (operands from argv[optind]), else an exit status. */
static int parse(int argc, char **argv, predict_args *a)
{
    static const struct option own[] = {{"plot", required_argument, NULL, OPT_PLOT},
                                        {"type", required_argument, NULL, OPT_TYPE},
                                        {"mode", required_argument, NULL, OPT_MODE},
                                        {"stress-unit", required_argument, NULL, OPT_STRESS_UNIT},
                                        {"plane", required_argument, NULL, OPT_PLANE},
                                        {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->mopt = cf_measure_default_options();
    cf_cli_parser p;
    int rc = cf_cli_parser_init(&p, "predict", predict_help, 0, argc, argv, "", own);
    if (rc || (rc = cf_cli_parse(&p, predict_option, a)) >= 0)
        return rc;
    a->out = p.output;
    a->quiet = p.quiet;
    if (argc - optind < 2)
        return cf_cli_usage_error("predict", "give a fit file and at least one table");
    return -1;
}

/* The report, the CSV and the figure of r: the files prepared together, then committed. */
static int write_outputs(const predict_args *a, const cf_predict_result *r,
                         const char *const *inputs)
{
    cf_error err = {0};
    const int csv_stdout = a->out && cf_cli_is_stdio(a->out);
    if (!csv_stdout) { /* the report is the result: -q drops only the reader's notes */
        char *text = cf_predict_text(r);
        if (!text) {
            cf_error_set(&err, CF_E_INTERNAL, "out of memory for the report");
            return cf_cli_fail(&err);
        }
        cf_cli_write_safe(stdout, text);
        free(text);
    }
    cf_atomic csv, plot;
    memset(&csv, 0, sizeof csv);
    memset(&plot, 0, sizeof plot);
    cf_status st = cf_predict_prepare(r, a->out && !csv_stdout ? a->out : NULL, a->plot, inputs,
                                      &csv, &plot, &err);
    if (st == CF_OK && a->out && !csv_stdout)
        st = cf_atomic_commit(&csv, &err);
    if (st == CF_OK && a->plot)
        st = cf_atomic_commit(&plot, &err);
    if (st != CF_OK) {
        cf_atomic_abort(&csv);
        cf_atomic_abort(&plot);
        return cf_cli_fail(&err);
    }
    if (csv_stdout)
        cf_predict_write_csv(r, stdout);
    return 0;
}

int cf_cli_predict(int argc, char **argv)
{
    predict_args a;
    int rc = parse(argc, argv, &a);
    if (rc >= 0)
        return rc;
    const char *fit = argv[optind];
    const size_t n = (size_t)(argc - optind - 1);
    cf_table *tables = calloc(n, sizeof *tables);
    const cf_table **tp = calloc(n, sizeof *tp);
    const char **inputs = calloc(n + 2, sizeof *inputs);
    cf_error err = {0};
    cf_predict_result r;
    memset(&r, 0, sizeof r);
    if (!tables || !tp || !inputs) {
        cf_error_set(&err, CF_E_INTERNAL, "out of memory");
        rc = cf_cli_fail(&err);
        goto out;
    }
    inputs[0] = fit;
    for (size_t k = 0; k < n; k++) {
        inputs[k + 1] = argv[optind + 1 + (int)k];
        if (cf_measure_load(inputs[k + 1], &a.mopt, &tables[k], &err) != CF_OK) {
            rc = cf_cli_fail(&err);
            goto out;
        }
        if (!a.quiet)
            cf_cli_table_notes(&tables[k]);
        tp[k] = &tables[k];
    }
    if (cf_predict(fit, a.type, tp, n, &r, &err) != CF_OK) {
        rc = cf_cli_fail(&err);
        goto out;
    }
    rc = write_outputs(&a, &r, inputs);
out:
    cf_predict_free(&r);
    for (size_t k = 0; tables && k < n; k++)
        cf_table_free(&tables[k]);
    free(tables);
    free(tp);
    free(inputs);
    return rc;
}
