/*
** The export subcommand: a fitted spring written for another simulator (see export.h).
** The whole output is produced in memory first, so a failure never leaves partial output on
** stdout or in the -o file.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic.h"
#include "cli/cli.h"
#include "conifit/export.h"
#include "conifit/fitfile.h"

static const char export_help[] =
    "usage: conifit export FIT.json --format F [--type T] [-o FILE] [--tol REL] [--degree N]\n"
    "                      [--example]\n"
    "Writes a fitted spring for another simulator. Tables are sampled adaptively so that linear\n"
    "interpolation stays within --tol of the law (relative to the local force, floor 1e-3 F_C),\n"
    "from full stretch to a hair before solid; the achieved maximum error and the row count are\n"
    "printed on stderr. Units: mm, N, s, tonne (stated inside each file).\n\n"
    "  --format F   json | csv | calculix | abaqus | febio | lsdyna | sofa\n"
    "  --type T     telescoping | non-telescoping (default: the fit's better type)\n"
    "  -o FILE      output file (default stdout); written atomically\n"
    "  --tol REL    relative tolerance of the table, 1e-9..0.1 (default 1e-4; for calculix\n"
    "               the smallest of 1e-4, 2e-4, 5e-4, 1e-3, ... whose table fits CalculiX's\n"
    "               200 rows)\n"
    "  --degree N   sofa: degree of the polynomial in strain, 1..15 (default 7)\n"
    "  --example    calculix/abaqus: a complete one-spring .inp instead of the *SPRING block\n\n"
    "FIT.json is a fit file (conifit fit -o) or an exported spring (--format json).\n";

int cf_cli_export(int argc, char **argv)
{
    cf_error err = {0};
    cf_export_options opt = cf_export_default_options();
    const char *fit_path = NULL, *type = NULL, *out_path = NULL;
    int have_format = 0, tol_given = 0;
    for (int i = 1; i < argc; i++) {
        const char *val;
        int m;
        if (cf_cli_is_help(argv[i])) {
            fputs(export_help, stdout);
            return CF_EXIT_OK;
        }
        if ((m = cf_cli_match(argc, argv, &i, "--format", &val, &err)) != 0) {
            if (m < 0 || cf_export_format_parse(val, &opt.format, &err) != CF_OK)
                return cf_cli_usage_error("export", "%s", err.msg);
            have_format = 1;
            continue;
        }
        if ((m = cf_cli_match(argc, argv, &i, "--type", &val, &err)) != 0) {
            cf_spring_type t;
            if (m < 0 || cf_spring_type_parse(val, &t, &err) != CF_OK)
                return cf_cli_usage_error("export", "%s", err.msg);
            type = val;
            continue;
        }
        if ((m = cf_cli_match(argc, argv, &i, "-o", &val, &err)) != 0) {
            if (m < 0)
                return cf_cli_usage_error("export", "%s", err.msg);
            out_path = val;
            continue;
        }
        if ((m = cf_cli_match(argc, argv, &i, "--tol", &val, &err)) != 0) {
            if (m < 0 || cf_cli_parse_double("--tol", val, &opt.tol, &err) != CF_OK)
                return cf_cli_usage_error("export", "%s", err.msg);
            tol_given = 1;
            if (opt.tol < CF_EXPORT_TOL_MIN || opt.tol > CF_EXPORT_TOL_MAX)
                return cf_cli_usage_error("export", "option --tol: %g is outside [%g, %g]",
                                          opt.tol, CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX);
            continue;
        }
        if ((m = cf_cli_match(argc, argv, &i, "--degree", &val, &err)) != 0) {
            long d;
            if (m < 0 || cf_cli_parse_long("--degree", val, 1, CF_EXPORT_DEGREE_MAX, &d, &err))
                return cf_cli_usage_error("export", "%s", err.msg);
            opt.degree = (int)d;
            continue;
        }
        if (strcmp(argv[i], "--example") == 0) {
            opt.example = 1;
            continue;
        }
        if (argv[i][0] == '-' && argv[i][1] != '\0')
            return cf_cli_usage_error("export", "unknown option '%s'", argv[i]);
        if (fit_path)
            return cf_cli_usage_error("export", "more than one fit file ('%s' and '%s')",
                                      fit_path, argv[i]);
        fit_path = argv[i];
    }
    if (!fit_path)
        return cf_cli_usage_error("export", "missing the fit file");
    if (!have_format)
        return cf_cli_usage_error("export", "missing option --format");
    if (opt.example && opt.format != CF_EXPORT_CALCULIX && opt.format != CF_EXPORT_ABAQUS)
        return cf_cli_usage_error("export", "--example is for --format calculix or abaqus");

    cf_fitted_spring fs;
    if (cf_fitfile_load(fit_path, type, &fs, &err) != CF_OK)
        return cf_cli_fail(&err);
    opt.source = fit_path;
    opt.auto_tol = !tol_given;

    char *buf = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&buf, &len);
    if (!mem) {
        cf_error_set(&err, CF_E_INTERNAL, "out of memory");
        return cf_cli_fail(&err);
    }
    cf_export_report rep;
    cf_status st = cf_export_write(mem, &fs, &opt, &rep, &err);
    if (fclose(mem) != 0 && st == CF_OK)
        st = cf_error_set(&err, CF_E_INTERNAL, "out of memory");
    if (st != CF_OK) {
        free(buf);
        return cf_cli_fail(&err);
    }
    if (out_path) {
        cf_atomic a;
        const char *inputs[2] = {fit_path, NULL};
        if (cf_atomic_open(&a, out_path, inputs, &err) != CF_OK) {
            free(buf);
            return cf_cli_fail(&err);
        }
        fwrite(buf, 1, len, a.fp);
        if (cf_atomic_commit(&a, &err) != CF_OK) {
            free(buf);
            return cf_cli_fail(&err);
        }
    } else if (fwrite(buf, 1, len, stdout) != len || fflush(stdout) != 0) {
        free(buf);
        cf_error_set(&err, CF_E_CANTWRITE, "cannot write to standard output");
        return cf_cli_fail(&err);
    }
    free(buf);
    if (opt.format == CF_EXPORT_SOFA)
        fprintf(stderr,
                "conifit export: sofa polynomial of degree %d, max error %.3g N (%.3g of F_C)\n",
                opt.degree, rep.max_err_N, rep.max_err_rel);
    else if (opt.format != CF_EXPORT_JSON)
        fprintf(stderr,
                "conifit export: %s, %zu rows, max error %.3g relative (%.3g N), tol %g, "
                "table ends at |u| = %.10g mm\n",
                cf_export_format_name(opt.format), rep.rows, rep.max_err_rel, rep.max_err_N,
                rep.tol, rep.u_end_mm);
    return CF_EXIT_OK;
}
