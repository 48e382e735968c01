/*
** The arguments of `conifit fit` (private to src/cli/): what cli_fit_args.c parses and cli_fit.c
** runs.
*/
#ifndef CF_CLI_FIT_H
#define CF_CLI_FIT_H

#include "io/measure.h"
#include "pipeline/pipeline.h"
#include "fit/viscofit.h"

typedef struct fit_args {
    const char **files;
    int nfiles;
    const char *out;
    const char *plot;
    cf_pipeline_options popt;    /* types, fitter options, validation lattice */
    cf_measure_options mopt;
    long jobs;
    int quiet;
    int progress;                /* progress lines on stderr */
    const char *scene;           /* the validation scene, or NULL for the default lattice */
    int argc;                    /* the command line, for --validate SCENE.json */
    char **argv;
    cf_visco_fit_options vopt;   /* time series: the viscoelastic fit */
    const char *elastic;         /* --elastic FIT.json[:TYPE] */
    int series_only;             /* an option for time series only was given */
    int joint;                   /* --joint: one lattice for every table */
    int calibration_given;       /* --calibration was given */
    char *options;               /* the options that change a fit, escaped (cli_summary.h), by
                                 ** their long names, in order; NULL for none (malloc'd) */
} fit_args;

/* Parses fit's command line into a: the options, the operands (the tables) and the checks across
** them. -1 to go on, else an exit status (a usage error's message printed). */
int cf_cli_fit_parse(int argc, char **argv, fit_args *a);

#endif
