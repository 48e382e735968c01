/*
** The fitting pipeline as one library call: a table in, a report out.
**
**   cf_table (measure.h) --cf_fit_run, each type--> cf_fit_result
**                        --cf_baseline_fit_all----> linear, Duffing, Fung, Yeoh, Ogden
**                        --cf_validate_run---------> lattice curve, RMSE, R^2 (optional)
**                        --cf_lattice_fit----------> the fit through the lattice (optional),
**                          cf_validate_lattice_fit    verified in the full lattice
**   = cf_fit_report (report.h) --cf_pipeline_write--> fit file (JSON) and plot
**
** Every front end (the command line, the tests, the benchmark) goes through these calls, so the
** path from a table to a fit file exists once. Thread-safe: no globals; one report per call.
*/
#ifndef CF_PIPELINE_H
#define CF_PIPELINE_H

#include "io/budget.h"
#include "conifit/error.h"
#include "fit/fit.h"
#include "io/measure.h"
#include "conifit/output.h"
#include "report/report.h"
#include "check/validate.h"

/* Spring types to fit, as bits of cf_pipeline_options.types. */
enum {
    CF_PIPELINE_TELESCOPING = 1 << CF_TELESCOPING,
    CF_PIPELINE_NON_TELESCOPING = 1 << CF_NON_TELESCOPING,
    CF_PIPELINE_BOTH = CF_PIPELINE_TELESCOPING | CF_PIPELINE_NON_TELESCOPING
};

/* Called before each long step: `table` is the table's path (NULL for a step over several tables,
** pipeline_joint.h), `what` says what starts ("fitting the telescoping spring through the
** lattice"). The library itself never prints. */
typedef void (*cf_pipeline_progress)(void *ctx, const char *table, const char *what);

/* What the fit aims at. */
typedef enum cf_pipeline_target {
    CF_TARGET_AUTO = 0,    /* the lattice whenever one is involved: with validate, and for every
                           ** mode but uniaxial (a single spring has no shear, planar, equibiaxial
                           ** or confined form); the spring for a uniaxial table fitted alone */
    CF_TARGET_SPRING = 1,  /* the single spring's curve F(eH)/H^2 */
    CF_TARGET_LATTICE = 2  /* the lattice's curve in the table's mode (lattice_fit.h,
                           ** cf_lattice_fit), verified once in the full lattice */
} cf_pipeline_target;

typedef struct cf_pipeline_options {
    unsigned types;              /* CF_PIPELINE_* bits (default both) */
    cf_fit_options fit;          /* the fitter's options (fit.h) */
    int validate;                /* 1: run each fit in the lattice */
    cf_pipeline_target target;   /* CF_TARGET_LATTICE implies validate */
    cf_validate_setup lattice;   /* the lattice of the validation (validate.h) */
    cf_budget budget;            /* limits of the validation's memory and static solves (budget.h,
                                 ** as for a scene; default cf_budget_default) */
    int with_timing;             /* 0: write wall times as 0 (reproducible fit files) */
    const char *fibres;          /* a joint fit's fibre groups (fibre_fit.h: "f", "fs", "fn" ...;
                                 ** NULL: none): a fibre-reinforced lattice fitted beside the
                                 ** isotropic one when the tables lie in a fibre frame */
    const char *title;           /* the figure's title (NULL: the table's name; report.h) */
    cf_pipeline_progress progress; /* NULL: silent */
    void *progress_ctx;
} cf_pipeline_options;

/* Both types, the fitter's defaults, no validation (default lattice ready), timing on. */
cf_pipeline_options cf_pipeline_default_options(void);

/* Replaces opt->lattice by the lattice of the static uniaxial scene at path (scene.h,
** cf_validate_from_scene), whose size must fit opt->budget (cf_budget_check_size). CF_E_NOINPUT
** or CF_E_DATA naming the file and key (and the estimate, for a scene above the budget). */
cf_status cf_pipeline_use_scene(cf_pipeline_options *opt, const char *path, cf_error *err);

/* Fits table t and fills r (r->table = t, which must outlive r; release r with cf_report_free).
** A table the lattice cannot run (force-displacement) is validated as skipped, with a note, not
** an error. Errors: those of cf_fit_run, prefixed with the table's path; CF_E_DATA before any
** fit when the validation would need more static solves than opt->budget allows. */
cf_status cf_pipeline_fit(const cf_table *t, const cf_pipeline_options *opt, cf_fit_report *r,
                          cf_error *err);

/* Writes the report's fit file to json_path and its plot to plot_path (either NULL: not
** written) as complete temporary files beside their targets, not yet in place (conifit/output.h):
** the caller commits them (cf_output_commit) when all of its outputs are ready, or aborts them.
** On failure neither is left. `inputs` (NULL-terminated, may be NULL) are refused as targets.
** CF_E_USAGE, nothing written, when both paths are given with one handle or name one file. */
cf_status cf_pipeline_prepare(const cf_fit_report *r, const char *json_path,
                              const char *plot_path, const char *const *inputs,
                              cf_output *json_out, cf_output *plot_out,
                              cf_error *err);

/* The same, both put in place at once: the plot is drawn before either file is written, so a
** failing gnuplot replaces nothing. */
cf_status cf_pipeline_write(const cf_fit_report *r, const char *json_path, const char *plot_path,
                            const char *const *inputs, cf_error *err);

#endif
